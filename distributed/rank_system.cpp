#include "distributed/rank_system.h"

#include "distributed/comm.h"
#include "distributed/rank_hierarchy.h"
#include "solvers/petsc_runtime.h"
#include "solvers/petsc_solver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <stdexcept>

#ifdef MCFBENCH_HAVE_PETSC
#include <petscksp.h>
#endif

namespace mcf::dist {

#ifndef MCFBENCH_HAVE_PETSC

struct RankSystem::Impl {};
RankSystem::RankSystem(const RankMesh&, MassKind, RankSolverOptions) {
  throw PetscUnavailable("a flow across MPI ranks: " + petsc_unavailable_message());
}
RankSystem::~RankSystem() = default;
Positions RankSystem::with_ghosts(const Coefficients& owned) {
  return owned;
}
void RankSystem::update(const Positions&, bool, bool) {}
Coefficients RankSystem::apply_mass(const Coefficients& owned) {
  return owned;
}
Coefficients RankSystem::apply_stiffness(const Coefficients& owned) {
  return owned;
}
SolveReport RankSystem::solve(double, double, const Coefficients&, const Coefficients&,
                              const Coefficients&, Coefficients&) {
  SolveReport r;
  r.status = SolveStatus::failed;
  r.message = petsc_unavailable_message();
  return r;
}
std::vector<std::pair<std::string, std::string>> RankSystem::settings() const {
  return {};
}
std::string RankSystem::name() const {
  return "";
}
int RankSystem::levels() const {
  return 1;
}
double RankSystem::matrix_bytes() const {
  return 0;
}
double RankSystem::preconditioner_bytes() const {
  return -1;
}

#else

namespace {

std::string reason_name(KSPConvergedReason reason) {
  const char* name = KSPConvergedReasons[reason];
  return name != nullptr ? name : "reason " + std::to_string(int(reason));
}

SolveStatus status_of(KSPConvergedReason reason) {
  if (reason > 0) return SolveStatus::converged;
  switch (reason) {
    case KSP_DIVERGED_ITS:
      return SolveStatus::max_iterations;
    case KSP_DIVERGED_INDEFINITE_PC:
    case KSP_DIVERGED_INDEFINITE_MAT:
      return SolveStatus::not_positive_definite;
    case KSP_DIVERGED_NANORINF:
      return SolveStatus::numerical_issue;
    default:
      return SolveStatus::failed;
  }
}

int severity(SolveStatus s) {
  return s == SolveStatus::converged ? 0 : s == SolveStatus::max_iterations ? 1 : 2;
}

/// An AIJ matrix's storage on this rank: a value and a column index per stored entry, a row
/// offset per local row.
double storage_bytes(Mat m) {
  MatInfo info;
  petsc_check(MatGetInfo(m, MAT_LOCAL, &info), "MatGetInfo");
  PetscInt rows = 0, cols = 0;
  petsc_check(MatGetLocalSize(m, &rows, &cols), "MatGetLocalSize");
  return info.nz_used * double(sizeof(PetscScalar) + sizeof(PetscInt)) +
         double(rows + 1) * double(sizeof(PetscInt));
}

/// Inserts `options` under `prefix` into PETSc's options database.
void insert_options(const std::string& prefix, const std::string& options) {
  petsc_check(PetscOptionsPrefixPush(nullptr, prefix.c_str()), "PetscOptionsPrefixPush");
  const PetscErrorCode inserted = PetscOptionsInsertString(nullptr, options.c_str());
  petsc_check(PetscOptionsPrefixPop(nullptr), "PetscOptionsPrefixPop");
  petsc_check(inserted, "PetscOptionsInsertString");
}

}  // namespace

struct RankSystem::Impl {
  const RankMesh& mesh;
  RankSolverOptions options;
  HatBasis basis;
  MPI_Comm comm = PETSC_COMM_WORLD;
  std::string prefix, inserted;

  // The owned rows in CSR with global, increasing column numbers; source[k] is entry k's position
  // in the local basis's value arrays (its column j = the owned row, full symmetric storage).
  std::vector<PetscInt> ia, ja;
  std::vector<int> source;
  std::vector<PetscScalar> values;
  std::vector<PetscInt> held_rows;  // global numbers of the owned held rows

