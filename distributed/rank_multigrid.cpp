#include "distributed/rank_multigrid.h"

#ifdef MCFBENCH_HAVE_PETSC

#include "core/galerkin_pattern.h"
#include "core/sparse.h"
#include "core/vec4.h"
#include "distributed/comm.h"
#include "distributed/rank_hierarchy.h"
#include "solvers/galerkin.h"
#include "solvers/petsc_runtime.h"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <stdexcept>
#include <vector>

#include <petscmat.h>

namespace mcf::dist {

namespace {

using vec4::load4;
using vec4::splat;
using vec4::store4;
using vec4::v4;
using RowMajor = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

/// A sequential AIJ matrix's CSR arrays, borrowed (valid until its pattern changes).
struct Csr {
  const PetscInt* ia = nullptr;
  const PetscInt* ja = nullptr;
  const PetscScalar* v = nullptr;
  PetscInt rows = 0;
};

Csr csr_of(Mat m) {
  Csr c;
  PetscBool done = PETSC_FALSE;
  petsc_check(MatGetRowIJ(m, 0, PETSC_FALSE, PETSC_FALSE, &c.rows, &c.ia, &c.ja, &done),
              "MatGetRowIJ");
  if (!done) throw std::runtime_error("distributed multigrid: a level's rows are not readable");
  petsc_check(MatSeqAIJGetArrayRead(m, &c.v), "MatSeqAIJGetArrayRead");
  const PetscScalar* v = c.v;
  petsc_check(MatSeqAIJRestoreArrayRead(m, &v), "MatSeqAIJRestoreArrayRead");
  PetscInt rows = 0;
  const PetscInt *ia = c.ia, *ja = c.ja;
  petsc_check(MatRestoreRowIJ(m, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done),
              "MatRestoreRowIJ");
  return c;
}

}  // namespace

struct RankMultigrid::Impl {
  struct Level {
    PetscInt n = 0, offset = 0, total = 0;  // owned rows, the first's global number, all rows
    RowMajor prolongation;                  // from the level below (l >= 1): n x its n
    // The owned rows: the diagonal block (owned columns, local numbers) and the off-diagonal
    // block (column m is the ghost of global number ghost_columns[m], increasing). The finest
    // level's are views of PETSc's matrix; the coarse levels' are held in own_*.
    Csr diagonal, off;
    std::vector<PetscInt> ghost_columns;
    std::vector<PetscInt> own_diagonal_ia, own_diagonal_ja, own_off_ia, own_off_ja;
    std::vector<double> own_diagonal_v, own_off_v;
    std::vector<int> diag_pos, interface;
    std::vector<double> inv_diag;
    Vec global = nullptr, ghosts = nullptr;  // an iterate's layout, the ghost rows' buffer
    VecScatter scatter = nullptr;
    std::vector<double> ghost, b, x, r;  // blocks of 4 per row
    // The Galerkin product onto the level below (l >= 1), as the one-process multigrid forms it
    // (solvers/galerkin.h) on the rank's extended system: on the owned then the ghost vertices,
    // Â holds the owned rows and, in the ghost columns, their mirror (the ghost rows' entries in
    // owned columns; none between ghosts), and P̂ the owned and the ghost vertices' prolongation
    // rows (the ghosts' exchanged from their owners), onto the owned then the ghost coarse
    // vertices. The coarse level's owned rows are the first rows of Ĉ = P̂ᵀ Â P̂ (symmetric).
    SparseMatrix ext_A, ext_P, ext_C;
    std::vector<int> ext_source;  // per Â entry in a ghost column: the off-diagonal block's entry
    std::vector<int> ext_transpose, c_source;  // c_source: per coarse owned entry, its place in Ĉ
    multigrid_detail::GalerkinPlan plan;
    multigrid_detail::Spa spa;
  };

