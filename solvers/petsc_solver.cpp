#include "solvers/petsc_solver.h"

#include "solvers/petsc_runtime.h"

#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

#ifdef MCFBENCH_HAVE_PETSC
#include "core/parallel.h"

#include <petscksp.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#endif

namespace mcf {

namespace {
SolveReport failed_report(std::string message) {
  SolveReport r;
  r.status = SolveStatus::failed;
  r.message = std::move(message);
  return r;
}

}  // namespace

std::string petsc_default_options(double relative_tolerance, int max_iterations) {
  char numbers[96];
  std::snprintf(numbers, sizeof numbers, "-ksp_rtol %.17g -ksp_max_it %d", relative_tolerance,
                max_iterations);
  // The levels' smoother: Richardson with symmetric SOR, not GAMG's Chebyshev. Chebyshev needs a
  // bound of the level's largest eigenvalue: taken from the prolongator smoothing's estimate it
  // goes stale while the interpolation is kept, and the preconditioner turned indefinite after 6
  // steps of MCF on the bunny; estimated by Chebyshev itself it fell short on the octree's
  // (paper's) system, indefinite in the first solve. A symmetric SOR sweep needs no bound and
  // keeps the cycle symmetric positive definite, so CG applies; it also took fewer iterations on
  // both (docs/petsc.md).
  return std::string(
             "-ksp_type cg -pc_type gamg -pc_gamg_reuse_interpolation true "
             "-mg_levels_ksp_type richardson -mg_levels_pc_type sor "
             "-ksp_initial_guess_nonzero true ") +
         numbers;
}

#ifndef MCFBENCH_HAVE_PETSC

struct PetscSolver::Impl {};

PetscSolver::PetscSolver(PetscSolverOptions) {
  throw PetscUnavailable("solver.name: \"petsc\": " + petsc_unavailable_message());
}
PetscSolver::~PetscSolver() = default;
std::string PetscSolver::name() const {
  return "petsc";
}
SolveReport PetscSolver::set_matrix(const SparseMatrix&, HierarchyView) {
  return failed_report(petsc_unavailable_message());
}
SolveReport PetscSolver::set_matrix_sum(const MatrixSum&, HierarchyView) {
  return failed_report(petsc_unavailable_message());
}
SolveReport PetscSolver::solve_in_place(const ConstMatrixRef&, MatrixRef) {
  return failed_report(petsc_unavailable_message());
}
std::vector<std::pair<std::string, std::string>> PetscSolver::settings() const {
  return {};
}
int PetscSolver::preconditioner_setups() const {
  return 0;
}
int PetscSolver::new_patterns() const {
  return 0;
}
int PetscSolver::pattern_comparisons() const {
  return 0;
}
std::string PetscSolver::version() {
  return "";
}

#else

namespace {

using Eigen::Index;

/// The option names (without the leading '-', lower case) in a PETSc options string: the
/// tokens that begin with '-' and a letter (a value such as -1 is not a name).
std::vector<std::string> option_names(const std::string& options) {
  std::vector<std::string> names;
  std::istringstream in(options);
  std::string token;
  while (in >> token)
    if (token.size() > 1 && token[0] == '-' && std::isalpha(static_cast<unsigned char>(token[1]))) {
      std::string name = token.substr(1);
      for (char& ch : name) ch = char(std::tolower(static_cast<unsigned char>(ch)));
      names.push_back(name);
    }
  return names;
}

/// The converged reason's name ("CONVERGED_RTOL", "DIVERGED_ITS").
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

}  // namespace

struct PetscSolver::Impl {
  PetscSolverOptions options;
  std::string prefix;    // this solver's prefix in the options database ("mcf3_")
  std::string inserted;  // defaults, then the user's options
  std::string ksp_type, pc_type, name;
  double rtol = 0;  // -ksp_rtol and -ksp_max_it as the KSP took them
  int max_it = 0;
  std::string norm_type;                  // the residual norm the KSP tests
  bool reuse_interpolation = false;       // GAMG with -pc_gamg_reuse_interpolation
  PetscBool user_reuse_pc = PETSC_FALSE;  // -ksp_reuse_preconditioner: kept even when values change

