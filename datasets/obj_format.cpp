#include "datasets/obj_format.h"

#include "datasets/walk_helpers.h"

#include <unistd.h>
#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace mcf {
namespace {

using namespace walk_detail;

// OBJ: 'v' and 'f' records; a face corner is "v", "v/vt", "v/vt/vn" or "v//vn", and a negative
// v counts back from the last vertex read. Errors name the line.
void walk_obj(const std::string& path, WalkedMesh& walk) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot open file");
  walk.source_is_line = true;
  walk.index_base = 1;
  long long vertices = 0;
  std::string line;
  long long line_number = 0, max_index = 0, max_index_line = 0;
  std::vector<int> corner;
  while (std::getline(in, line)) {
    ++line_number;
    line = clean_line(line);
    if (line.size() < 2) continue;
    if (line[0] == 'v' && std::isspace(static_cast<unsigned char>(line[1]))) {
      const char* p = line.c_str() + 1;
      for (int c = 0; c < 3; ++c) {
        char* end = nullptr;
        double x = std::strtod(p, &end);
        if (end == p)
          fail(path, "vertex " + std::to_string(vertices) + ": cannot parse '" + line + "'");
        if (!std::isfinite(x))
          fail(path, "vertex " + std::to_string(vertices) + " has a non-finite coordinate ('" +
                         line + "')");
        walk.coords.push_back(x);
        p = end;
      }
      ++vertices;
      check_int_range(path, vertices, "vertices");
    } else if (line[0] == 'f' && std::isspace(static_cast<unsigned char>(line[1]))) {
      std::istringstream fs_(line.substr(2));
      std::string tok;
      corner.clear();
      while (fs_ >> tok) {
        // OpenMesh drops a face with a bad index as "non-manifold", which hides the real cause.
        char* end = nullptr;
        const long long v = std::strtoll(tok.c_str(), &end, 10);
        // v < -vertices rather than -v > vertices: strtoll saturates at LLONG_MIN, whose
        // negation overflows.
        if (end == tok.c_str() || (*end != '\0' && *end != '/') || v == 0 ||
            (v < 0 && v < -static_cast<long long>(vertices)))
          fail(path, "line " + std::to_string(line_number) + ": face corner '" + tok +
                         "' is not a vertex index (1.." + std::to_string(vertices) + " or -1..-" +
                         std::to_string(vertices) + " so far)");
        if (v > max_index) {
          max_index = v;
          max_index_line = line_number;
        }
        // Forward references (v beyond the vertices read so far) are checked once the file ends.
        corner.push_back(static_cast<int>(
            std::min<long long>(v > 0 ? v - 1 : vertices + v, std::numeric_limits<int>::max())));
      }
      if (corner.size() < 3)
        fail(path, "line " + std::to_string(line_number) + ": face with fewer than 3 corners: '" +
                       line + "'");
      add_fan(walk, corner, line_number);
    }
  }
  if (vertices == 0 && walk.triangles.empty())
    fail(path, "no vertex or face records (not an OBJ file?)");
  if (max_index > vertices)
    fail(path, "line " + std::to_string(max_index_line) + ": face refers to vertex " +
                   std::to_string(max_index) + " but the file has " + std::to_string(vertices) +
                   " vertices");
}

}  // namespace

WalkedMesh scan_obj(const std::string& path) {
  WalkedMesh walk;
  walk_obj(path, walk);
  return walk;
}

}  // namespace mcf
