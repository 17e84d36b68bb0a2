#include "distributed/rank_system.h"

#include "distributed/comm.h"
#include "distributed/rank_block_cg.h"
#include "distributed/rank_multigrid.h"
#include "solvers/multigrid_fallback.h"
#include "solvers/petsc_runtime.h"
#include "solvers/petsc_solver.h"

#include <algorithm>
#include <array>
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

/// The KSP's type and its PC's type ("" where not set).
std::pair<std::string, std::string> ksp_and_pc_types(KSP ksp) {
  KSPType kt = nullptr;
  PC pc = nullptr;
  PCType pt = nullptr;
  KSPGetType(ksp, &kt);
  KSPGetPC(ksp, &pc);
  PCGetType(pc, &pt);
  return {kt ? kt : "", pt ? pt : ""};
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
  Vec ghosted = nullptr;                     // block size 3: the owned rows' xyz, then the ghosts'
  KSP ksp = nullptr, direct = nullptr;       // solver "petsc"; MUMPS, the guard's last step
  std::unique_ptr<RankMultigrid> multigrid;  // solvers "multigrid" and "pcg"
  bool guarded = false;                      // fixed multigrid cycles with a residual bound
  double start_fit = -1;                     // the solve under way's (RankSystem::solve)
  bool prefer_direct = false;                // an earlier step needed the factorization
  int level_count = 1;

  Impl(const RankMesh& m, MassKind mass, RankSolverOptions o)
      : mesh(m), options(std::move(o)), basis(TriangleMesh{m.vertices, m.faces}, mass) {}

  ~Impl() {
    multigrid.reset();
    if (ksp) KSPDestroy(&ksp);
    if (direct) KSPDestroy(&direct);
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
    // The surface multigrid across ranks, three columns at a time (rank_multigrid.h): fixed
    // cycles (tolerance 0) converged only at the residual bound, where CG by the cycle and then
    // MUMPS take over; cycles to a tolerance; or CG preconditioned by one cycle.
    multigrid =
        std::make_unique<RankMultigrid>(mesh, RankCycle{options.cycle != "V", options.smooth});
    level_count = multigrid->levels();
    guarded = options.solver == "multigrid" && options.tolerance <= 0 && options.residual_bound > 0;
    std::snprintf(numbers, sizeof numbers, "%s(%d,%d) %s, %d levels, coarsest %lld vertices",
                  options.cycle == "V" ? "V" : "W", options.smooth, options.smooth,
                  options.solver == "multigrid" ? "cycles" : "preconditioning CG", level_count,
                  multigrid->coarsest_size());
    inserted = numbers;
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

  void load_column(Vec v, const Coefficients& X, int c) {
    PetscScalar* w = nullptr;
    petsc_check(VecGetArray(v, &w), "VecGetArray");
    for (int i = 0; i < mesh.owned; ++i) w[i] = X(i, c);
    petsc_check(VecRestoreArray(v, &w), "VecRestoreArray");
  }
  void store_column(Vec v, Coefficients& X, int c) {
    const PetscScalar* w = nullptr;
    petsc_check(VecGetArrayRead(v, &w), "VecGetArrayRead");
    for (int i = 0; i < mesh.owned; ++i) X(i, c) = w[i];
    petsc_check(VecRestoreArrayRead(v, &w), "VecRestoreArrayRead");
  }

  /// Solver "petsc": PETSc's KSP on each coordinate in turn.
  void solve_columns(const Coefficients& rhs, const Coefficients& start, Coefficients& Y,
                     SolveReport& report) {
    for (int c = 0; c < 3; ++c) {
      load_column(b, rhs, c);
      load_column(x, start, c);
      petsc_check(KSPSolve(ksp, b, x), "KSPSolve");
      KSPConvergedReason reason;
      PetscInt its = 0;
      petsc_check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
      petsc_check(KSPGetIterationNumber(ksp, &its), "KSPGetIterationNumber");
      ColumnReport column;
      column.iterations = int(its);
      column.reason = reason_name(reason);
      column.relative_residual = relative_residual();
      const SolveStatus status = status_of(reason);
      if (severity(status) > severity(report.status)) report.status = status;
      report.iterations += column.iterations;
      report.relative_residual = std::max(report.relative_residual, column.relative_residual);
      report.residuals.push_back(column.relative_residual);
      report.columns.push_back(column);
      store_column(x, Y, c);
    }
  }

  /// Solvers "multigrid" and "pcg": the three coordinates together (rank_multigrid.h,
  /// rank_block_cg.h); a guarded step above its bound goes on with CG by the cycle, then MUMPS
  /// on each coordinate still above it.
  void solve_blocks(const Coefficients& rhs, const Coefficients& start, Coefficients& Y,
                    SolveReport& report) {
    const int n = mesh.owned;
    multigrid->set_operator(A);
    std::vector<double> B(4 * std::size_t(n), 0.0), X(4 * std::size_t(n), 0.0);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        B[4 * std::size_t(i) + std::size_t(c)] = rhs(i, c);
        X[4 * std::size_t(i) + std::size_t(c)] = start(i, c);
      }
    std::array<int, 3> iterations{0, 0, 0};
    std::array<std::string, 3> reasons;
    std::array<SolveStatus, 3> status{SolveStatus::converged, SolveStatus::converged,
                                      SolveStatus::converged};
    std::array<double, 3> rel{};
    if (options.solver == "pcg") {
      const BlockCgReport cg = block_cg(*multigrid, B.data(), X.data(), {true, true, true},
                                        options.tolerance, options.max_iterations);
      rel = relative_residuals(*multigrid, B.data(), X.data());
      for (std::size_t c = 0; c < 3; ++c) {
        iterations[c] = cg.iterations[c];
        status[c] = cg.converged[c]   ? SolveStatus::converged
                    : cg.breakdown[c] ? SolveStatus::numerical_issue
                                      : SolveStatus::max_iterations;
        reasons[c] = cg.converged[c]   ? "CG converged to the tolerance"
                     : cg.breakdown[c] ? "CG broke down (p'Ap <= 0)"
                                       : "CG reached its iteration limit";
      }
    } else if (options.tolerance > 0) {
      // Cycles until every coordinate is at the tolerance, at most `cycles`.
      rel = relative_residuals(*multigrid, B.data(), X.data());
      const double first = *std::max_element(rel.begin(), rel.end());
      int k = 0;
      const auto above = [&]() {
        return *std::max_element(rel.begin(), rel.end()) > options.tolerance;
      };
      while (k < options.cycles && above()) {
        multigrid->cycle(B.data(), X.data());
        ++k;
        rel = relative_residuals(*multigrid, B.data(), X.data());
        for (std::size_t c = 0; c < 3; ++c)
          if (iterations[c] == 0 && rel[c] <= options.tolerance) iterations[c] = k;
      }
      const double last = *std::max_element(rel.begin(), rel.end());
      if (k > 0 && first > 0 && last > 0) report.contraction = std::pow(last / first, 1.0 / k);
      for (std::size_t c = 0; c < 3; ++c) {
        const bool met = rel[c] <= options.tolerance;
        if (!met) iterations[c] = k;
        status[c] = met ? SolveStatus::converged : SolveStatus::max_iterations;
        reasons[c] = met ? "cycles to the tolerance" : "cycles reached their limit";
      }
    } else {
      for (int k = 0; k < options.cycles; ++k) multigrid->cycle(B.data(), X.data());
      rel = relative_residuals(*multigrid, B.data(), X.data());
      iterations.fill(options.cycles);
      reasons.fill(guarded ? "cycles under the bound" : "fixed cycles");
      if (guarded && !options.bound_smooth_steps && start_fit >= kSmoothStartFit)
        keep_smooth_step(rel, reasons, status, report);
      else if (guarded)
        guard(B, X, rel, iterations, reasons, status, report);
    }
    for (std::size_t c = 0; c < 3; ++c) {
      if (!std::isfinite(rel[c])) status[c] = SolveStatus::numerical_issue;
      ColumnReport column;
      column.iterations = iterations[c];
      column.relative_residual = rel[c];
      column.reason = reasons[c];
      if (severity(status[c]) > severity(report.status)) report.status = status[c];
      report.iterations = std::max(report.iterations, iterations[c]);
      report.relative_residual = std::max(report.relative_residual, rel[c]);
      report.residuals.push_back(rel[c]);
      report.columns.push_back(column);
    }
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) Y(i, c) = X[4 * std::size_t(i) + std::size_t(c)];
  }

  /// A smooth step (its start fit the prediction: solvers/multigrid_fallback.h, "Smooth steps")
  /// keeps its cycles in the coordinates above the bound, with status max_iterations and a note.
  void keep_smooth_step(const std::array<double, 3>& rel, std::array<std::string, 3>& reasons,
                        std::array<SolveStatus, 3>& status, SolveReport& report) const {
    bool kept = false;
    for (std::size_t c = 0; c < 3; ++c)
      if (std::isfinite(rel[c]) && rel[c] > options.residual_bound) {
        status[c] = SolveStatus::max_iterations;
        reasons[c] = "cycles above the bound, kept: a smooth step";
        kept = true;
      }
    if (!kept) return;
    char note[128];
    std::snprintf(note, sizeof note,
                  "cycles ended above the residual bound %.3g; kept: a smooth step (the start "
                  "fit the prediction at %.2f)",
                  options.residual_bound, start_fit);
    report.message = joined_messages(report.message, note);
  }

  /// Fixed cycles ended above the residual bound in some coordinates: CG preconditioned by the
  /// cycle to the bound (at most `direct_after` iterations; skipped once a step needed more),
  /// then MUMPS on the coordinates still above it.
  void guard(std::vector<double>& B, std::vector<double>& X, std::array<double, 3>& rel,
             std::array<int, 3>& iterations, std::array<std::string, 3>& reasons,
             std::array<SolveStatus, 3>& status, SolveReport& report) {
    const double bound = options.residual_bound;
    const auto above = [&](std::size_t c) { return std::isfinite(rel[c]) && rel[c] > bound; };
    std::array<bool, 3> active{above(0), above(1), above(2)};
    if (!active[0] && !active[1] && !active[2]) return;
    if (!prefer_direct) {
      const BlockCgReport cg = block_cg(*multigrid, B.data(), X.data(), active, bound,
                                        std::max(options.direct_after, 1));
      rel = relative_residuals(*multigrid, B.data(), X.data());
      for (std::size_t c = 0; c < 3; ++c)
        if (active[c]) {
          iterations[c] += cg.iterations[c];
          report.fallback_iterations += cg.iterations[c];
          reasons[c] = "CG preconditioned by the cycle took over";
        }
      report.message = joined_messages(report.message, "CG preconditioned by the cycle took over");
    }
    active = {above(0), above(1), above(2)};
    if (options.direct_after > 0 && (active[0] || active[1] || active[2])) {
      if (!direct) make_direct();
      Coefficients Xc(mesh.owned, 3);
      for (int c = 0; c < 3; ++c) {
        if (!active[std::size_t(c)]) continue;
        for (int i = 0; i < mesh.owned; ++i) {
          Xc(i, 0) = B[4 * std::size_t(i) + std::size_t(c)];
          Xc(i, 1) = X[4 * std::size_t(i) + std::size_t(c)];
        }
        load_column(b, Xc, 0);
        load_column(x, Xc, 1);
        petsc_check(KSPSolve(direct, b, x), "KSPSolve");
        store_column(x, Xc, 1);
        for (int i = 0; i < mesh.owned; ++i) X[4 * std::size_t(i) + std::size_t(c)] = Xc(i, 1);
        reasons[std::size_t(c)] = "a distributed Cholesky factorization (MUMPS) solved it";
      }
      prefer_direct = true;
      report.direct_fallback = true;
      rel = relative_residuals(*multigrid, B.data(), X.data());
      report.message =
          joined_messages(report.message, "a distributed Cholesky factorization (MUMPS) solved it");
    }
    for (std::size_t c = 0; c < 3; ++c)
      if (above(c)) status[c] = SolveStatus::max_iterations;
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

Coefficients RankSystem::apply_sum(double a, double b, const Coefficients& owned) {
  const Positions X = with_ghosts(owned);
  const int n = impl_->mesh.owned;
  return a * owned_product(impl_->basis.mass(), X, n) +
         b * owned_product(impl_->basis.stiffness(), X, n);
}

SolveReport RankSystem::solve(double a, double b, const Coefficients& R, const Coefficients& held,
                              const Coefficients& warm, Coefficients& Y, double start_fit) {
  Impl& s = *impl_;
  s.start_fit = start_fit;
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
    Coefficients rhs = R;
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
        for (int i = 0; i < n; ++i) rhs(i, c) -= w[i];
        petsc_check(VecRestoreArrayRead(s.r, &w), "VecRestoreArrayRead");
        for (const int i : held_) rhs(i, c) = held(i, c);
      }
      petsc_check(MatZeroRowsColumns(s.A, PetscInt(s.held_rows.size()), s.held_rows.data(), 1.0,
                                     nullptr, nullptr),
                  "MatZeroRowsColumns");
    }
    Coefficients start = warm;
    for (const int i : held_) start.row(i) = held.row(i);
    if (s.multigrid)
      s.solve_blocks(rhs, start, Y, report);
    else
      s.solve_columns(rhs, start, Y, report);
    if (report.status != SolveStatus::converged && report.message.empty())
      report.message = report.columns.empty() ? "" : report.columns.back().reason;
  } catch (const PetscFailure& e) {
    report.status = SolveStatus::failed;
    report.message = e.what();
  } catch (const std::runtime_error& e) {
    report.status = SolveStatus::failed;
    report.message = e.what();
  }
  return report;
}

