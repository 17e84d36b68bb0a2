#include "solvers/petsc_galerkin.h"

#include "solvers/petsc_runtime.h"

#ifdef MCFBENCH_HAVE_PETSC
#include <petscmat.h>

#include <algorithm>
#include <vector>
#endif

namespace mcf {

#ifndef MCFBENCH_HAVE_PETSC

struct PetscGalerkin::Internals {};

PetscGalerkin::PetscGalerkin(const SparseMatrix&, const SparseMatrix&, const std::string&) {
  throw PetscUnavailable(petsc_unavailable_message());
}
PetscGalerkin::~PetscGalerkin() = default;
void PetscGalerkin::refresh(const double*) {}
void PetscGalerkin::multiply() {}
SparseMatrix PetscGalerkin::product() const {
  return {};
}

#else

namespace {

/// A sequential AIJ matrix of compressed rows (ia, ja sorted within each row, values).
Mat seq_aij(PetscInt rows, PetscInt cols, const std::vector<PetscInt>& ia,
            const std::vector<PetscInt>& ja, const std::vector<PetscScalar>& values) {
  Mat M = nullptr;
  petsc_check(MatCreate(PETSC_COMM_SELF, &M), "MatCreate");
  petsc_check(MatSetSizes(M, rows, cols, rows, cols), "MatSetSizes");
  petsc_check(MatSetType(M, MATSEQAIJ), "MatSetType");
  petsc_check(MatSeqAIJSetPreallocationCSR(M, ia.data(), ja.data(), values.data()),
              "MatSeqAIJSetPreallocationCSR");
  return M;
}

/// S's compressed rows: a row-major copy (Eigen sorts the indices).
Mat seq_aij_of(const SparseMatrix& S) {
  const Eigen::SparseMatrix<double, Eigen::RowMajor, int> R(S);
  std::vector<PetscInt> ia(R.outerIndexPtr(), R.outerIndexPtr() + R.rows() + 1);
  std::vector<PetscInt> ja(R.innerIndexPtr(), R.innerIndexPtr() + R.nonZeros());
  std::vector<PetscScalar> values(R.valuePtr(), R.valuePtr() + R.nonZeros());
  return seq_aij(PetscInt(R.rows()), PetscInt(R.cols()), ia, ja, values);
}

}  // namespace

struct PetscGalerkin::Internals {
  Mat A = nullptr, P = nullptr, C = nullptr;
  Eigen::Index a_nonzeros = 0;
  ~Internals() {
    for (Mat* M : {&C, &P, &A})
      if (*M) MatDestroy(M);
  }
};

PetscGalerkin::PetscGalerkin(const SparseMatrix& A, const SparseMatrix& P,
                             const std::string& algorithm)
    : m_(std::make_unique<Internals>()) {
  PetscRuntime::instance();
  // A is symmetric: its compressed columns are its compressed rows, in the same order, so a
  // refresh writes A's values straight into PETSc's array.
  std::vector<PetscInt> ia(A.outerIndexPtr(), A.outerIndexPtr() + A.cols() + 1);
  std::vector<PetscInt> ja(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
  std::vector<PetscScalar> values(A.valuePtr(), A.valuePtr() + A.nonZeros());
  m_->A = seq_aij(PetscInt(A.rows()), PetscInt(A.cols()), ia, ja, values);
  m_->a_nonzeros = A.nonZeros();
  m_->P = seq_aij_of(P);
  petsc_check(MatProductCreate(m_->A, m_->P, nullptr, &m_->C), "MatProductCreate");
  petsc_check(MatProductSetType(m_->C, MATPRODUCT_PtAP), "MatProductSetType");
  petsc_check(MatProductSetAlgorithm(m_->C, algorithm.c_str()), "MatProductSetAlgorithm");
  petsc_check(MatProductSetFill(m_->C, PETSC_DEFAULT), "MatProductSetFill");
  petsc_check(MatProductSetFromOptions(m_->C), "MatProductSetFromOptions");
  petsc_check(MatProductSymbolic(m_->C), "MatProductSymbolic");
  petsc_check(MatProductNumeric(m_->C), "MatProductNumeric");
}

PetscGalerkin::~PetscGalerkin() = default;

void PetscGalerkin::refresh(const double* a_values) {
  PetscScalar* v = nullptr;
  petsc_check(MatSeqAIJGetArray(m_->A, &v), "MatSeqAIJGetArray");
  std::copy(a_values, a_values + m_->a_nonzeros, v);
  petsc_check(MatSeqAIJRestoreArray(m_->A, &v), "MatSeqAIJRestoreArray");
  multiply();
}

void PetscGalerkin::multiply() {
  petsc_check(MatProductNumeric(m_->C), "MatProductNumeric");
}

SparseMatrix PetscGalerkin::product() const {
  PetscInt rows = 0;
  const PetscInt *ia = nullptr, *ja = nullptr;
  PetscBool done = PETSC_FALSE;
  petsc_check(MatGetRowIJ(m_->C, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done),
              "MatGetRowIJ");
  if (!done) throw PetscFailure("MatGetRowIJ: the product's rows are not available");
  const PetscScalar* v = nullptr;
  petsc_check(MatSeqAIJGetArrayRead(m_->C, &v), "MatSeqAIJGetArrayRead");
  PetscInt cols = 0;
  petsc_check(MatGetSize(m_->C, nullptr, &cols), "MatGetSize");
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(std::size_t(ia[rows]));
  for (PetscInt i = 0; i < rows; ++i)
    for (PetscInt e = ia[i]; e < ia[i + 1]; ++e) entries.emplace_back(int(i), int(ja[e]), v[e]);
  const PetscInt n = rows;  // MatRestoreRowIJ zeroes `rows`
  petsc_check(MatSeqAIJRestoreArrayRead(m_->C, &v), "MatSeqAIJRestoreArrayRead");
  petsc_check(MatRestoreRowIJ(m_->C, 0, PETSC_FALSE, PETSC_FALSE, &rows, &ia, &ja, &done),
              "MatRestoreRowIJ");
  SparseMatrix C(n, cols);
  C.setFromTriplets(entries.begin(), entries.end());
  return C;
}

#endif

}  // namespace mcf
