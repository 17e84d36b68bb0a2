#include "bases/fixed_pattern.h"

#include "core/parallel.h"

#include <tbb/parallel_sort.h>

#include <numeric>
#include <stdexcept>

namespace mcf {

FixedPattern::FixedPattern(Eigen::Index n, const std::vector<int>& rows,
                           const std::vector<int>& cols) {
  if (rows.size() != cols.size())
    throw std::invalid_argument("FixedPattern: rows/cols size mismatch");
  const std::size_t slots = rows.size();
  // Sort slots by (col, row, slot) — column-major order of the target — to find the nonzeros.
  std::vector<std::int64_t> order(slots);
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](std::int64_t s) { return std::int64_t(cols[s]) * n + rows[s]; };
  tbb::parallel_sort(order.begin(), order.end(), [&](std::int64_t a, std::int64_t b) {
    const auto ka = key(a), kb = key(b);
    return ka != kb ? ka < kb : a < b;
  });

  std::vector<int> outer(n + 1, 0), inner;
  inner.reserve(slots / 2 + 1);
  first_.clear();
  first_.reserve(slots / 2 + 2);
  std::int64_t prev = -1;
  for (std::size_t i = 0; i < slots; ++i) {
    const auto k = key(order[i]);
    if (k != prev) {
      first_.push_back(std::int64_t(i));
      inner.push_back(rows[order[i]]);
      ++outer[cols[order[i]] + 1];
      prev = k;
    }
  }
  first_.push_back(std::int64_t(slots));
  for (Eigen::Index c = 0; c < n; ++c) outer[c + 1] += outer[c];
  slot_of_ = std::move(order);

  outer_ = std::move(outer);
  inner_ = std::move(inner);
}

void FixedPattern::gather(const std::vector<double>& local, std::vector<double>& values) const {
  values.resize(inner_.size());
  double* out = values.data();
  parallel_for_indices<Eigen::Index>(non_zeros(), 4096, [&](Eigen::Index nz) {
    double sum = 0.0;
    for (std::int64_t i = first_[nz]; i < first_[nz + 1]; ++i) sum += local[slot_of_[i]];
    out[nz] = sum;
  });
}

}  // namespace mcf