  MPI_Comm comm = PETSC_COMM_WORLD;
  int ranks = 1;
  RankCycle shape;
  std::vector<Level> levels;  // coarsest first
  bool symbolic_done = false;
  // The coarsest level, gathered on every rank: its entries' global rows and columns, in the
  // gathered order, and their values; the factor's pattern is analysed once.
  std::vector<int> gather_counts, gather_displs;  // per rank, entries
  std::vector<PetscInt> gathered_rows, gathered_cols;
  std::vector<double> gathered_values, local_values;
  SparseMatrix coarse_matrix;
  Eigen::SimplicialLDLT<SparseMatrix> coarse_factor;
  bool analyzed = false;
  std::vector<int> counts, displs;  // per rank, in doubles (4 per row)
  std::vector<double> coarse_rhs;
  Eigen::MatrixXd coarse_b, coarse_x;

  ~Impl() {
    for (Level& L : levels) {
      if (L.scatter) VecScatterDestroy(&L.scatter);
      if (L.global) VecDestroy(&L.global);
      if (L.ghosts) VecDestroy(&L.ghosts);
    }
  }

  void build(const RankMesh& mesh) {
    ranks = dist::ranks();
    const RankHierarchy h = build_rank_hierarchy(mesh, std::max(100, 1000 / mesh.ranks));
    levels.resize(std::size_t(h.levels()));
    levels.back().n = mesh.owned;
    for (std::size_t l = 0; l + 1 < levels.size(); ++l)
      levels[l].n = PetscInt(h.prolongations[l].cols());
    for (Level& L : levels) {
      PetscInt end = 0;
      petsc_check(MPI_Scan(&L.n, &end, 1, MPIU_INT, MPI_SUM, comm), "MPI_Scan");
      L.offset = end - L.n;
      petsc_check(MPI_Allreduce(&L.n, &L.total, 1, MPIU_INT, MPI_SUM, comm), "MPI_Allreduce");
      if (&L != &levels.back()) {  // the finest level's are the caller's
        L.b.assign(std::size_t(4 * L.n), 0.0);
        L.x.assign(std::size_t(4 * L.n), 0.0);
      }
      L.r.assign(std::size_t(4 * L.n), 0.0);
      petsc_check(VecCreateMPIWithArray(comm, 4, 4 * L.n, PETSC_DECIDE, nullptr, &L.global),
                  "VecCreateMPIWithArray");
    }
    for (std::size_t l = 1; l < levels.size(); ++l)
      levels[l].prolongation = RowMajor(h.prolongations[l - 1]);
    // The coarsest level's rows on each rank, for the gather before its solve.
    const Level& K = levels.front();
    const std::vector<double> sizes = all_values(double(K.n));
    counts.resize(sizes.size());
    displs.resize(sizes.size());
    int at = 0;
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      counts[k] = 4 * int(sizes[k]);
      displs[k] = at;
      at += counts[k];
    }
    coarse_rhs.assign(std::size_t(at), 0.0);
    coarse_b.resize(K.total, 3);
  }

  /// The ghost exchange of a level, from its ghost columns.
  void make_scatter(Level& L) {
    const auto count = PetscInt(L.ghost_columns.size());
    if (L.scatter) VecScatterDestroy(&L.scatter);
    if (L.ghosts) VecDestroy(&L.ghosts);
    L.ghost.assign(std::size_t(4 * count), 0.0);
    petsc_check(VecCreateSeqWithArray(PETSC_COMM_SELF, 4, 4 * count, L.ghost.data(), &L.ghosts),
                "VecCreateSeqWithArray");
    IS from = nullptr, to = nullptr;
    petsc_check(
        ISCreateBlock(PETSC_COMM_SELF, 4, count, L.ghost_columns.data(), PETSC_COPY_VALUES, &from),
        "ISCreateBlock");
    petsc_check(ISCreateStride(PETSC_COMM_SELF, 4 * count, 0, 1, &to), "ISCreateStride");
    petsc_check(VecScatterCreate(L.global, from, L.ghosts, to, &L.scatter), "VecScatterCreate");
    ISDestroy(&from);
    ISDestroy(&to);
  }

