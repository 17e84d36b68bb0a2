#include "solvers/blas_threads.h"

// OpenBLAS's own entry points (cblas.h declares them too, but pulls in the whole CBLAS API).
extern "C" {
void openblas_set_num_threads(int num_threads);
int openblas_get_num_threads(void);
}

namespace mcf {

// CHOLMOD sets its count around every factorization and solve (each time step): where the count
// is already the one asked for, OpenBLAS is not called.
ScopedBlasThreads::ScopedBlasThreads(int threads) : previous_(openblas_get_num_threads()) {
  if (threads > 0 && threads != previous_) openblas_set_num_threads(threads);
}

ScopedBlasThreads::~ScopedBlasThreads() {
  if (openblas_get_num_threads() != previous_) openblas_set_num_threads(previous_);
}

int blas_threads() {
  return openblas_get_num_threads();
}

int auto_blas_threads(int threads, long long dimension) {
  if (dimension < kBlasThreadsFromDimension) return 1;
  return threads < 1 ? 1 : (threads < kMaxAutoBlasThreads ? threads : kMaxAutoBlasThreads);
}

}  // namespace mcf
