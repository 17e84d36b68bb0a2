#include "distributed/rank_multigrid.h"

#ifdef MCFBENCH_HAVE_PETSC

#include "core/sparse.h"
#include "core/vec4.h"
#include "distributed/comm.h"
#include "distributed/rank_hierarchy.h"
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

double storage_bytes(Mat m) {
  MatInfo info;
  petsc_check(MatGetInfo(m, MAT_LOCAL, &info), "MatGetInfo");
  PetscInt rows = 0, cols = 0;
  petsc_check(MatGetLocalSize(m, &rows, &cols), "MatGetLocalSize");
  return info.nz_used * double(sizeof(PetscScalar) + sizeof(PetscInt)) +
         double(rows + 1) * double(sizeof(PetscInt));
}

}  // namespace

struct RankMultigrid::Impl {
  struct Level {
    PetscInt n = 0, offset = 0, total = 0;  // owned rows, the first's global number, all rows
    Mat A = nullptr;                        // coarse levels: P^T A P, held here
    Mat P = nullptr;                        // interpolation from the level below (l >= 1)
    RowMajor prolongation;                  // its owned rows: n x (level l - 1's n)
    Csr diagonal, off;                      // A's local blocks: owned and ghost columns
    std::vector<PetscInt> ghost_columns;    // global numbers of `off`'s columns
    std::vector<int> diag_pos;
    std::vector<double> inv_diag;
    Vec global = nullptr, ghosts = nullptr;  // an iterate's layout, the ghost rows' buffer
    VecScatter scatter = nullptr;
    std::vector<double> ghost, b, x, r;  // blocks of 4 per row
  };

  MPI_Comm comm = PETSC_COMM_WORLD;
  int ranks = 1;
  RankCycle shape;
  std::vector<Level> levels;  // coarsest first
  // The coarsest level, gathered on every rank.
  Mat* gathered = nullptr;  // one matrix: MatCreateSubMatrices' array
  IS all_rows = nullptr;
  SparseMatrix coarse_matrix;
  Eigen::SimplicialLDLT<SparseMatrix> coarse_factor;
  bool analyzed = false;
  std::vector<int> counts, displs;  // per rank, in doubles (4 per row)
  std::vector<double> coarse_rhs;
  Eigen::MatrixXd coarse_b, coarse_x;