  /// The finest level's blocks from PETSc's matrix; false if its ghost columns changed (the
  /// products' patterns are then made again).
  bool read_finest(Mat A) {
    Level& L = levels.back();
    Mat Ad = nullptr, Ao = nullptr;
    const PetscInt* garray = nullptr;
    petsc_check(MatMPIAIJGetSeqAIJ(A, &Ad, &Ao, &garray), "MatMPIAIJGetSeqAIJ");
    L.diagonal = csr_of(Ad);
    L.off = csr_of(Ao);
    PetscInt ghost_count = 0;
    petsc_check(MatGetSize(Ao, nullptr, &ghost_count), "MatGetSize");
    if (L.diagonal.rows != L.n || L.off.rows != L.n)
      throw std::runtime_error("distributed multigrid: the local rows do not match the mesh's");
    const std::vector<PetscInt> columns(garray, garray + ghost_count);
    if (columns == L.ghost_columns && L.scatter) return true;
    L.ghost_columns = columns;
    make_scatter(L);
    return false;
  }

  static Csr view(const std::vector<PetscInt>& ia, const std::vector<PetscInt>& ja,
                  const std::vector<double>& v) {
    return Csr{ia.data(), ja.data(), v.data(), PetscInt(ia.size()) - 1};
  }

  /// The patterns of the level below l's product (Â, P̂, Ĉ and the Galerkin plan) and of its
  /// owned rows, after P's ghost rows (exchanged once); the coarse ghost columns and their
  /// exchange.
  void galerkin_symbolic(std::size_t l) {
    Level &F = levels[l], &C = levels[l - 1];
    const RowMajor& P = F.prolongation;
    const auto nf = std::size_t(F.n), gf = F.ghost_columns.size();
    // Each owned fine row's P row as blocks of 4 (global coarse numbers, -1 past its end; the
    // weights), exchanged as an iterate is.
    std::vector<double> index(4 * nf, -1.0), weight(4 * nf, 0.0);
    for (int i = 0; i < P.rows(); ++i) {
      int k = 0;
      for (RowMajor::InnerIterator it(P, i); it; ++it, ++k) {
        if (k == 4)
          throw std::runtime_error("distributed multigrid: a prolongation row has over 4 entries");
        index[4 * std::size_t(i) + std::size_t(k)] = double(C.offset + it.col());
        weight[4 * std::size_t(i) + std::size_t(k)] = it.value();
      }
    }
    exchange(F, index.data());
    const std::vector<double> ghost_index = F.ghost;
    exchange(F, weight.data());
    const std::vector<double> ghost_weight = F.ghost;
    std::vector<PetscInt>& G = C.ghost_columns;
    G.clear();
    for (const double g : ghost_index)
      if (g >= 0 && !(g >= double(C.offset) && g < double(C.offset + C.n)))
        G.push_back(PetscInt(g));
    std::sort(G.begin(), G.end());
    G.erase(std::unique(G.begin(), G.end()), G.end());
    const auto nc = std::size_t(C.n);
    const auto local = [&](PetscInt g) {
      if (g >= C.offset && g < C.offset + C.n) return int(g - C.offset);
      return int(nc) + int(std::lower_bound(G.begin(), G.end(), g) - G.begin());
    };
    // P̂: the owned fine rows' P rows, then the ghosts', on local coarse columns.
    const std::size_t width = nc + G.size(), rows = nf + gf;
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < P.rows(); ++i)
      for (RowMajor::InnerIterator it(P, i); it; ++it)
        entries.emplace_back(i, int(it.col()), it.value());
    for (std::size_t m = 0; m < gf; ++m)
      for (std::size_t k = 0; k < 4; ++k)
        if (ghost_index[4 * m + k] >= 0)
          entries.emplace_back(int(nf + m), local(PetscInt(ghost_index[4 * m + k])),
                               ghost_weight[4 * m + k]);
    F.ext_P = SparseMatrix(Eigen::Index(rows), Eigen::Index(width));
    F.ext_P.setFromTriplets(entries.begin(), entries.end());
    F.ext_P.makeCompressed();
    // Â: column k < nf is the owned row k (owned columns, then the ghost columns shifted by nf:
    // sorted); column nf + m holds the owned rows with an entry in ghost column m, increasing.
    std::vector<int> outer(rows + 1, 0);
    for (std::size_t k = 0; k < nf; ++k) {
      outer[k + 1] =
          int((F.diagonal.ia[k + 1] - F.diagonal.ia[k]) + (F.off.ia[k + 1] - F.off.ia[k]));
      for (PetscInt p = F.off.ia[k]; p < F.off.ia[k + 1]; ++p)
        ++outer[nf + std::size_t(F.off.ja[p]) + 1];
    }
    for (std::size_t c = 0; c < rows; ++c) outer[c + 1] += outer[c];
    std::vector<int> inner(static_cast<std::size_t>(outer[rows])),
        next(outer.begin(), outer.end() - 1);
    F.ext_source.assign(inner.size() - std::size_t(outer[nf]), 0);
    for (std::size_t k = 0; k < nf; ++k) {
      for (PetscInt p = F.diagonal.ia[k]; p < F.diagonal.ia[k + 1]; ++p) {
        const int at = next[k]++;
        inner[std::size_t(at)] = int(F.diagonal.ja[p]);
      }
      for (PetscInt p = F.off.ia[k]; p < F.off.ia[k + 1]; ++p) {
        int at = next[k]++;
        inner[std::size_t(at)] = int(nf) + int(F.off.ja[p]);
        at = next[nf + std::size_t(F.off.ja[p])]++;
        inner[std::size_t(at)] = int(k);
        F.ext_source[std::size_t(at - outer[nf])] = int(p);
      }
    }
    F.ext_A = SparseMatrix(Eigen::Index(rows), Eigen::Index(rows));
    F.ext_A.resizeNonZeros(Eigen::Index(inner.size()));
    std::copy(outer.begin(), outer.end(), F.ext_A.outerIndexPtr());
    std::copy(inner.begin(), inner.end(), F.ext_A.innerIndexPtr());
    std::fill(F.ext_A.valuePtr(), F.ext_A.valuePtr() + inner.size(), 0.0);
    F.ext_C = galerkin_pattern(F.ext_P, F.ext_A);
    F.ext_transpose = multigrid_detail::transpose_positions(F.ext_C);
    F.plan = multigrid_detail::galerkin_plan(multigrid_detail::Csc(F.ext_A), F.ext_P, F.ext_C, {});
    // The coarse owned rows: Ĉ's first nc columns (rows by symmetry), owned rows first.
    const SparseMatrix& Ch = F.ext_C;
    C.own_diagonal_ia.assign(1, 0);
    C.own_off_ia.assign(1, 0);
    C.own_diagonal_ja.clear();
    C.own_off_ja.clear();
    std::vector<int> diagonal_source, off_source;
    for (std::size_t i = 0; i < nc; ++i) {
      for (int p = Ch.outerIndexPtr()[i]; p < Ch.outerIndexPtr()[i + 1]; ++p) {
        const int r = Ch.innerIndexPtr()[p];
        if (r < int(nc)) {
          C.own_diagonal_ja.push_back(r);
          diagonal_source.push_back(p);
        } else {
          C.own_off_ja.push_back(r - int(nc));
          off_source.push_back(p);
        }
      }
      C.own_diagonal_ia.push_back(PetscInt(C.own_diagonal_ja.size()));
      C.own_off_ia.push_back(PetscInt(C.own_off_ja.size()));
    }
    F.c_source = diagonal_source;
    F.c_source.insert(F.c_source.end(), off_source.begin(), off_source.end());
    C.own_diagonal_v.assign(C.own_diagonal_ja.size(), 0.0);
    C.own_off_v.assign(C.own_off_ja.size(), 0.0);
    C.diagonal = view(C.own_diagonal_ia, C.own_diagonal_ja, C.own_diagonal_v);
    C.off = view(C.own_off_ia, C.own_off_ja, C.own_off_v);
    make_scatter(C);
  }

  /// The values of the level below l on its patterns: Â from the level's blocks, Ĉ by the
  /// one-process Galerkin kernel (a fixed order: the same bits on every rerun), the coarse
  /// owned rows read out of it.
  void galerkin_numeric(std::size_t l) {
    Level &F = levels[l], &C = levels[l - 1];
    // Â's owned columns are the owned rows (the diagonal block's run, then the off-diagonal
    // block's), its ghost columns the off-diagonal entries mirrored.
    double* a = F.ext_A.valuePtr();
    const int* outer = F.ext_A.outerIndexPtr();
    for (PetscInt k = 0; k < F.n; ++k) {
      double* to = std::copy(F.diagonal.v + F.diagonal.ia[k], F.diagonal.v + F.diagonal.ia[k + 1],
                             a + outer[k]);
      std::copy(F.off.v + F.off.ia[k], F.off.v + F.off.ia[k + 1], to);
    }
    double* ghosts = a + outer[F.n];
    for (std::size_t e = 0; e < F.ext_source.size(); ++e) ghosts[e] = F.off.v[F.ext_source[e]];
    multigrid_detail::galerkin_values(multigrid_detail::Csc(F.ext_A), F.ext_P, F.ext_C,
                                      F.ext_C.valuePtr(), F.ext_transpose, {}, F.spa,
                                      F.plan.empty() ? nullptr : &F.plan);
    const double* c = F.ext_C.valuePtr();
    const std::size_t nd = C.own_diagonal_v.size();
    for (std::size_t e = 0; e < nd; ++e) C.own_diagonal_v[e] = c[F.c_source[e]];
    for (std::size_t e = 0; e < C.own_off_v.size(); ++e) C.own_off_v[e] = c[F.c_source[nd + e]];
  }

  void find_diagonals(Level& L) {
    L.interface.clear();
    for (PetscInt i = 0; i < L.n; ++i)
      if (L.off.ia[i + 1] > L.off.ia[i]) L.interface.push_back(int(i));
    L.diag_pos.assign(std::size_t(L.n), -1);
    const Csr& d = L.diagonal;
    for (PetscInt i = 0; i < L.n; ++i)
      for (PetscInt p = d.ia[i]; p < d.ia[i + 1]; ++p)
        if (d.ja[p] == i) {
          L.diag_pos[std::size_t(i)] = int(p);
          break;
        }
  }

  void invert_diagonals(Level& L) {
    L.inv_diag.resize(std::size_t(L.n));
    for (PetscInt i = 0; i < L.n; ++i) {
      const int p = L.diag_pos[std::size_t(i)];
      if (p < 0 || !(L.diagonal.v[p] > 0))
        throw std::runtime_error(
            "distributed multigrid: a level's diagonal entry is missing or not positive");
      L.inv_diag[std::size_t(i)] = 1.0 / L.diagonal.v[p];
    }
  }

  /// The coarsest level's entries with global rows and columns, gathered on every rank once.
  void gather_symbolic() {
    const Level& K = levels.front();
    std::vector<PetscInt> rows, cols;
    for (PetscInt i = 0; i < K.n; ++i) {
      for (PetscInt p = K.diagonal.ia[i]; p < K.diagonal.ia[i + 1]; ++p) {
        rows.push_back(K.offset + i);
        cols.push_back(K.offset + K.diagonal.ja[p]);
      }
      for (PetscInt p = K.off.ia[i]; p < K.off.ia[i + 1]; ++p) {
        rows.push_back(K.offset + i);
        cols.push_back(K.ghost_columns[std::size_t(K.off.ja[p])]);
      }
    }
    const std::vector<double> sizes = all_values(double(rows.size()));
    gather_counts.resize(sizes.size());
    gather_displs.resize(sizes.size());
    int at = 0;
    for (std::size_t k = 0; k < sizes.size(); ++k) {
      gather_counts[k] = int(sizes[k]);
      gather_displs[k] = at;
      at += gather_counts[k];
    }
    gathered_rows.resize(std::size_t(at));
    gathered_cols.resize(std::size_t(at));
    gathered_values.resize(std::size_t(at));
    petsc_check(MPI_Allgatherv(rows.data(), int(rows.size()), MPIU_INT, gathered_rows.data(),
                               gather_counts.data(), gather_displs.data(), MPIU_INT, comm),
                "MPI_Allgatherv");
    petsc_check(MPI_Allgatherv(cols.data(), int(cols.size()), MPIU_INT, gathered_cols.data(),
                               gather_counts.data(), gather_displs.data(), MPIU_INT, comm),
                "MPI_Allgatherv");
    local_values.resize(rows.size());
    analyzed = false;
  }

  void factor_coarsest() {
    const Level& K = levels.front();
    std::size_t e = 0;
    for (PetscInt i = 0; i < K.n; ++i) {
      for (PetscInt p = K.diagonal.ia[i]; p < K.diagonal.ia[i + 1]; ++p)
        local_values[e++] = K.diagonal.v[p];
      for (PetscInt p = K.off.ia[i]; p < K.off.ia[i + 1]; ++p) local_values[e++] = K.off.v[p];
    }
    petsc_check(MPI_Allgatherv(local_values.data(), int(local_values.size()), MPI_DOUBLE,
                               gathered_values.data(), gather_counts.data(), gather_displs.data(),
                               MPI_DOUBLE, comm),
                "MPI_Allgatherv");
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(gathered_values.size());
    for (std::size_t k = 0; k < gathered_values.size(); ++k)
      entries.emplace_back(int(gathered_rows[k]), int(gathered_cols[k]), gathered_values[k]);
    const auto n = Eigen::Index(K.total);
    coarse_matrix.resize(n, n);
    coarse_matrix.setFromTriplets(entries.begin(), entries.end());
    if (!analyzed) {
      coarse_factor.analyzePattern(coarse_matrix);
      analyzed = true;
    }
    coarse_factor.factorize(coarse_matrix);
    if (coarse_factor.info() != Eigen::Success)
      throw std::runtime_error("distributed multigrid: the coarsest level's factorization failed");
  }

  void exchange(Level& L, const double* x) {
    if (ranks == 1) return;
    petsc_check(VecPlaceArray(L.global, x), "VecPlaceArray");
    petsc_check(VecScatterBegin(L.scatter, L.global, L.ghosts, INSERT_VALUES, SCATTER_FORWARD),
                "VecScatterBegin");
    petsc_check(VecScatterEnd(L.scatter, L.global, L.ghosts, INSERT_VALUES, SCATTER_FORWARD),
                "VecScatterEnd");
    petsc_check(VecResetArray(L.global), "VecResetArray");
  }

  /// Σ over row i's ghost entries and its off-diagonal owned entries, subtracted from acc.
  static inline void subtract_row(const Level& L, const double* x, PetscInt i, v4& acc0, v4& acc1) {
    const Csr &d = L.diagonal, &o = L.off;
    for (PetscInt p = o.ia[i]; p < o.ia[i + 1]; ++p)
      acc1 -= splat(o.v[p]) * load4(L.ghost.data() + 4 * std::size_t(o.ja[p]));
    const PetscInt dp = L.diag_pos[std::size_t(i)];
    for (PetscInt p = d.ia[i]; p < dp; ++p)
      acc0 -= splat(d.v[p]) * load4(x + 4 * std::size_t(d.ja[p]));
    for (PetscInt p = dp + 1; p < d.ia[i + 1]; ++p)
      acc1 -= splat(d.v[p]) * load4(x + 4 * std::size_t(d.ja[p]));
  }

  /// One Gauss-Seidel sweep over the owned rows with the ghost rows fixed (exchanged first, or
  /// zero: `zero_ghosts`, the iterate zero everywhere, the first sweep from a zero guess), and
  /// the interface rows' second pass with fresh ghosts: after the sweep going forward, before
  /// it going backward (the adjoint).
  void sweep(Level& L, const double* b, double* x, bool forward, bool zero_ghosts) {
    if (zero_ghosts)
      std::fill(L.ghost.begin(), L.ghost.end(), 0.0);
    else
      exchange(L, x);
    const auto relax = [&](PetscInt i) {
      v4 acc0 = load4(b + 4 * std::size_t(i)), acc1 = splat(0.0);
      subtract_row(L, x, i, acc0, acc1);
      store4(x + 4 * std::size_t(i), (acc0 + acc1) * splat(L.inv_diag[std::size_t(i)]));
    };
    if (forward) {
      for (PetscInt i = 0; i < L.n; ++i) relax(i);
      if (ranks > 1) {
        exchange(L, x);
        for (const int i : L.interface) relax(i);
      }
    } else {
      if (ranks > 1) {
        for (auto it = L.interface.rbegin(); it != L.interface.rend(); ++it) relax(*it);
        exchange(L, x);
      }
      for (PetscInt i = L.n - 1; i >= 0; --i) relax(i);
    }
  }

  /// R = B - A X.
  void residual(Level& L, const double* b, const double* x, double* r) {
    exchange(L, x);
    for (PetscInt i = 0; i < L.n; ++i) {
      const std::size_t ii = 4 * std::size_t(i);
      v4 acc0 = load4(b + ii), acc1 = splat(0.0);
      subtract_row(L, x, i, acc0, acc1);
      acc0 -= splat(L.diagonal.v[L.diag_pos[std::size_t(i)]]) * load4(x + ii);
      store4(r + ii, acc0 + acc1);
    }
  }

  void coarse_solve(Level& K, const double* b, double* x) {
    petsc_check(MPI_Allgatherv(b, 4 * int(K.n), MPI_DOUBLE, coarse_rhs.data(), counts.data(),
                               displs.data(), MPI_DOUBLE, comm),
                "MPI_Allgatherv");
    const Eigen::Index n = K.total;
    for (Eigen::Index i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) coarse_b(i, c) = coarse_rhs[std::size_t(4 * i + c)];
    coarse_x = coarse_factor.solve(coarse_b);
    for (PetscInt i = 0; i < K.n; ++i)
      for (int c = 0; c < 3; ++c)
        x[4 * std::size_t(i) + std::size_t(c)] = coarse_x(K.offset + i, c);
  }

  void cycle_at(std::size_t l, const double* b, double* x, bool zero_guess) {
    Level& L = levels[l];
    if (l == 0) {
      coarse_solve(L, b, x);
      return;
    }
    for (int s = 0; s < shape.smooth; ++s) sweep(L, b, x, true, zero_guess && s == 0);
    residual(L, b, x, L.r.data());
    Level& C = levels[l - 1];
    // Restriction by the owned rows of Pᵀ (the prolongation is block diagonal across ranks).
    std::fill(C.b.begin(), C.b.end(), 0.0);
    for (int i = 0; i < L.prolongation.rows(); ++i) {
      const v4 ri = load4(L.r.data() + 4 * std::size_t(i));
      for (RowMajor::InnerIterator it(L.prolongation, i); it; ++it) {
        double* cb = C.b.data() + 4 * std::size_t(it.col());
        store4(cb, load4(cb) + splat(it.value()) * ri);
      }
    }
    std::fill(C.x.begin(), C.x.end(), 0.0);
    const int gamma = shape.w_cycle && l > 1 ? 2 : 1;
    for (int g = 0; g < gamma; ++g) cycle_at(l - 1, C.b.data(), C.x.data(), g == 0);
    for (int i = 0; i < L.prolongation.rows(); ++i) {
      v4 e = splat(0.0);
      for (RowMajor::InnerIterator it(L.prolongation, i); it; ++it)
        e += splat(it.value()) * load4(C.x.data() + 4 * std::size_t(it.col()));
      double* xi = x + 4 * std::size_t(i);
      store4(xi, load4(xi) + e);
    }
    for (int s = 0; s < shape.smooth; ++s) sweep(L, b, x, false, false);
  }
};

