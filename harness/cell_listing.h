#pragma once
// `mcfbench expand CONFIG.json`: the cells of an experiment matrix, listed without running them.

#include <string>

namespace mcf {

struct CellListingRequest {
  std::string config;  ///< the experiment config (JSON)
  bool quick = false;  ///< the config's "quick" variant
  int threads = -1;    ///< as RunOptions::threads (changes the hashes)
  bool json = false;   ///< a JSON array instead of lines
};

/// One line per cell ("index hash repetition assignment", under a two-line header) or a JSON
/// array of {index, hash, key, repetition, assignment, config}; ends with a newline. The meshes
/// are loaded, since a cell's hash covers its input mesh's bytes.
std::string cell_listing(const CellListingRequest& request);

}  // namespace mcf