  ~Impl() {
    for (Level& L : levels) {
      if (L.P) MatDestroy(&L.P);
      if (L.A && &L != &levels.back()) MatDestroy(&L.A);
      if (L.scatter) VecScatterDestroy(&L.scatter);
      if (L.global) VecDestroy(&L.global);
      if (L.ghosts) VecDestroy(&L.ghosts);
    }
    if (gathered) MatDestroySubMatrices(1, &gathered);
    if (all_rows) ISDestroy(&all_rows);
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
      L.b.assign(std::size_t(4 * L.n), 0.0);
      L.x.assign(std::size_t(4 * L.n), 0.0);
      L.r.assign(std::size_t(4 * L.n), 0.0);
      petsc_check(VecCreateMPIWithArray(comm, 4, 4 * L.n, PETSC_DECIDE, nullptr, &L.global),
                  "VecCreateMPIWithArray");
    }
    for (std::size_t l = 1; l < levels.size(); ++l) {
      Level &F = levels[l], &C = levels[l - 1];
      F.prolongation = RowMajor(h.prolongations[l - 1]);
      // The interpolation as PETSc's matrix, for the Galerkin products.
      const RowMajor& P = F.prolongation;
      std::vector<PetscInt> ia(std::size_t(P.rows()) + 1, 0), ja;
      std::vector<PetscScalar> v;
      for (int i = 0; i < P.rows(); ++i) {
        for (RowMajor::InnerIterator it(P, i); it; ++it) {
          ja.push_back(C.offset + it.col());
          v.push_back(it.value());
        }
        ia[std::size_t(i) + 1] = PetscInt(ja.size());
      }
      petsc_check(MatCreateMPIAIJWithArrays(comm, F.n, C.n, F.total, C.total, ia.data(), ja.data(),
                                            v.data(), &F.P),
                  "MatCreateMPIAIJWithArrays");
    }
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
    petsc_check(ISCreateStride(PETSC_COMM_SELF, K.total, 0, 1, &all_rows), "ISCreateStride");
  }

  /// A level's local blocks, diagonal and ghost exchange, from its current matrix.
  void read_blocks(Level& L) {
    Mat Ad = nullptr, Ao = nullptr;
    const PetscInt* garray = nullptr;
    petsc_check(MatMPIAIJGetSeqAIJ(L.A, &Ad, &Ao, &garray), "MatMPIAIJGetSeqAIJ");
    L.diagonal = csr_of(Ad);
    L.off = csr_of(Ao);
    PetscInt ghost_count = 0;
    petsc_check(MatGetSize(Ao, nullptr, &ghost_count), "MatGetSize");
    if (L.diagonal.rows != L.n || L.off.rows != L.n)
      throw std::runtime_error("distributed multigrid: a level's local rows do not match");
    const std::vector<PetscInt> columns(garray, garray + ghost_count);
    if (columns != L.ghost_columns || !L.scatter) {
      L.ghost_columns = columns;
      if (L.scatter) VecScatterDestroy(&L.scatter);
      if (L.ghosts) VecDestroy(&L.ghosts);
      L.ghost.assign(std::size_t(4 * ghost_count), 0.0);
      petsc_check(
          VecCreateSeqWithArray(PETSC_COMM_SELF, 4, 4 * ghost_count, L.ghost.data(), &L.ghosts),
          "VecCreateSeqWithArray");
      IS from = nullptr, to = nullptr;
      petsc_check(ISCreateBlock(PETSC_COMM_SELF, 4, ghost_count, L.ghost_columns.data(),
                                PETSC_COPY_VALUES, &from),
                  "ISCreateBlock");
      petsc_check(ISCreateStride(PETSC_COMM_SELF, 4 * ghost_count, 0, 1, &to), "ISCreateStride");
      petsc_check(VecScatterCreate(L.global, from, L.ghosts, to, &L.scatter), "VecScatterCreate");
      ISDestroy(&from);
      ISDestroy(&to);
    }
    L.diag_pos.assign(std::size_t(L.n), -1);
    L.inv_diag.assign(std::size_t(L.n), 0.0);
    const Csr& d = L.diagonal;
    for (PetscInt i = 0; i < L.n; ++i)
      for (PetscInt p = d.ia[i]; p < d.ia[i + 1]; ++p)
        if (d.ja[p] == i) {
          L.diag_pos[std::size_t(i)] = int(p);
          L.inv_diag[std::size_t(i)] = 1.0 / d.v[p];
          break;
        }
    for (PetscInt i = 0; i < L.n; ++i)
      if (L.diag_pos[std::size_t(i)] < 0 || !(d.v[L.diag_pos[std::size_t(i)]] > 0))
        throw std::runtime_error(
            "distributed multigrid: a level's diagonal entry is missing or not positive");
  }

  void factor_coarsest() {
    Level& K = levels.front();
    petsc_check(MatCreateSubMatrices(K.A, 1, &all_rows, &all_rows,
                                     gathered ? MAT_REUSE_MATRIX : MAT_INITIAL_MATRIX, &gathered),
                "MatCreateSubMatrices");
    const Csr c = csr_of(gathered[0]);
    const int n = int(K.total);
    std::vector<int> outer(std::size_t(n) + 1), inner(std::size_t(c.ia[n]));
    for (int i = 0; i <= n; ++i) outer[std::size_t(i)] = int(c.ia[i]);
    for (std::size_t p = 0; p < inner.size(); ++p) inner[p] = int(c.ja[p]);
    // Symmetric: its rows are its columns.
    coarse_matrix =
        Eigen::Map<const SparseMatrix>(n, n, int(inner.size()), outer.data(), inner.data(), c.v);
    if (!analyzed) {
      coarse_factor.analyzePattern(coarse_matrix);
      analyzed = true;
    }
    coarse_factor.factorize(coarse_matrix);
    if (coarse_factor.info() != Eigen::Success)
      throw std::runtime_error("distributed multigrid: the coarsest level's factorization failed");
    coarse_b.resize(n, 3);
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

  /// One Gauss-Seidel sweep over the owned rows with the ghost rows fixed: exchanged first, or
  /// zero (`zero_ghosts`: the iterate is zero everywhere, the first sweep from a zero guess).
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
    if (forward)
      for (PetscInt i = 0; i < L.n; ++i) relax(i);
    else
      for (PetscInt i = L.n - 1; i >= 0; --i) relax(i);
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
  s.levels.back().A = A;
  for (std::size_t l = s.levels.size() - 1; l > 0; --l) {
    Mat& coarse = s.levels[l - 1].A;
    petsc_check(MatPtAP(s.levels[l].A, s.levels[l].P,
                        coarse ? MAT_REUSE_MATRIX : MAT_INITIAL_MATRIX, PETSC_DEFAULT, &coarse),
                "MatPtAP");
  }
  for (auto& L : s.levels) s.read_blocks(L);
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
    if (l + 1 < s.levels.size() && L.A) bytes += storage_bytes(L.A);
    if (L.P) bytes += storage_bytes(L.P);
    bytes += double(L.prolongation.nonZeros()) * 12.0;
    bytes +=
        8.0 * double(L.b.size() + L.x.size() + L.r.size() + L.ghost.size() + L.inv_diag.size());
  }
  if (s.gathered) bytes += storage_bytes(s.gathered[0]);
  bytes += double(s.coarse_matrix.nonZeros()) * 12.0 * 3.0;  // the matrix and its factor
  return bytes;
}

}  // namespace mcf::dist

#endif