RankMultigrid::RankMultigrid(const RankMesh& mesh, RankCycle cycle)
    : impl_(std::make_unique<Impl>()) {
  impl_->shape = cycle;
  impl_->build(mesh);
}

RankMultigrid::~RankMultigrid() = default;

void RankMultigrid::set_operator(Mat A) {
  Impl& s = *impl_;
  // Patterns, diagonal positions and interface rows are made once: A's pattern (and with it
  // every coarse level's) is the same at every call; only the values are refreshed below.
  if (!s.read_finest(A) || !s.symbolic_done) {
    for (std::size_t l = s.levels.size() - 1; l > 0; --l) s.galerkin_symbolic(l);
    for (auto& L : s.levels) s.find_diagonals(L);
    s.gather_symbolic();
    s.symbolic_done = true;
  }
  for (std::size_t l = s.levels.size() - 1; l > 0; --l) s.galerkin_numeric(l);
  for (auto& L : s.levels) s.invert_diagonals(L);
  s.factor_coarsest();
}

void RankMultigrid::cycle(const double* B, double* X) {
  impl_->cycle_at(impl_->levels.size() - 1, B, X, false);
}

void RankMultigrid::apply(const double* X, double* Y) {
  Impl::Level& L = impl_->levels.back();
  impl_->exchange(L, X);
  for (PetscInt i = 0; i < L.n; ++i) {
    v4 acc0 = splat(0.0), acc1 = splat(0.0);
    Impl::subtract_row(L, X, i, acc0, acc1);
    acc0 -= splat(L.diagonal.v[L.diag_pos[std::size_t(i)]]) * load4(X + 4 * std::size_t(i));
    store4(Y + 4 * std::size_t(i), -(acc0 + acc1));
  }
}

