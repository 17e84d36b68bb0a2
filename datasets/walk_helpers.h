#pragma once
// What the walks of the text formats (datasets/off_format.cpp, datasets/obj_format.cpp) and the
// STL scan share: errors naming the file, a line without its comment, the int range of indices.

#include "datasets/mesh_error.h"

#include <cctype>
#include <cstddef>
#include <limits>
#include <string>

namespace mcf::walk_detail {

[[noreturn]] inline void fail(const std::string& path, const std::string& problem) {
  throw MeshError(path + ": " + problem);
}

// Strips '#' comments and surrounding blanks.
inline std::string clean_line(std::string line) {
  if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
  while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
  size_t start = 0;
  while (start < line.size() && std::isspace(static_cast<unsigned char>(line[start]))) ++start;
  return line.substr(start);
}

inline void check_int_range(const std::string& path, long long count, const char* what) {
  if (count > std::numeric_limits<int>::max())
    fail(path, std::to_string(count) + " " + what + ": more than a mesh's int indices can address");
}

}  // namespace mcf::walk_detail