  Mat A = nullptr;
  Vec b = nullptr, x = nullptr, r = nullptr, shift = nullptr;
  Vec ghosted = nullptr;  // block size 3: the owned rows' xyz, then the ghosts'
  KSP ksp = nullptr, cg = nullptr, direct = nullptr;
  std::vector<Mat> interpolations;
  bool guarded = false;        // fixed multigrid cycles with a residual bound
  bool prefer_direct = false;  // an earlier step needed the factorization
  int level_count = 1;

  Impl(const RankMesh& m, MassKind mass, RankSolverOptions o)
      : mesh(m), options(std::move(o)), basis(TriangleMesh{m.vertices, m.faces}, mass) {}

  ~Impl() {
    if (ksp) KSPDestroy(&ksp);
    if (cg) KSPDestroy(&cg);
    if (direct) KSPDestroy(&direct);
    for (Mat& p : interpolations) MatDestroy(&p);
    if (A) MatDestroy(&A);
    for (Vec* v : {&b, &x, &r, &shift, &ghosted})
      if (*v) VecDestroy(v);
  }

  void build_pattern() {
    const SparseView M = basis.mass();
    const int n = mesh.owned;
    const auto entries = std::size_t(M.outerIndexPtr()[n]);  // the owned columns' (= rows')
    ia.assign(std::size_t(n) + 1, 0);
    ja.clear();
    ja.reserve(entries);
    source.clear();
    source.reserve(entries);
    std::vector<std::pair<std::int64_t, int>> row;
    for (int j = 0; j < n; ++j) {
      row.clear();
      for (auto p = M.outerIndexPtr()[j]; p < M.outerIndexPtr()[j + 1]; ++p)
        row.emplace_back(mesh.global(M.innerIndexPtr()[p]), int(p));
      std::sort(row.begin(), row.end());
      for (const auto& [g, p] : row) {
        ja.push_back(PetscInt(g));
        source.push_back(p);
      }
      ia[std::size_t(j) + 1] = PetscInt(ja.size());
    }
    values.assign(ja.size(), 0.0);
  }

  void fill(double a, double bk) {
    const double* m = basis.mass().valuePtr();
    const double* k = basis.stiffness().valuePtr();
    for (std::size_t e = 0; e < values.size(); ++e)
      values[e] = sum_entry(a, m[std::size_t(source[e])], bk, k[std::size_t(source[e])]);
  }