int RankMultigrid::owned() const {
  return int(impl_->levels.back().n);
}

int RankMultigrid::levels() const {
  return int(impl_->levels.size());
}

long long RankMultigrid::coarsest_size() const {
  return impl_->levels.front().total;
}

double RankMultigrid::bytes() const {
  const Impl& s = *impl_;
  double bytes = 0;
  for (std::size_t l = 0; l < s.levels.size(); ++l) {
    const Impl::Level& L = s.levels[l];
    bytes += double(L.own_diagonal_ja.size() + L.own_off_ja.size()) * 12.0 +
             double(L.own_diagonal_ia.size() + L.own_off_ia.size()) * 4.0;
    bytes += double(L.prolongation.nonZeros() + L.ext_P.nonZeros() + L.ext_A.nonZeros() +
                    L.ext_C.nonZeros()) *
                 12.0 +
             4.0 * double(L.ext_source.size() + L.ext_transpose.size() + L.c_source.size()) +
             double(L.plan.bytes());
    bytes +=
        8.0 * double(L.b.size() + L.x.size() + L.r.size() + L.ghost.size() + L.inv_diag.size()) +
        4.0 * double(L.diag_pos.size());
  }
  bytes += double(s.gathered_values.size()) * (8.0 + 2 * sizeof(PetscInt));
  bytes += double(s.coarse_matrix.nonZeros()) * 12.0 * 3.0;  // the matrix and its factor
  return bytes;
}