  // Across MPI ranks (PETSC_COMM_WORLD of more than one rank) every rank holds the whole system,
  // as every rank runs the whole flow, and hands PETSc its own block of rows [row_begin,
  // row_end); the solution is gathered back to every rank (gather, all).
  bool distributed = false;
  MPI_Comm comm = PETSC_COMM_SELF;
  PetscInt row_begin = 0, row_end = 0;
  std::vector<PetscInt> local_ia, local_ja;  // the block's rows (distributed only)
  std::vector<PetscScalar> kept_values;      // the values in the Mat (distributed only)
  VecScatter gather = nullptr;
  Vec all = nullptr;

  // An AIJ matrix's storage on this rank: a value and a column index per stored entry, a row
  // offset per local row (PETSc's AIJ layout; an MPIAIJ block counts its two parts together).
  static double storage_bytes(Mat m) {
    MatInfo info;
    petsc_check(MatGetInfo(m, MAT_LOCAL, &info), "MatGetInfo");
    PetscInt local_rows = 0, local_cols = 0;
    petsc_check(MatGetLocalSize(m, &local_rows, &local_cols), "MatGetLocalSize");
    return info.nz_used * double(sizeof(PetscScalar) + sizeof(PetscInt)) +
           double(local_rows + 1) * double(sizeof(PetscInt));
  }
  double largest_over_ranks(double local) const {
    double largest = local;
    if (distributed) MPI_Allreduce(&local, &largest, 1, MPI_DOUBLE, MPI_MAX, comm);
    return largest;
  }
  // The coarse levels' operators and the interpolations of a multigrid preconditioner, after its
  // set-up; -1 where the PC is not PETSc's multigrid (hypre keeps its hierarchy to itself).
  double hierarchy_bytes() const {
    PC pc = nullptr;
    petsc_check(KSPGetPC(ksp, &pc), "KSPGetPC");
    PetscBool multigrid = PETSC_FALSE;
    petsc_check(PetscObjectTypeCompareAny((PetscObject)pc, &multigrid, PCMG, PCGAMG, ""),
                "PetscObjectTypeCompareAny");
    if (!multigrid) return -1;
    PetscInt levels = 0;
    petsc_check(PCMGGetLevels(pc, &levels), "PCMGGetLevels");
    double local = 0;
    for (PetscInt l = 0; l < levels; ++l) {
      if (l + 1 < levels) {  // the finest level's operator is A itself
        KSP smoother = nullptr;
        Mat op = nullptr;
        petsc_check(PCMGGetSmoother(pc, l, &smoother), "PCMGGetSmoother");
        petsc_check(KSPGetOperators(smoother, &op, nullptr), "KSPGetOperators");
        if (op) local += storage_bytes(op);
      }
      if (l > 0) {
        Mat p = nullptr;
        petsc_check(PCMGGetInterpolation(pc, l, &p), "PCMGGetInterpolation");
        if (p) local += storage_bytes(p);
      }
    }
    return largest_over_ranks(local);
  }

  KSP ksp = nullptr;
  Mat A = nullptr;
  Vec b = nullptr, x = nullptr, r = nullptr;
  Index rows = -1, nonzeros = 0;
  std::vector<int> outer, inner;  // the Mat's pattern (Eigen's compressed arrays)
  KeptPattern kept;
  bool have_matrix = false;
  std::string setup;  // what the next solve does with the preconditioner: new | refreshed | kept
  int setups = 0, patterns = 0;
  // The storage of the matrix's block on the rank holding the largest one, and of the multigrid
  // preconditioner's coarse operators and interpolations (PCMG and GAMG; -1 for other PCs),
  // largest over the set-ups seen: what distributing the solve divides.
  double matrix_bytes_per_rank = 0, preconditioner_bytes_per_rank = -1;
  std::vector<PetscReal> history;

