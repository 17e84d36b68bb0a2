#pragma once
// The BLAS under CHOLMOD's supernodal factorization (OpenBLAS, cmake/FindCholmod.cmake) keeps its
// own thread pool, sized to every core whatever TBB is allowed: a flow's `threads` must cap both,
// or `--threads 1` still runs the factorization on all cores.

namespace mcf {

/// Caps OpenBLAS at `threads` (> 0) for this object's life and restores the previous cap after.
/// OpenBLAS's result depends on its thread count (its blocking does), so CHOLMOD's factor is
/// bitwise the same for one thread count, not across them.
class ScopedBlasThreads {
 public:
  explicit ScopedBlasThreads(int threads);
  ~ScopedBlasThreads();
  ScopedBlasThreads(const ScopedBlasThreads&) = delete;
  ScopedBlasThreads& operator=(const ScopedBlasThreads&) = delete;

 private:
  int previous_;
};

/// OpenBLAS's current thread cap.
int blas_threads();

/// The BLAS threads for CHOLMOD's factorization of a system of `dimension` unknowns when `threads`
/// may run: at most four, however many cores there are, and one below kBlasThreadsFromDimension
/// unknowns. The supernodal updates of a surface's factor are small; OpenBLAS's threads spin on
/// them, and beyond a few threads the factorization gets slower, not faster (the measurements are
/// in docs/benchmarks.md, "BLAS threads").
int auto_blas_threads(int threads, long long dimension);
inline constexpr long long kBlasThreadsFromDimension = 20000;
inline constexpr int kMaxAutoBlasThreads = 4;

}  // namespace mcf
