#pragma once
// The undirected graph of a list of vertex pairs in compressed rows: what the vertex orderings
// and the surface hierarchy walk.

#include <utility>
#include <vector>

namespace mcf {

/// Inputs:
///   n      vertices, numbered 0 .. n-1
///   pairs  edges (a, b), each given once or more times, either way round; pairs with a == b
///          are left out
/// Outputs:
///   start      n + 1 offsets
///   neighbour  the neighbours of v in neighbour[start[v] .. start[v+1]), ascending, each once
/// The same arrays as sorting every directed pair and removing duplicates, in linear time: one
/// counting pass, then a sort of each vertex's few neighbours, in parallel over vertices
/// (deterministic: no vertex's output depends on another's).
void undirected_graph(int n, const std::vector<std::pair<int, int>>& pairs, std::vector<int>& start,
                      std::vector<int>& neighbour);

}  // namespace mcf