  ~Impl() {
    destroy();
    // This solver's options leave the database with it: a process that makes many solvers (a
    // study's cells) would otherwise fill it (PETSc holds at most 512 options).
    PetscBool initialized = PETSC_FALSE, finalized = PETSC_FALSE;
    PetscInitialized(&initialized);
    PetscFinalized(&finalized);
    if (initialized && !finalized && !prefix.empty())
      for (const std::string& name : option_names(inserted))
        PetscOptionsClearValue(nullptr, ("-" + prefix + name).c_str());
  }
  void destroy() {
    if (ksp != nullptr) KSPDestroy(&ksp);
    if (A != nullptr) MatDestroy(&A);
    if (b != nullptr) VecDestroy(&b);
    if (x != nullptr) VecDestroy(&x);
    if (r != nullptr) VecDestroy(&r);
    if (gather != nullptr) VecScatterDestroy(&gather);
    if (all != nullptr) VecDestroy(&all);
    local_ia.clear();
    local_ja.clear();
    kept_values.clear();
    rows = -1;
    nonzeros = 0;
    have_matrix = false;
  }

  /// A KSP on `on` with this solver's prefix and options (not yet given operators).
  KSP make_ksp(MPI_Comm on) const {
    KSP k = nullptr;
    petsc_check(KSPCreate(on, &k), "KSPCreate");
    try {
      petsc_check(KSPSetOptionsPrefix(k, prefix.c_str()), "KSPSetOptionsPrefix");
      petsc_check(KSPSetFromOptions(k), "KSPSetFromOptions");
      // CG tests the true residual unless the user chose a norm, so that the tolerance means
      // ||b - A x|| / ||b|| as for the other solvers (PETSc's default for CG is the
      // preconditioned residual's norm). Other methods keep PETSc's default, recorded in
      // settings(): not all of them support the unpreconditioned norm (MINRES does not).
      KSPType type = nullptr;
      petsc_check(KSPGetType(k, &type), "KSPGetType");
      PetscBool norm_given = PETSC_FALSE;
      petsc_check(PetscOptionsHasName(nullptr, prefix.c_str(), "-ksp_norm_type", &norm_given),
                  "PetscOptionsHasName");
      if (!norm_given && type != nullptr && std::string(type) == KSPCG)
        petsc_check(KSPSetNormType(k, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
    } catch (...) {
      KSPDestroy(&k);
      throw;
    }
    return k;
  }

  /// Keeps Eigen's pattern and makes a Mat of it with values from fill(v) (v: nonzeros doubles).
  template <class Fill>
  void new_matrix(const SparseRef& S, Fill fill) {
    destroy();
    rows = S.rows();
    nonzeros = S.nonZeros();
    outer.assign(S.outerIndexPtr(), S.outerIndexPtr() + rows + 1);
    inner.assign(S.innerIndexPtr(), S.innerIndexPtr() + nonzeros);
    // Full symmetric storage: the compressed columns are the compressed rows.
    std::vector<PetscInt> ia(outer.begin(), outer.end()), ja(inner.begin(), inner.end());
    std::vector<PetscScalar> values(static_cast<std::size_t>(nonzeros));
    fill(values.data());
    const PetscInt n = PetscInt(rows);
    petsc_check(MatCreate(comm, &A), "MatCreate");
    if (!distributed) {
      petsc_check(MatSetSizes(A, n, n, n, n), "MatSetSizes");
      petsc_check(MatSetType(A, MATSEQAIJ), "MatSetType");
      petsc_check(MatSeqAIJSetPreallocationCSR(A, ia.data(), ja.data(), values.data()),
                  "MatSeqAIJSetPreallocationCSR");
    } else {
      PetscInt local = PETSC_DECIDE, global = n;
      petsc_check(PetscSplitOwnership(comm, &local, &global), "PetscSplitOwnership");
      petsc_check(MPI_Scan(&local, &row_end, 1, MPIU_INT, MPI_SUM, comm), "MPI_Scan");
      row_begin = row_end - local;
      local_ia.resize(std::size_t(local) + 1);
      for (PetscInt i = 0; i <= local; ++i) local_ia[i] = ia[row_begin + i] - ia[row_begin];
      local_ja.assign(ja.begin() + ia[row_begin], ja.begin() + ia[row_end]);
      petsc_check(MatSetSizes(A, local, local, n, n), "MatSetSizes");
      petsc_check(MatSetType(A, MATMPIAIJ), "MatSetType");
      petsc_check(MatMPIAIJSetPreallocationCSR(A, local_ia.data(), local_ja.data(),
                                               values.data() + ia[row_begin]),
                  "MatMPIAIJSetPreallocationCSR");
      kept_values = values;
    }
    // Every flow's system is symmetric, whatever its values become: GAMG then skips making
    // its graph symmetric.
    petsc_check(MatSetOption(A, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption");
    petsc_check(MatSetOption(A, MAT_SYMMETRY_ETERNAL, PETSC_TRUE), "MatSetOption");
    petsc_check(MatSetOption(A, MAT_NEW_NONZERO_LOCATION_ERR, PETSC_TRUE), "MatSetOption");
    matrix_bytes_per_rank = std::max(matrix_bytes_per_rank, largest_over_ranks(storage_bytes(A)));
    MatInfo info;
    petsc_check(MatGetInfo(A, MAT_GLOBAL_SUM, &info), "MatGetInfo");
    // The value array is then Eigen's, entry for entry (refresh() relies on it).
    if (Index(info.nz_used) != nonzeros)
      throw PetscFailure("PETSc's AIJ matrix holds " + std::to_string(Index(info.nz_used)) +
                         " entries of " + std::to_string(nonzeros));
    petsc_check(MatCreateVecs(A, &x, &b), "MatCreateVecs");
    petsc_check(VecDuplicate(b, &r), "VecDuplicate");
    if (distributed) petsc_check(VecScatterCreateToAll(x, &gather, &all), "VecScatterCreateToAll");
    ksp = make_ksp(comm);
    petsc_check(KSPSetOperators(ksp, A, A), "KSPSetOperators");
    PetscReal rtol = 0, abstol = 0, dtol = 0;
    PetscInt max_it = 0;
    petsc_check(KSPGetTolerances(ksp, &rtol, &abstol, &dtol, &max_it), "KSPGetTolerances");
    history.assign(static_cast<std::size_t>(std::max<PetscInt>(max_it, 0) + 1), 0.0);
    petsc_check(KSPSetResidualHistory(ksp, history.data(), PetscInt(history.size()), PETSC_TRUE),
                "KSPSetResidualHistory");
    have_matrix = true;
    setup = "new";
    ++patterns;
  }

  /// Rewrites the values (same pattern) from fill(v); a fill equal to the current values bit for
  /// bit leaves the Mat alone, and its preconditioner is kept whole.
  template <class Fill>
  void refresh(Fill fill) {
    std::vector<PetscScalar> values(static_cast<std::size_t>(nonzeros));
    fill(values.data());
    bool same = false;
    if (distributed) {
      // Every rank compares the whole system (the same on every rank), so all take one branch.
      same = values == kept_values;
    } else {
      const PetscScalar* current = nullptr;
      petsc_check(MatSeqAIJGetArrayRead(A, &current), "MatSeqAIJGetArrayRead");
      same = std::equal(values.begin(), values.end(), current);
      petsc_check(MatSeqAIJRestoreArrayRead(A, &current), "MatSeqAIJRestoreArrayRead");
    }
    if (same) {
      petsc_check(KSPSetReusePreconditioner(ksp, PETSC_TRUE), "KSPSetReusePreconditioner");
      if (setup != "new") setup = "kept";
      return;
    }
    if (distributed) {
      const PetscInt local = row_end - row_begin, n = PetscInt(rows);
      petsc_check(MatUpdateMPIAIJWithArrays(A, local, local, n, n, local_ia.data(), local_ja.data(),
                                            values.data() + outer[row_begin]),
                  "MatUpdateMPIAIJWithArrays");
      kept_values = std::move(values);
    } else {
      PetscScalar* v = nullptr;
      petsc_check(MatSeqAIJGetArrayWrite(A, &v), "MatSeqAIJGetArrayWrite");
      std::copy(values.begin(), values.end(), v);
      petsc_check(MatSeqAIJRestoreArrayWrite(A, &v), "MatSeqAIJRestoreArrayWrite");
    }
    // The assembly makes the new values a new object state (through public calls only): the
    // next KSPSolve then sets the preconditioner up again on SAME_NONZERO_PATTERN, unless the
    // user asked to keep it (-ksp_reuse_preconditioner). It moves no entry: the pattern is full.
    petsc_check(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
    petsc_check(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
    petsc_check(KSPSetReusePreconditioner(ksp, user_reuse_pc), "KSPSetReusePreconditioner");
    if (setup != "new") setup = user_reuse_pc ? "kept" : "refreshed";
  }

  bool same_pattern_as(const SparseRef& S, std::uint64_t key) {
    const bool sized =
        have_matrix && S.rows() == rows && S.cols() == rows && S.nonZeros() == nonzeros;
    return kept.same(sized, key, [&] {
      return std::equal(outer.begin(), outer.end(), S.outerIndexPtr()) &&
             std::equal(inner.begin(), inner.end(), S.innerIndexPtr());
    });
  }

  template <class Fill>
  SolveReport set(const SparseRef& S, std::uint64_t key, Fill fill) {
    SolveReport rep;
    try {
      if (same_pattern_as(S, key))
        refresh(fill);
      else
        new_matrix(S, fill);
    } catch (const PetscFailure& e) {
      destroy();
      rep.status = SolveStatus::failed;
      rep.message = e.what();
    }
    return rep;
  }
};

PetscSolver::PetscSolver(PetscSolverOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.options = std::move(options);
  PetscRuntime& runtime = PetscRuntime::instance();
  s.prefix = runtime.new_prefix();
  s.distributed = runtime.size() > 1;
  s.comm = s.distributed ? PETSC_COMM_WORLD : PETSC_COMM_SELF;
  s.inserted = petsc_default_options(s.options.relative_tolerance, s.options.max_iterations) + " " +
               s.options.options;
  auto refuse = [&](const std::string& why) {
    throw std::invalid_argument("solver.petsc_options: \"" + s.options.options + "\": " + why);
  };
  try {
    petsc_check(PetscOptionsPrefixPush(nullptr, s.prefix.c_str()), "PetscOptionsPrefixPush");
    const PetscErrorCode inserted = PetscOptionsInsertString(nullptr, s.inserted.c_str());
    petsc_check(PetscOptionsPrefixPop(nullptr), "PetscOptionsPrefixPop");
    petsc_check(inserted, "PetscOptionsInsertString");
  } catch (const PetscFailure& e) {
    refuse(e.what());
  }

  // The trial: the options set up and run on a 48 x 48 five-point Laplacian, so that an unknown
  // type, a combination PETSc refuses and an option nothing reads are found before a flow
  // starts (a multigrid's level options are read only when its levels are built).
  KSP trial = nullptr;
  Mat L = nullptr;
  Vec tb = nullptr, tx = nullptr;
  try {
    trial = s.make_ksp(PETSC_COMM_SELF);
    const PetscInt g = 48, n = g * g;
    petsc_check(MatCreateSeqAIJ(PETSC_COMM_SELF, n, n, 5, nullptr, &L), "MatCreateSeqAIJ");
    for (PetscInt i = 0; i < g; ++i)
      for (PetscInt j = 0; j < g; ++j) {
        const PetscInt row = i * g + j;
        PetscInt cols[5];
        PetscScalar vals[5];
        int k = 0;
        auto add = [&](PetscInt c, PetscScalar v) {
          cols[k] = c;
          vals[k++] = v;
        };
        if (i > 0) add(row - g, -1.0);
        if (j > 0) add(row - 1, -1.0);
        add(row, 4.0);
        if (j + 1 < g) add(row + 1, -1.0);
        if (i + 1 < g) add(row + g, -1.0);
        petsc_check(MatSetValues(L, 1, &row, k, cols, vals, INSERT_VALUES), "MatSetValues");
      }
    petsc_check(MatAssemblyBegin(L, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
    petsc_check(MatAssemblyEnd(L, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
    petsc_check(MatSetOption(L, MAT_SYMMETRIC, PETSC_TRUE), "MatSetOption");
    petsc_check(MatCreateVecs(L, &tx, &tb), "MatCreateVecs");
    petsc_check(VecSet(tb, 1.0), "VecSet");
    petsc_check(VecSet(tx, 0.0), "VecSet");
    petsc_check(KSPSetOperators(trial, L, L), "KSPSetOperators");
    petsc_check(KSPSetUp(trial), "KSPSetUp");
    petsc_check(KSPSolve(trial, tb, tx), "KSPSolve");

    KSPType kt = nullptr;
    PCType pt = nullptr;
    PC pc = nullptr;
    petsc_check(KSPGetType(trial, &kt), "KSPGetType");
    petsc_check(KSPGetPC(trial, &pc), "KSPGetPC");
    petsc_check(PCGetType(pc, &pt), "PCGetType");
    s.ksp_type = kt != nullptr ? kt : "";
    s.pc_type = pt != nullptr ? pt : "";
    s.name = "petsc-" + s.ksp_type + "-" + s.pc_type;
    if (s.pc_type == PCHYPRE) {
      const char* h = nullptr;
      petsc_check(PCHYPREGetType(pc, &h), "PCHYPREGetType");
      if (h != nullptr) s.name += std::string("-") + h;
    }
    PetscBool flag = PETSC_FALSE, set = PETSC_FALSE;
    petsc_check(
        PetscOptionsGetBool(nullptr, s.prefix.c_str(), "-pc_gamg_reuse_interpolation", &flag, &set),
        "PetscOptionsGetBool");
    s.reuse_interpolation = s.pc_type == PCGAMG && set && flag;
    petsc_check(KSPGetReusePreconditioner(trial, &s.user_reuse_pc), "KSPGetReusePreconditioner");
    PetscReal rtol = 0, abstol = 0, dtol = 0;
    PetscInt max_it = 0;
    petsc_check(KSPGetTolerances(trial, &rtol, &abstol, &dtol, &max_it), "KSPGetTolerances");
    s.rtol = double(rtol);
    s.max_it = int(max_it);
    KSPNormType norm = KSP_NORM_DEFAULT;
    petsc_check(KSPGetNormType(trial, &norm), "KSPGetNormType");
    s.norm_type = KSPNormTypes[norm];
  } catch (const PetscFailure& e) {
    if (tb != nullptr) VecDestroy(&tb);
    if (tx != nullptr) VecDestroy(&tx);
    if (L != nullptr) MatDestroy(&L);
    if (trial != nullptr) KSPDestroy(&trial);
    refuse(e.what());
  }
  VecDestroy(&tb);
  VecDestroy(&tx);
  MatDestroy(&L);
  KSPDestroy(&trial);

  // Every option the user gave must have been read by now.
  PetscInt left = 0;
  char** names = nullptr;
  char** values = nullptr;
  std::vector<std::string> unused;
  if (PetscOptionsLeftGet(nullptr, &left, &names, &values) == 0) {
    for (const std::string& given : option_names(s.options.options))
      for (PetscInt i = 0; i < left; ++i) {
        std::string name = names[i];
        for (char& ch : name) ch = char(std::tolower(static_cast<unsigned char>(ch)));
        if (name == s.prefix + given &&
            std::find(unused.begin(), unused.end(), given) == unused.end())
          unused.push_back(given);
      }
    PetscOptionsLeftRestore(nullptr, &left, &names, &values);
  }
  if (!unused.empty()) {
    std::string list;
    for (const std::string& u : unused) list += (list.empty() ? "-" : ", -") + u;
    refuse("PETSc did not use " + list + " with KSP " + s.ksp_type + " and PC " + s.pc_type +
           " (misspelt, or not an option of this method)");
  }
}

PetscSolver::~PetscSolver() = default;

std::string PetscSolver::name() const {
  return impl_->name;
}

SolveReport PetscSolver::set_matrix(const SparseMatrix& A, HierarchyView hierarchy) {
  if (A.rows() != A.cols()) return failed_report("matrix is not square");
  if (!A.isCompressed()) {
    SparseMatrix C = A;
    C.makeCompressed();
    return set_matrix(C, hierarchy);
  }
  return impl_->set(SparseRef(A), hierarchy.pattern_key,
                    [&](double* v) { std::copy(A.valuePtr(), A.valuePtr() + A.nonZeros(), v); });
}

SolveReport PetscSolver::set_matrix_sum(const MatrixSum& sum, HierarchyView hierarchy) {
  const SparseRef& M = sum.M;
  if (!summable(sum) || M.rows() != M.cols()) return LinearSolver::set_matrix_sum(sum, hierarchy);
  return impl_->set(M, hierarchy.pattern_key, [&](double* v) {
    parallel_for_chunks(M.nonZeros(), Index(1) << 14, [&](Index, Index b, Index e) {
      for (Index p = b; p < e; ++p) v[p] = sum.entry(p);
    });
  });
}

SolveReport PetscSolver::solve_in_place(const ConstMatrixRef& B, MatrixRef X) {
  Impl& s = *impl_;
  SolveReport rep;
  if (!s.have_matrix) {
    rep.status = SolveStatus::failed;
    rep.message = "set_matrix not called or failed";
    return rep;
  }
  if (B.rows() != s.rows) {
    rep.status = SolveStatus::failed;
    rep.message = "right-hand side has " + std::to_string(B.rows()) + " rows, the matrix " +
                  std::to_string(s.rows);
    return rep;
  }
  rep.preconditioner_setup = s.setup;
  if (s.setup != "kept") ++s.setups;
  s.setup = "kept";  // a second solve on this matrix (a second pass, Taylor-2) keeps it
  std::vector<std::vector<double>> histories;
  try {
    for (Index c = 0; c < B.cols(); ++c) {
      // This rank's rows (all of them when not distributed).
      const Index first = s.distributed ? Index(s.row_begin) : 0;
      const Index count = s.distributed ? Index(s.row_end - s.row_begin) : s.rows;
      PetscScalar* v = nullptr;
      petsc_check(VecGetArrayWrite(s.b, &v), "VecGetArrayWrite");
      std::copy(B.col(c).data() + first, B.col(c).data() + first + count, v);
      petsc_check(VecRestoreArrayWrite(s.b, &v), "VecRestoreArrayWrite");
      petsc_check(VecGetArrayWrite(s.x, &v), "VecGetArrayWrite");
      std::copy(X.col(c).data() + first, X.col(c).data() + first + count, v);
      petsc_check(VecRestoreArrayWrite(s.x, &v), "VecRestoreArrayWrite");

      petsc_check(KSPSolve(s.ksp, s.b, s.x), "KSPSolve");
      if (c == 0 && rep.preconditioner_setup != "kept")
        s.preconditioner_bytes_per_rank =
            std::max(s.preconditioner_bytes_per_rank, s.hierarchy_bytes());
      PetscInt its = 0;
      KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
      petsc_check(KSPGetIterationNumber(s.ksp, &its), "KSPGetIterationNumber");
      petsc_check(KSPGetConvergedReason(s.ksp, &reason), "KSPGetConvergedReason");

      // The whole solution on every rank: each runs the rest of the flow on it.
      Vec whole = s.x;
      if (s.distributed) {
        petsc_check(VecScatterBegin(s.gather, s.x, s.all, INSERT_VALUES, SCATTER_FORWARD),
                    "VecScatterBegin");
        petsc_check(VecScatterEnd(s.gather, s.x, s.all, INSERT_VALUES, SCATTER_FORWARD),
                    "VecScatterEnd");
        whole = s.all;
      }
      const PetscScalar* xv = nullptr;
      petsc_check(VecGetArrayRead(whole, &xv), "VecGetArrayRead");
      std::copy(xv, xv + s.rows, X.col(c).data());
      petsc_check(VecRestoreArrayRead(whole, &xv), "VecRestoreArrayRead");

      // The true residual, whatever norm the KSP tested.
      PetscReal bnorm = 0, rnorm = 0;
      petsc_check(MatMult(s.A, s.x, s.r), "MatMult");
      petsc_check(VecAYPX(s.r, -1.0, s.b), "VecAYPX");
      petsc_check(VecNorm(s.r, NORM_2, &rnorm), "VecNorm");
      petsc_check(VecNorm(s.b, NORM_2, &bnorm), "VecNorm");
      const double relative = bnorm > 0 ? rnorm / bnorm : rnorm;

      const PetscReal* h = nullptr;
      PetscInt hn = 0;
      petsc_check(KSPGetResidualHistory(s.ksp, &h, &hn), "KSPGetResidualHistory");
      std::vector<double> history;
      for (PetscInt i = 1; i < hn; ++i) history.push_back(bnorm > 0 ? h[i] / bnorm : h[i]);
      histories.push_back(std::move(history));

      rep.columns.push_back({int(its), relative, reason_name(reason)});
      rep.iterations += int(its);
      if (!(relative <= rep.relative_residual)) rep.relative_residual = relative;
      const SolveStatus status = status_of(reason);
      if (status != SolveStatus::converged) {
        if (rep.status == SolveStatus::converged) rep.status = status;
        rep.message += (rep.message.empty() ? "" : "; ") + std::string("column ") +
                       std::to_string(c) + ": KSP " + reason_name(reason) + " after " +
                       std::to_string(its) + " iterations (relative residual " +
                       std::to_string(relative) + ")";
      }
      if (!std::isfinite(relative) && rep.status == SolveStatus::converged) {
        rep.status = SolveStatus::numerical_issue;
        rep.message += (rep.message.empty() ? "" : "; ") + std::string("column ") +
                       std::to_string(c) + ": residual not finite";
      }
    }
  } catch (const PetscFailure& e) {
    rep.status = SolveStatus::failed;
    rep.message += (rep.message.empty() ? "" : "; ") + std::string(e.what());
    return rep;
  }
  // residuals[i]: the worst column's relative residual after iteration i+1 (a column that
  // stopped earlier counts with its last one).
  std::size_t longest = 0;
  for (const auto& h : histories) longest = std::max(longest, h.size());
  rep.residuals.assign(longest, 0.0);
  for (const auto& h : histories)
    for (std::size_t i = 0; i < longest; ++i)
      if (!h.empty()) rep.residuals[i] = std::max(rep.residuals[i], h[std::min(i, h.size() - 1)]);
  return rep;
}

std::vector<std::pair<std::string, std::string>> PetscSolver::settings() const {
  const Impl& s = *impl_;
  char tolerance[32];
  std::snprintf(tolerance, sizeof tolerance, "%.17g", s.rtol);
  std::string reuse = "none: a new preconditioner whenever the values change";
  if (s.user_reuse_pc)
    reuse = "whole preconditioner kept for the pattern (-ksp_reuse_preconditioner)";
  else if (s.reuse_interpolation)
    reuse =
        "interpolation kept while the pattern is fixed (-pc_gamg_reuse_interpolation), "
        "coarse operators recomputed when the values change";
  reuse += "; whole preconditioner kept when the values are unchanged";
  return {{"petsc_options", s.options.options},
          {"inserted_options", s.inserted},
          {"options_prefix", s.prefix},
          {"ksp_type", s.ksp_type},
          {"pc_type", s.pc_type},
          {"norm_type", s.norm_type},
          {"relative_tolerance", tolerance},
          {"max_iterations", std::to_string(s.max_it)},
          {"preconditioner_reuse", reuse},
          {"version", version()},
          {"ranks", std::to_string(PetscRuntime::instance().size())},
          {"matrix_bytes_per_rank", std::to_string(std::llround(s.matrix_bytes_per_rank))},
          {"preconditioner_bytes_per_rank",
           std::to_string(std::llround(s.preconditioner_bytes_per_rank))},
          {"distribution",
           s.distributed ? "every rank reads the mesh, assembles and holds the whole system and "
                           "runs the whole flow; PETSc holds a block of rows of the matrix, "
                           "vectors and preconditioner on each rank, and the solution is "
                           "gathered to every rank after each solve"
                         : "one process"}};
}

int PetscSolver::preconditioner_setups() const {
  return impl_->setups;
}
int PetscSolver::new_patterns() const {
  return impl_->patterns;
}
int PetscSolver::pattern_comparisons() const {
  return impl_->kept.comparisons();
}

std::string PetscSolver::version() {
  return PetscRuntime::instance().version();
}

#endif

}  // namespace mcf