std::vector<RankMultigrid::Entry> RankMultigrid::operator_entries(int l) const {
  const Impl::Level& L = impl_->levels[std::size_t(l)];
  std::vector<Entry> out;
  for (PetscInt i = 0; i < L.n; ++i) {
    for (PetscInt p = L.diagonal.ia[i]; p < L.diagonal.ia[i + 1]; ++p)
      out.push_back({L.offset + i, L.offset + L.diagonal.ja[p], L.diagonal.v[p]});
    for (PetscInt p = L.off.ia[i]; p < L.off.ia[i + 1]; ++p)
      out.push_back({L.offset + i, L.ghost_columns[std::size_t(L.off.ja[p])], L.off.v[p]});
  }
  return out;
}

std::vector<RankMultigrid::Entry> RankMultigrid::prolongation_entries(int l) const {
  const Impl::Level &F = impl_->levels[std::size_t(l)], &C = impl_->levels[std::size_t(l) - 1];
  std::vector<Entry> out;
  for (int i = 0; i < F.prolongation.rows(); ++i)
    for (RowMajor::InnerIterator it(F.prolongation, i); it; ++it)
      out.push_back({F.offset + i, C.offset + it.col(), it.value()});
  return out;
}

std::pair<long long, int> RankMultigrid::level_rows(int l) const {
  const Impl::Level& L = impl_->levels[std::size_t(l)];
  return {L.offset, int(L.n)};
}

}  // namespace mcf::dist

#endif