std::vector<std::pair<std::string, std::string>> RankSystem::settings() const {
  const Impl& s = *impl_;
  std::vector<std::pair<std::string, std::string>> out;
  if (s.multigrid) {
    out.emplace_back("method", s.options.solver == "pcg"
                                   ? "CG on the three coordinates together, preconditioned by "
                                     "one cycle of the surface multigrid across ranks"
                                   : "the surface multigrid across ranks, the three coordinates "
                                     "together");
    out.emplace_back("cycle", s.inserted);
    out.emplace_back("coarsest_solve",
                     "Cholesky (LDLT) of the gathered coarsest level on every rank");
    out.emplace_back("direct_fallback", "PETSc's Cholesky with MUMPS");
  } else {
    const auto [kt, pt] = ksp_and_pc_types(s.ksp);
    out.emplace_back("ksp_type", kt);
    out.emplace_back("pc_type", pt);
    out.emplace_back("options_prefix", s.prefix);
    out.emplace_back("inserted_options", s.inserted);
    out.emplace_back("petsc_options", s.options.petsc_options);
  }
  out.emplace_back("version", PetscRuntime::instance().version());
  return out;
}

std::string RankSystem::name() const {
  const Impl& s = *impl_;
  if (s.options.solver == "multigrid") return "distributed-multigrid";
  if (s.options.solver == "pcg") return "distributed-pcg-multigrid";
  const auto [kt, pt] = ksp_and_pc_types(s.ksp);
  return "petsc-" + (kt.empty() ? "?" : kt) + "-" + (pt.empty() ? "?" : pt);
}

int RankSystem::levels() const {
  return impl_->level_count;
}

double RankSystem::matrix_bytes() const {
  return storage_bytes(impl_->A);
}

double RankSystem::preconditioner_bytes() const {
  const Impl& s = *impl_;
  if (s.multigrid) return s.multigrid->bytes();
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
