// A declaration of the shape that broke the clang build of core/undirected_graph.cpp: GCC reads
// `T all(U(first[N]))` as an object initialized from first[N], clang as the declaration of a
// function `all` taking an array `first` of N elements (C++'s most vexing parse), and the uses of
// `all` below then fail to compile. With -DMCF_FIXED the line is written as the project writes it
// now. tests/compilers/check_vexing_parse.sh compiles both shapes.
#include <cstddef>
#include <vector>

std::size_t bucket_count(const std::vector<int>& first, std::size_t N) {
#ifdef MCF_FIXED
  std::vector<int> all(static_cast<std::size_t>(first[N]));
#else
  std::vector<int> all(std::size_t(first[N]));
#endif
  all.push_back(1);
  return all.size();
}
