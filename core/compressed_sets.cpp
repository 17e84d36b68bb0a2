#include "core/compressed_sets.h"

namespace mcf {

void sort_symmetric_sets(const std::vector<int>& start, std::vector<int>& member) {
  std::vector<int> sorted(member.size());
  std::vector<int> fill(start.begin(), start.end() - 1);
  const int n = int(start.size()) - 1;
  for (int y = 0; y < n; ++y)
    for (int e = start[std::size_t(y)]; e < start[std::size_t(y) + 1]; ++e)
      sorted[std::size_t(fill[std::size_t(member[std::size_t(e)])]++)] = y;
  member.swap(sorted);
}

}  // namespace mcf
