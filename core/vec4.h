#pragma once
// Four doubles as one value (GCC/Clang vector extensions: one AVX register when compiled for it,
// emulated otherwise), for the kernels that handle four lanes at once: bases/cell_blocks.h holds
// a point's 8 corner lanes in two of them, bases/tracked_octree_basis.cpp four cubature points in
// one, and the multigrid's kernels (solvers/smoother.h) four right-hand-side columns of a row.

#include <algorithm>
#include <cmath>
#include <cstring>
#if defined(__AVX__)
#include <immintrin.h>
#endif

namespace mcf::vec4 {

using v4 = double __attribute__((vector_size(32)));
using m4 = long long __attribute__((vector_size(32)));  // lane masks of v4 comparisons

inline v4 splat(double x) {
  return v4{x, x, x, x};
}
/// Unaligned load and store (memcpy compiles to one vector move).
inline v4 load4(const double* p) {
  v4 r;
  std::memcpy(&r, p, sizeof(r));
  return r;
}
inline void store4(double* p, v4 x) {
  std::memcpy(p, &x, sizeof(x));
}
/// x clamped to [0, 1] lane by lane as std::clamp does it (max, then min).
inline v4 clamp01(v4 x) {
#if defined(__AVX__)
  return _mm256_min_pd(_mm256_max_pd(x, splat(0.0)), splat(1.0));
#else
  for (int a = 0; a < 4; ++a) x[a] = std::clamp(x[a], 0.0, 1.0);
  return x;
#endif
}
inline v4 sqrt4(v4 x) {
#if defined(__AVX__)
  return _mm256_sqrt_pd(x);
#else
  return v4{std::sqrt(x[0]), std::sqrt(x[1]), std::sqrt(x[2]), std::sqrt(x[3])};
#endif
}

}  // namespace mcf::vec4
