#include "bases/fixed_pattern.h"

#include "core/parallel.h"

#include <tbb/parallel_sort.h>

#include <limits>
#include <numeric>
#include <stdexcept>

namespace mcf {

FixedPattern::FixedPattern(Eigen::Index n, const std::vector<int>& rows,
                           const std::vector<int>& cols) {
  if (rows.size() != cols.size())
    throw std::invalid_argument("FixedPattern: rows/cols size mismatch");
  const std::size_t slots = rows.size();
  if (slots > std::size_t(std::numeric_limits<int>::max()))
    throw std::length_error("FixedPattern: more than 2^31 - 1 slots");
  // Sort slots by (col, row, slot) — column-major order of the target — to find the nonzeros.
  std::vector<int> order(slots);
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](int s) { return std::int64_t(cols[std::size_t(s)]) * n + rows[std::size_t(s)]; };
  tbb::parallel_sort(order.begin(), order.end(), [&](int a, int b) {
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
      first_.push_back(int(i));
      inner.push_back(rows[order[i]]);
      ++outer[cols[order[i]] + 1];
      prev = k;
    }
  }
  first_.push_back(int(slots));
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
    for (int i = first_[std::size_t(nz)]; i < first_[std::size_t(nz) + 1]; ++i)
      sum += local[std::size_t(slot_of_[std::size_t(i)])];
    out[nz] = sum;
  });
}

}  // namespace mcf
