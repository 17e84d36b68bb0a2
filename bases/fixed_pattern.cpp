#include "bases/fixed_pattern.h"

#include "core/parallel.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>

namespace mcf {

FixedPattern::FixedPattern(Eigen::Index n, const std::vector<int>& rows,
                           const std::vector<int>& cols) {
  if (rows.size() != cols.size())
    throw std::invalid_argument("FixedPattern: rows/cols size mismatch");
  const std::size_t slots = rows.size();
  if (slots > std::size_t(std::numeric_limits<int>::max()))
    throw std::length_error("FixedPattern: more than 2^31 - 1 slots");
  // Order the slots by (col, row, slot), column-major order of the target: a counting sort by
  // column (slots in ascending order, so each column's bucket is in slot order), then each
  // column's few slots sorted stably by row. Linear in the slots but for the buckets' sorts.
  const std::size_t columns = std::size_t(n);
  std::vector<int> bucket(columns + 1, 0);
  for (std::size_t s = 0; s < slots; ++s) {
    if (cols[s] < 0 || cols[s] >= n || rows[s] < 0 || rows[s] >= n)
      throw std::out_of_range("FixedPattern: slot index outside the dimension");
    ++bucket[std::size_t(cols[s]) + 1];
  }
  for (std::size_t c = 0; c < columns; ++c) bucket[c + 1] += bucket[c];
  std::vector<int> order(slots);
  {
    std::vector<int> fill(bucket.begin(), bucket.end() - 1);
    for (std::size_t s = 0; s < slots; ++s)
      order[std::size_t(fill[std::size_t(cols[s])]++)] = int(s);
  }
  parallel_for_indices<std::size_t>(columns, 1024, [&](std::size_t c) {
    std::stable_sort(order.begin() + bucket[c], order.begin() + bucket[c + 1],
                     [&](int a, int b) { return rows[std::size_t(a)] < rows[std::size_t(b)]; });
  });
  const auto key = [&](int s) {
    return std::int64_t(cols[std::size_t(s)]) * n + rows[std::size_t(s)];
  };

  std::vector<int> outer(n + 1, 0), inner;
  inner.reserve(slots / 2 + 1);
  first_.clear();
  first_.reserve(slots / 2 + 2);
  std::int64_t prev = -1;
  for (std::size_t i = 0; i < slots; ++i) {
    const auto k = key(order[i]);
    if (k != prev) {
      first_.push_back(int(i));
      inner.push_back(rows[std::size_t(order[i])]);
      ++outer[cols[std::size_t(order[i])] + 1];
      prev = k;
    }
  }
  first_.push_back(int(slots));
  for (Eigen::Index c = 0; c < n; ++c) outer[c + 1] += outer[c];
  slot_of_ = std::move(order);

  outer_ = std::move(outer);
  inner_ = std::move(inner);
}

}  // namespace mcf