  void make_matrix() {
    const PetscInt n = mesh.owned, N = PetscInt(mesh.global_vertices);
    fill(1.0, 1.0);
    petsc_check(MatCreate(comm, &A), "MatCreate");
    petsc_check(MatSetSizes(A, n, n, N, N), "MatSetSizes");
    petsc_check(MatSetType(A, MATMPIAIJ), "MatSetType");
    petsc_check(MatMPIAIJSetPreallocationCSR(A, ia.data(), ja.data(), values.data()),
                "MatMPIAIJSetPreallocationCSR");
    petsc_check(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption");
    petsc_check(MatSetOption(A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE), "MatSetOption");
    petsc_check(MatSetOption(A, MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE), "MatSetOption");
    petsc_check(MatSetOption(A, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE), "MatSetOption");
    petsc_check(MatCreateVecs(A, &x, &b), "MatCreateVecs");
    petsc_check(VecDuplicate(b, &r), "VecDuplicate");
    petsc_check(VecDuplicate(b, &shift), "VecDuplicate");
    std::vector<PetscInt> ghosts(mesh.ghost_global.begin(), mesh.ghost_global.end());
    petsc_check(VecCreateGhostBlock(comm, 3, 3 * n, 3 * N, PetscInt(ghosts.size()), ghosts.data(),
                                    &ghosted),
                "VecCreateGhostBlock");
  }

  KSP make_ksp(const std::string& options_text) {
    insert_options(prefix, options_text);
    KSP k = nullptr;
    petsc_check(KSPCreate(comm, &k), "KSPCreate");
    petsc_check(KSPSetOptionsPrefix(k, prefix.c_str()), "KSPSetOptionsPrefix");
    petsc_check(KSPSetOperators(k, A, A), "KSPSetOperators");
    return k;
  }

  /// The surface multigrid as PETSc's PCMG on `pc`: the per-partition hierarchy's
  /// prolongations, Galerkin coarse operators, `smooth` forward SOR sweeps down and as many
  /// backward sweeps up (a symmetric cycle, as CG needs), the coarsest level solved redundantly.
  void set_multigrid(PC pc) {
    const RankHierarchy h = build_rank_hierarchy(mesh, std::max(100, 1000 / mesh.ranks));
    level_count = h.levels();
    petsc_check(PCSetType(pc, PCMG), "PCSetType");
    petsc_check(PCMGSetLevels(pc, level_count, nullptr), "PCMGSetLevels");
    if (interpolations.empty()) {
      // Level sizes on this rank, finest last; global offsets by a scan over the ranks.
      std::vector<PetscInt> local(static_cast<std::size_t>(level_count));
      local.back() = mesh.owned;
      for (int l = 0; l + 1 < level_count; ++l)
        local[std::size_t(l)] = PetscInt(h.prolongations[std::size_t(l)].cols());
      std::vector<PetscInt> offset(local.size()), total(local.size());
      for (std::size_t l = 0; l < local.size(); ++l) {
        PetscInt end = 0;
        petsc_check(MPI_Scan(&local[l], &end, 1, MPIU_INT, MPI_SUM, comm), "MPI_Scan");
        offset[l] = end - local[l];
        petsc_check(MPI_Allreduce(&local[l], &total[l], 1, MPIU_INT, MPI_SUM, comm),
                    "MPI_Allreduce");
      }
      for (int l = 0; l + 1 < level_count; ++l) {
        const SparseMatrix& P = h.prolongations[std::size_t(l)];  // fine x coarse, CSC
        const SparseMatrix rows = P.transpose();                  // coarse x fine: CSC of rows
        std::vector<PetscInt> pia(std::size_t(rows.cols()) + 1), pja;
        std::vector<PetscScalar> pv;
        for (Eigen::Index i = 0; i < rows.cols(); ++i) {
          for (auto p = rows.outerIndexPtr()[i]; p < rows.outerIndexPtr()[i + 1]; ++p) {
            pja.push_back(offset[std::size_t(l)] + rows.innerIndexPtr()[p]);
            pv.push_back(rows.valuePtr()[p]);
          }
          pia[std::size_t(i) + 1] = PetscInt(pja.size());
        }
        Mat Pm = nullptr;
        petsc_check(
            MatCreateMPIAIJWithArrays(comm, local[std::size_t(l) + 1], local[std::size_t(l)],
                                      total[std::size_t(l) + 1], total[std::size_t(l)], pia.data(),
                                      pja.data(), pv.data(), &Pm),
            "MatCreateMPIAIJWithArrays");
        interpolations.push_back(Pm);
      }
    }
    for (int l = 1; l < level_count; ++l)
      petsc_check(PCMGSetInterpolation(pc, l, interpolations[std::size_t(l) - 1]),
                  "PCMGSetInterpolation");
    petsc_check(PCMGSetGalerkin(pc, PC_MG_GALERKIN_BOTH), "PCMGSetGalerkin");
  }

  /// Options of the surface multigrid's PC under the prefix (the cycle, the smoothers, the
  /// coarse solve); `pc` is "mg_" for the PCs of the solver and of the guard's CG alike.
  std::string multigrid_options() const {
    char text[512];
    std::snprintf(text, sizeof text,
                  "-pc_mg_cycle_type %s -pc_mg_distinct_smoothup "
                  "-mg_levels_ksp_type richardson -mg_levels_ksp_max_it %d "
                  "-mg_levels_ksp_norm_type none -mg_levels_pc_type sor "
                  "-mg_levels_pc_sor_local_forward "
                  "-mg_levels_up_ksp_type richardson -mg_levels_up_ksp_max_it %d "
                  "-mg_levels_up_ksp_norm_type none -mg_levels_up_pc_type sor "
                  "-mg_levels_up_pc_sor_local_backward "
                  "-mg_coarse_ksp_type preonly -mg_coarse_pc_type redundant "
                  "-mg_coarse_redundant_pc_type cholesky",
                  options.cycle == "V" ? "v" : "w", options.smooth, options.smooth);
    return text;
  }

  void make_solver() {
    prefix = PetscRuntime::instance().new_prefix();
    char numbers[160];
    if (options.solver == "petsc") {
      inserted = petsc_default_options(options.tolerance, options.max_iterations) + " " +
                 options.petsc_options;
      ksp = make_ksp(inserted);
      petsc_check(KSPSetFromOptions(ksp), "KSPSetFromOptions");
      PetscBool norm_given = PETSC_FALSE;
      petsc_check(PetscOptionsHasName(nullptr, prefix.c_str(), "-ksp_norm_type", &norm_given),
                  "PetscOptionsHasName");
      KSPType type = nullptr;
      petsc_check(KSPGetType(ksp, &type), "KSPGetType");
      if (!norm_given && type != nullptr && std::string(type) == KSPCG)
        petsc_check(KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
      return;
    }
    const bool cycles_only = options.solver == "multigrid" && options.tolerance <= 0;
    if (options.solver == "multigrid") {
      // Fixed cycles: Richardson on the cycle, `cycles` of them, no test in between; with a
      // tolerance, cycles until it, at most `cycles` (as the one-process multigrid counts).
      std::snprintf(numbers, sizeof numbers,
                    "-ksp_type richardson -ksp_richardson_scale 1 -ksp_max_it %d -ksp_rtol %.17g "
                    "-ksp_norm_type %s -ksp_initial_guess_nonzero true ",
                    options.cycles, cycles_only ? 0.0 : options.tolerance,
                    cycles_only ? "none" : "unpreconditioned");
    } else {
      std::snprintf(numbers, sizeof numbers,
                    "-ksp_type cg -ksp_max_it %d -ksp_rtol %.17g -ksp_norm_type unpreconditioned "
                    "-ksp_initial_guess_nonzero true ",
                    options.max_iterations, options.tolerance);
    }
    inserted = std::string(numbers) + multigrid_options();
    ksp = make_ksp(inserted);
    PC pc = nullptr;
    petsc_check(KSPGetPC(ksp, &pc), "KSPGetPC");
    set_multigrid(pc);
    petsc_check(KSPSetFromOptions(ksp), "KSPSetFromOptions");
    guarded = cycles_only && options.residual_bound > 0;
    if (guarded) {
      // The guard: CG preconditioned by the same cycle (the same PC object) to the bound, and a
      // distributed Cholesky factorization (MUMPS) after `direct_after` iterations.
      petsc_check(KSPCreate(comm, &cg), "KSPCreate");
      petsc_check(KSPSetOperators(cg, A, A), "KSPSetOperators");
      petsc_check(KSPSetType(cg, KSPCG), "KSPSetType");
      petsc_check(KSPSetPC(cg, pc), "KSPSetPC");
      petsc_check(KSPSetNormType(cg, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
      petsc_check(KSPSetInitialGuessNonzero(cg, PETSC_TRUE), "KSPSetInitialGuessNonzero");
      petsc_check(KSPSetTolerances(cg, options.residual_bound, PETSC_DEFAULT, PETSC_DEFAULT,
                                   std::max(options.direct_after, 1)),
                  "KSPSetTolerances");
    }
  }

  void make_direct() {
    petsc_check(KSPCreate(comm, &direct), "KSPCreate");
    petsc_check(KSPSetOperators(direct, A, A), "KSPSetOperators");
    petsc_check(KSPSetType(direct, KSPPREONLY), "KSPSetType");
    PC pc = nullptr;
    petsc_check(KSPGetPC(direct, &pc), "KSPGetPC");
    petsc_check(PCSetType(pc, PCCHOLESKY), "PCSetType");
    petsc_check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
  }

  /// ||b - A x|| / ||b|| on the system as solved.
  double relative_residual() {
    petsc_check(MatMult(A, x, r), "MatMult");
    petsc_check(VecAYPX(r, -1.0, b), "VecAYPX");
    PetscReal rn = 0, bn = 0;
    petsc_check(VecNorm(r, NORM_2, &rn), "VecNorm");
    petsc_check(VecNorm(b, NORM_2, &bn), "VecNorm");
    return bn > 0 ? rn / bn : rn;
  }
};

RankSystem::RankSystem(const RankMesh& mesh, MassKind mass, RankSolverOptions options)
    : impl_(std::make_unique<Impl>(mesh, mass, std::move(options))) {
  Impl& s = *impl_;
  for (const int i : s.basis.locked_functions())
    if (i < mesh.owned) {
      held_.push_back(i);
      s.held_rows.push_back(PetscInt(mesh.global(i)));
    }
  held_global_ = sum_over_ranks((long long)held_.size());
  s.build_pattern();
  s.make_matrix();
  try {
    s.make_solver();
  } catch (const PetscFailure& e) {
    throw std::invalid_argument("solver.petsc_options: \"" + s.options.petsc_options +
                                "\": " + e.what());
  }
}

RankSystem::~RankSystem() = default;

Positions RankSystem::with_ghosts(const Coefficients& owned) {
  Impl& s = *impl_;
  Vec local = nullptr;
  petsc_check(VecGhostGetLocalForm(s.ghosted, &local), "VecGhostGetLocalForm");
  PetscScalar* v = nullptr;
  petsc_check(VecGetArray(local, &v), "VecGetArray");
  for (int i = 0; i < s.mesh.owned; ++i)
    for (int c = 0; c < 3; ++c) v[3 * i + c] = owned(i, c);
  petsc_check(VecRestoreArray(local, &v), "VecRestoreArray");
  petsc_check(VecGhostRestoreLocalForm(s.ghosted, &local), "VecGhostRestoreLocalForm");
  petsc_check(VecGhostUpdateBegin(s.ghosted, INSERT_VALUES, SCATTER_FORWARD), "VecGhostUpdate");
  petsc_check(VecGhostUpdateEnd(s.ghosted, INSERT_VALUES, SCATTER_FORWARD), "VecGhostUpdate");
  Positions out(s.mesh.local_vertices(), 3);
  petsc_check(VecGhostGetLocalForm(s.ghosted, &local), "VecGhostGetLocalForm");
  const PetscScalar* w = nullptr;
  petsc_check(VecGetArrayRead(local, &w), "VecGetArrayRead");
  for (int i = 0; i < out.rows(); ++i)
    for (int c = 0; c < 3; ++c) out(i, c) = w[3 * i + c];
  petsc_check(VecRestoreArrayRead(local, &w), "VecRestoreArrayRead");
  petsc_check(VecGhostRestoreLocalForm(s.ghosted, &local), "VecGhostRestoreLocalForm");
  return out;
}

void RankSystem::update(const Positions& local, bool mass, bool stiffness) {
  impl_->basis.update(local, mass, stiffness);
}

namespace {
/// The owned rows of S X for the local symmetric S (its owned columns are complete).
Coefficients owned_product(const SparseView& S, const Positions& X, int owned) {
  Coefficients Y(owned, 3);
  for (int j = 0; j < owned; ++j) {
    double y[3] = {0, 0, 0};
    for (auto p = S.outerIndexPtr()[j]; p < S.outerIndexPtr()[j + 1]; ++p) {
      const double v = S.valuePtr()[p];
      const int i = S.innerIndexPtr()[p];
      for (int c = 0; c < 3; ++c) y[c] += v * X(i, c);
    }
    for (int c = 0; c < 3; ++c) Y(j, c) = y[c];
  }
  return Y;
}
}  // namespace

Coefficients RankSystem::apply_mass(const Coefficients& owned) {
  return owned_product(impl_->basis.mass(), with_ghosts(owned), impl_->mesh.owned);
}

Coefficients RankSystem::apply_stiffness(const Coefficients& owned) {
  return owned_product(impl_->basis.stiffness(), with_ghosts(owned), impl_->mesh.owned);
}

SolveReport RankSystem::solve(double a, double b, const Coefficients& R, const Coefficients& held,
                              const Coefficients& warm, Coefficients& Y) {
  Impl& s = *impl_;
  SolveReport report;
  const int n = s.mesh.owned;
  Y.resize(n, 3);
  try {
    s.fill(a, b);
    petsc_check(MatUpdateMPIAIJWithArrays(s.A, n, n, PetscInt(s.mesh.global_vertices),
                                          PetscInt(s.mesh.global_vertices), s.ia.data(),
                                          s.ja.data(), s.values.data()),
                "MatUpdateMPIAIJWithArrays");
    // Right-hand sides with the held values moved over (before the held rows and columns go).
    std::vector<std::vector<PetscScalar>> rhs(3, std::vector<PetscScalar>(std::size_t(n)));
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < n; ++i) rhs[std::size_t(c)][std::size_t(i)] = R(i, c);
    if (held_global_ > 0) {
      for (int c = 0; c < 3; ++c) {
        petsc_check(VecSet(s.shift, 0.0), "VecSet");
        PetscScalar* v = nullptr;
        petsc_check(VecGetArray(s.shift, &v), "VecGetArray");
        for (const int i : held_) v[i] = held(i, c);
        petsc_check(VecRestoreArray(s.shift, &v), "VecRestoreArray");
        petsc_check(MatMult(s.A, s.shift, s.r), "MatMult");
        const PetscScalar* w = nullptr;
        petsc_check(VecGetArrayRead(s.r, &w), "VecGetArrayRead");
        for (int i = 0; i < n; ++i) rhs[std::size_t(c)][std::size_t(i)] -= w[i];
        petsc_check(VecRestoreArrayRead(s.r, &w), "VecRestoreArrayRead");
        for (const int i : held_) rhs[std::size_t(c)][std::size_t(i)] = held(i, c);
      }
      petsc_check(MatZeroRowsColumns(s.A, PetscInt(s.held_rows.size()), s.held_rows.data(), 1.0,
                                     nullptr, nullptr),
                  "MatZeroRowsColumns");
    }
    for (int c = 0; c < 3; ++c) {
      PetscScalar* v = nullptr;
      petsc_check(VecGetArray(s.b, &v), "VecGetArray");
      std::copy(rhs[std::size_t(c)].begin(), rhs[std::size_t(c)].end(), v);
      petsc_check(VecRestoreArray(s.b, &v), "VecRestoreArray");
      petsc_check(VecGetArray(s.x, &v), "VecGetArray");
      for (int i = 0; i < n; ++i) v[i] = warm(i, c);
      for (const int i : held_) v[i] = held(i, c);
      petsc_check(VecRestoreArray(s.x, &v), "VecRestoreArray");

      ColumnReport column;
      SolveStatus status = SolveStatus::converged;
      std::string note;
      petsc_check(KSPSolve(s.ksp, s.b, s.x), "KSPSolve");
      KSPConvergedReason reason;
      PetscInt its = 0;
      petsc_check(KSPGetConvergedReason(s.ksp, &reason), "KSPGetConvergedReason");
      petsc_check(KSPGetIterationNumber(s.ksp, &its), "KSPGetIterationNumber");
      column.iterations = int(its);
      column.reason = reason_name(reason);
      double rel = s.relative_residual();
      if (s.guarded) {
        // Fixed cycles: converged only at the bound; above it CG by the cycle, then MUMPS.
        status = std::isfinite(rel) ? SolveStatus::converged : SolveStatus::numerical_issue;
        if (status == SolveStatus::converged && rel > s.options.residual_bound) {
          bool solved = false;
          if (!s.prefer_direct) {
            petsc_check(KSPSolve(s.cg, s.b, s.x), "KSPSolve");
            PetscInt more = 0;
            petsc_check(KSPGetIterationNumber(s.cg, &more), "KSPGetIterationNumber");
            report.fallback_iterations += int(more);
            column.iterations += int(more);
            rel = s.relative_residual();
            solved = rel <= s.options.residual_bound;
            note = "CG preconditioned by the cycle took over";
          }
          if (!solved && s.options.direct_after > 0) {
            if (!s.direct) s.make_direct();
            petsc_check(KSPSolve(s.direct, s.b, s.x), "KSPSolve");
            s.prefer_direct = true;
            report.direct_fallback = true;
            rel = s.relative_residual();
            note = "a distributed Cholesky factorization (MUMPS) solved it";
            solved = rel <= s.options.residual_bound;
          }
          if (!solved) status = SolveStatus::max_iterations;
        }
        column.reason = note.empty() ? "cycles under the bound" : note;
      } else {
        status = status_of(reason);
      }
      column.relative_residual = rel;
      if (severity(status) > severity(report.status)) report.status = status;
      report.iterations += column.iterations;
      report.relative_residual = std::max(report.relative_residual, rel);
      report.residuals.push_back(rel);
      report.columns.push_back(column);
      const PetscScalar* w = nullptr;
      petsc_check(VecGetArrayRead(s.x, &w), "VecGetArrayRead");
      for (int i = 0; i < n; ++i) Y(i, c) = w[i];
      petsc_check(VecRestoreArrayRead(s.x, &w), "VecRestoreArrayRead");
      if (!note.empty()) report.message = joined_messages(report.message, note);
    }
    if (report.status != SolveStatus::converged && report.message.empty())
      report.message = report.columns.empty() ? "" : report.columns.back().reason;
  } catch (const PetscFailure& e) {
    report.status = SolveStatus::failed;
    report.message = e.what();
  }
  return report;
}

std::vector<std::pair<std::string, std::string>> RankSystem::settings() const {
  const Impl& s = *impl_;
  std::vector<std::pair<std::string, std::string>> out;
  KSPType kt = nullptr;
  PC pc = nullptr;
  PCType pt = nullptr;
  KSPGetType(s.ksp, &kt);
  KSPGetPC(s.ksp, &pc);
  PCGetType(pc, &pt);
  out.emplace_back("ksp_type", kt ? kt : "");
  out.emplace_back("pc_type", pt ? pt : "");
  out.emplace_back("options_prefix", s.prefix);
  out.emplace_back("inserted_options", s.inserted);
  out.emplace_back("petsc_options", s.options.petsc_options);
  out.emplace_back("version", PetscRuntime::instance().version());
  return out;
}

std::string RankSystem::name() const {
  const Impl& s = *impl_;
  KSPType kt = nullptr;
  PC pc = nullptr;
  PCType pt = nullptr;
  KSPGetType(s.ksp, &kt);
  KSPGetPC(s.ksp, &pc);
  PCGetType(pc, &pt);
  if (s.options.solver == "multigrid") return "distributed-multigrid";
  return std::string("petsc-") + (kt ? kt : "?") + "-" + (pt ? pt : "?");
}

int RankSystem::levels() const {
  return impl_->level_count;
}

double RankSystem::matrix_bytes() const {
  return storage_bytes(impl_->A);
}

double RankSystem::preconditioner_bytes() const {
  const Impl& s = *impl_;
  PC pc = nullptr;
  KSPGetPC(s.ksp, &pc);
  PetscBool multigrid = PETSC_FALSE;
  PetscObjectTypeCompareAny((PetscObject)pc, &multigrid, PCMG, PCGAMG, "");
  if (!multigrid) return -1;
  PetscInt levels = 0;
  if (PCMGGetLevels(pc, &levels) != 0) return -1;
  double bytes = 0;
  for (PetscInt l = 0; l < levels; ++l) {
    if (l + 1 < levels) {
      KSP smoother = nullptr;
      Mat op = nullptr;
      PCMGGetSmoother(pc, l, &smoother);
      KSPGetOperators(smoother, &op, nullptr);
      if (op) bytes += storage_bytes(op);
    }
    if (l > 0) {
      Mat p = nullptr;
      PCMGGetInterpolation(pc, l, &p);
      if (p) bytes += storage_bytes(p);
    }
  }
  return bytes;
}

#endif

}  // namespace mcf::dist
