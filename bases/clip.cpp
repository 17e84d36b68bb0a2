#include "bases/clip.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace mcf {
namespace {

// A convex polygon: triangle ∩ (up to 6 half-spaces) has at most 9 vertices.
struct Poly {
  int n = 0;
  double p[12][3];
  void push(const double* q) {
    p[n][0] = q[0];
    p[n][1] = q[1];
    p[n][2] = q[2];
    ++n;
  }
};

// Splits `in` by the plane x_axis = value into the part below (left) and above (right).
void split(const Poly& in, int axis, double value, Poly& left, Poly& right) {
  left.n = right.n = 0;
  double dmin = 0.0, dmax = 0.0;
  for (int i = 0; i < in.n; ++i) {
    const double d = in.p[i][axis] - value;
    dmin = i == 0 ? d : std::min(dmin, d);
    dmax = i == 0 ? d : std::max(dmax, d);
  }
  if (dmax <= 0.0) {  // entirely below or in the plane: nothing to cut
    left = in;
    return;
  }
  if (dmin >= 0.0) {
    right = in;
    return;
  }
  for (int i = 0; i < in.n; ++i) {
    const double* a = in.p[i];
    const double* b = in.p[(i + 1) % in.n];
    const double da = a[axis] - value, db = b[axis] - value;
    if (da <= 0.0) left.push(a);
    if (da >= 0.0) right.push(a);
    if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
      const double t = da / (da - db);
      double q[3];
      for (int c = 0; c < 3; ++c) {
        const double v = a[c] + t * (b[c] - a[c]);
        q[c] = std::clamp(v, std::min(a[c], b[c]), std::max(a[c], b[c]));
      }
      q[axis] = value;
      left.push(q);
      right.push(q);
    }
  }
}

struct Clipper {
  const GridCube& cube;
  int triangle;
  std::vector<ClippedTriangle>& out;
  double h, min_area2;
  int res;

  int slab(double x, int axis) const {
    const double u = std::floor((x - cube.origin[axis]) / h);
    return static_cast<int>(std::clamp(u, 0.0, static_cast<double>(res - 1)));
  }
  double plane(int axis, int i) const { return cube.origin[axis] + h * i; }

  void run(const Poly& poly, int axis, int cell[3]) {
    if (poly.n < 3) return;
    if (axis == 3) {
      emit(poly, cell);
      return;
    }
    double lo = poly.p[0][axis], hi = lo;
    for (int i = 1; i < poly.n; ++i) {
      lo = std::min(lo, poly.p[i][axis]);
      hi = std::max(hi, poly.p[i][axis]);
    }
    // Widen by one slab on each side: a rounding in the slab index only costs empty splits.
    const int s0 = std::max(0, slab(lo, axis) - 1), s1 = std::min(res - 1, slab(hi, axis) + 1);
    Poly rest = poly, left, right;
    for (int s = s0; s < s1; ++s) {
      split(rest, axis, plane(axis, s + 1), left, right);
      cell[axis] = s;
      run(left, axis + 1, cell);
      rest = right;
      if (rest.n < 3) return;
    }
    cell[axis] = s1;
    run(rest, axis + 1, cell);
  }

  void emit(const Poly& poly, const int cell[3]) {
    const GridKey key = grid_key(cell[0], cell[1], cell[2]);
    for (int k = 1; k + 1 < poly.n; ++k) {
      ClippedTriangle t;
      const double* q[3] = {poly.p[0], poly.p[k], poly.p[k + 1]};
      for (int v = 0; v < 3; ++v)
        for (int c = 0; c < 3; ++c) t.corners[v][c] = q[v][c];
      if (t.cross().squaredNorm() <= min_area2) continue;
      t.cell = key;
      t.triangle = triangle;
      out.push_back(t);
    }
  }
};

}  // namespace

void clip_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                   int triangle, const GridCube& cube, std::vector<ClippedTriangle>& out) {
  Clipper k{cube, triangle, out, cube.cell_size(), 0.0, cube.resolution()};
  const double a2 = 2e-14 * k.h * k.h;  // |cross| = 2 area
  k.min_area2 = a2 * a2;
  Poly p;
  p.push(a.data());
  p.push(b.data());
  p.push(c.data());
  int cell[3] = {0, 0, 0};
  k.run(p, 0, cell);
}

std::vector<ClippedTriangle> clip_mesh(const Positions& vertices, const Triangles& faces,
                                       const GridCube& cube) {
  const Eigen::Index m = faces.rows();
  constexpr Eigen::Index chunk = 512;
  const Eigen::Index nchunks = (m + chunk - 1) / chunk;
  std::vector<std::vector<ClippedTriangle>> parts(static_cast<std::size_t>(nchunks));
  tbb::parallel_for(Eigen::Index(0), nchunks, [&](Eigen::Index ch) {
    auto& out = parts[static_cast<std::size_t>(ch)];
    out.reserve(static_cast<std::size_t>(chunk) * 16);  // virtual; avoids regrowth copies
    const Eigen::Index e = std::min(m, (ch + 1) * chunk);
    for (Eigen::Index f = ch * chunk; f < e; ++f) {
      const Eigen::Vector3d a = vertices.row(faces(f, 0)).transpose();
      const Eigen::Vector3d b = vertices.row(faces(f, 1)).transpose();
      const Eigen::Vector3d c = vertices.row(faces(f, 2)).transpose();
      clip_triangle(a, b, c, static_cast<int>(f), cube, out);
    }
  });
  std::vector<std::size_t> offset(parts.size() + 1, 0);
  for (std::size_t i = 0; i < parts.size(); ++i) offset[i + 1] = offset[i] + parts[i].size();
  std::vector<ClippedTriangle> all(offset.back());
  tbb::parallel_for(std::size_t(0), parts.size(), [&](std::size_t i) {
    std::copy(parts[i].begin(), parts[i].end(),
              all.begin() + static_cast<std::ptrdiff_t>(offset[i]));
    std::vector<ClippedTriangle>().swap(parts[i]);
  });
  return all;
}

}  // namespace mcf
