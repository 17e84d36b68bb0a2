#pragma once
// The per-cell kernel of SetSystemMatrices (Chuang & Kazhdan 2011, Sec. 4; docs/design.md "The
// octree basis"): the 8x8 mass and stiffness blocks of one cell's corner functions,
// summed over the cell's cubature points,
//   M_ab += w_m β_a β_b,      K_ab += (η_a, μ_a) S (η_b, μ_b)ᵀ,
// where β are the trilinear values and (η, μ) the gradients in an orthonormal frame (e1, e2) of
// the piece's plane. The rebuilt basis integrates with the identity metric (w_m = w, S = w I); the
// tracked basis with the metric g of the current coefficients (w_m = w √|g|, S = w √|g| g⁻¹).
//
// Why a kernel of its own: this is the hot loop of both bases (one call per cubature point,
// ~2e7 per step at depth 9). Points are buffered, one lane per corner, and the blocks are
// accumulated over a batch of points with the accumulators held in vector registers (4-wide
// double vectors, GCC/Clang vector extensions: AVX2 or wider when compiled for it); only the
// upper triangles are summed (b ≥ a) and read. The order of the sums depends only on the order
// of the points, so results do not depend on threads.

#include "core/vec4.h"

#include <cmath>

namespace mcf {

/// The frame CellBlocks::add expects for a piece with corners p0, p1, p2 (any one length unit):
/// f1 = scale e1, f2 = scale e2, where e1 = (p1 - p0) / |p1 - p0| and e2 = n × e1 span the
/// piece's plane (n its unit normal). Returns |(p1 - p0) × (p2 - p0)|, twice the area; 0 for a
/// degenerate piece, whose frame is left unset.
/// One division for both vectors: with u = p1 - p0 and m = u × (p2 - p0) (|m| = len),
/// e1 = u / |u| and e2 = (m × u) / (len |u|) (this runs once per split triangle every step).
inline double piece_frame(const double p0[3], const double p1[3], const double p2[3], double scale,
                          double f1[3], double f2[3]) {
  const double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
  const double v[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
  const double m[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                       u[0] * v[1] - u[1] * v[0]};
  const double len = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
  const double ul = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  if (!(len > 0.0) || !(ul > 0.0)) return 0.0;
  const double r = scale / (len * ul);  // f2 = r (m × u), f1 = (r len) u
  const double r1 = r * len;
  const double w[3] = {m[1] * u[2] - m[2] * u[1], m[2] * u[0] - m[0] * u[2],
                       m[0] * u[1] - m[1] * u[0]};
  for (int a = 0; a < 3; ++a) {
    f1[a] = u[a] * r1;
    f2[a] = w[a] * r;
  }
  return len;
}

template <bool Mass, bool Stiffness>
class CellBlocks {
 public:
  static constexpr int kBatch = 16;

  CellBlocks() { clear(); }

  /// Starts a new cell: its blocks count from zero (the first batch does not load them).
  void clear() {
    count_ = 0;
    fresh_ = true;  // the first batch starts its sums from zero instead of loading the blocks
  }

  /// One cubature point at local cell coordinates t ∈ [0,1]^3. f1, f2 = e1/h, e2/h: the frame
  /// vectors divided by the cell size, so that η_a = f1 · ∇_t β_a (world units). wm weights the
  /// mass; (s11, s12, s22) is the symmetric 2x2 form S of the stiffness.
  void add(const double t[3], const double f1[3], const double f2[3], double wm, double s11,
           double s12, double s22) {
    // Corner c = x + 2y + 4z: lanes lo = corners 0..3 (z = 0), hi = corners 4..7 (z = 1).
    const double u = t[0], v = t[1], z = t[2];
    const v4 bx = {1 - u, u, 1 - u, u}, by = {1 - v, 1 - v, v, v};
    const v4 sx = {-1, 1, -1, 1}, sy = {-1, -1, 1, 1};
    const v4 bxy = bx * by;
    const v4 z0 = splat(1 - z), z1 = splat(z);
    double* slot = lanes_[count_];
    if constexpr (Mass) {
      const v4 val_lo = bxy * z0, val_hi = bxy * z1;
      store(slot + kVal, val_lo);
      store(slot + kVal + 4, val_hi);
      store(slot + kWVal, splat(wm) * val_lo);
      store(slot + kWVal + 4, splat(wm) * val_hi);
    }
    if constexpr (Stiffness) {
      // ∇_t β = (sx by bz, bx sy bz, bx by sz) with sz = -1 (lo) / +1 (hi).
      const v4 gxy1 = splat(f1[0]) * sx * by + splat(f1[1]) * sy * bx;
      const v4 gxy2 = splat(f2[0]) * sx * by + splat(f2[1]) * sy * bx;
      const v4 eta_lo = gxy1 * z0 - splat(f1[2]) * bxy, eta_hi = gxy1 * z1 + splat(f1[2]) * bxy;
      const v4 mu_lo = gxy2 * z0 - splat(f2[2]) * bxy, mu_hi = gxy2 * z1 + splat(f2[2]) * bxy;
      store(slot + kEta, eta_lo);
      store(slot + kEta + 4, eta_hi);
      store(slot + kMu, mu_lo);
      store(slot + kMu + 4, mu_hi);
      const v4 a11 = splat(s11), a12 = splat(s12), a22 = splat(s22);
      store(slot + kP, a11 * eta_lo + a12 * mu_lo);
      store(slot + kP + 4, a11 * eta_hi + a12 * mu_hi);
      store(slot + kQ, a12 * eta_lo + a22 * mu_lo);
      store(slot + kQ + 4, a12 * eta_hi + a22 * mu_hi);
    }
    if (++count_ == kBatch) accumulate();
  }

  /// Sums the buffered points; then mass(a,b) / stiffness(a,b) for a ≤ b are the cell's blocks.
  void finish() { accumulate(); }
  double mass(int a, int b) const { return m_[a][b]; }
  double stiffness(int a, int b) const { return k_[a][b]; }

 private:
  using v4 = vec4::v4;
  static v4 splat(double x) { return vec4::splat(x); }
  static v4 load(const double* p) { return vec4::load4(p); }
  static void store(double* p, v4 x) { vec4::store4(p, x); }

  // Per buffered point: 8 lanes each of β, w_m β, η, μ, P = S₁₁η + S₁₂μ, Q = S₁₂η + S₂₂μ.
  enum { kVal = 0, kWVal = 8, kEta = 16, kMu = 24, kP = 32, kQ = 40, kLanes = 48 };

  /// The upper triangle of an 8x8 block as vector lanes: row a in lanes b = 0..3 (only for
  /// a < 4) and b = 4..7.
  struct Upper {
    v4 lo[4], hi[8];
  };
  Upper load_upper(const double (&block)[8][8]) const {
    Upper u;
    if (fresh_) {
      for (auto& v : u.lo) v = splat(0.0);
      for (auto& v : u.hi) v = splat(0.0);
      return u;
    }
    for (int a = 0; a < 4; ++a) u.lo[a] = load(&block[a][0]);
    for (int a = 0; a < 8; ++a) u.hi[a] = load(&block[a][4]);
    return u;
  }
  static void store_upper(double (&block)[8][8], const Upper& u) {
    for (int a = 0; a < 4; ++a) store(&block[a][0], u.lo[a]);
    for (int a = 0; a < 8; ++a) store(&block[a][4], u.hi[a]);
  }

  /// Sums the buffered points into the blocks' upper triangles, held in registers meanwhile.
  void accumulate() {
    if (count_ == 0 && !fresh_) return;  // a cell without points still stores its zero blocks
    if constexpr (Mass) {
      Upper m = load_upper(m_);
      v4(&lo)[4] = m.lo;
      v4(&hi)[8] = m.hi;
      for (int p = 0; p < count_; ++p) {
        const double* s = lanes_[p];
        const v4 vlo = load(s + kVal), vhi = load(s + kVal + 4);
#pragma GCC unroll 8
        for (int a = 0; a < 8; ++a) {
          const v4 wa = splat(s[kWVal + a]);
          if (a < 4) lo[a] += wa * vlo;
          hi[a] += wa * vhi;
        }
      }
      store_upper(m_, m);
    }
    if constexpr (Stiffness) {
      // Two passes over the points, rows 0..3 (8 accumulators) then rows 4..7 (4), so that the
      // accumulators, four lane vectors and two broadcasts fit 16 AVX registers (all twelve at
      // once spilled on AVX2); each term is two multiply-adds into the accumulator.
      Upper k = load_upper(k_);
      v4(&lo)[4] = k.lo;
      v4(&hi)[8] = k.hi;
      for (int p = 0; p < count_; ++p) {
        const double* s = lanes_[p];
        const v4 elo = load(s + kEta), ehi = load(s + kEta + 4);
        const v4 mlo = load(s + kMu), mhi = load(s + kMu + 4);
#pragma GCC unroll 4
        for (int a = 0; a < 4; ++a) {
          const v4 pa = splat(s[kP + a]), qa = splat(s[kQ + a]);
          lo[a] += pa * elo;
          lo[a] += qa * mlo;
          hi[a] += pa * ehi;
          hi[a] += qa * mhi;
        }
      }
      for (int p = 0; p < count_; ++p) {
        const double* s = lanes_[p];
        const v4 ehi = load(s + kEta + 4), mhi = load(s + kMu + 4);
#pragma GCC unroll 4
        for (int a = 4; a < 8; ++a) {
          hi[a] += splat(s[kP + a]) * ehi;
          hi[a] += splat(s[kQ + a]) * mhi;
        }
      }
      store_upper(k_, k);
    }
    count_ = 0;
    fresh_ = false;
  }

  alignas(32) double m_[8][8];
  alignas(32) double k_[8][8];
  alignas(32) double lanes_[kBatch][kLanes];
  int count_ = 0;
  bool fresh_ = true;
};

}  // namespace mcf
