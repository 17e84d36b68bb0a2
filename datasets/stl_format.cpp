#include "datasets/stl_format.h"

#include "datasets/openmesh_mesh.h"
#include "datasets/walk_helpers.h"

#include <OpenMesh/Core/IO/MeshIO.hh>

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

namespace fs = std::filesystem;
using namespace walk_detail;
using namespace openmesh_detail;

// Whether word is the keyword (given in lowercase) in any case: STL's keywords are lowercase, but
// files in capitals ("SOLID", "OUTER LOOP", "VERTEX") exist.
bool is_keyword(std::string_view word, std::string_view keyword) {
  return word.size() == keyword.size() &&
         std::equal(word.begin(), word.end(), keyword.begin(), [](char w, char k) {
           return std::tolower(static_cast<unsigned char>(w)) == k;
         });
}

// The lines of an ASCII STL as OpenMesh 9's reader takes them (STLReader.cc, read_stla): a line
// containing "outer" (or "OUTER") opens a facet, and the next three lines are its corners, each
// read as a word and three floats with `>>`, which on bad text keeps whatever the stream holds
// (`vertex 0 1 zz` came out as (0, 1, 0), a missing coordinate as the last vertex's, `1e999` as
// FLT_MAX). The corner's word is checked to be "vertex" in any case (`>>` skips it whatever it
// is); a line starting with "outer" in mixed case ("Outer loop") opens no facet there, so it is
// refused rather than let its facet be skipped. Fed the file's bytes in order, in pieces of any
// size; keeps only the current line (at most 1 MiB). The first problem is kept as an error naming
// the line.
class AsciiStlLines {
 public:
  void feed(const char* p, std::size_t n) {
    while (n > 0 && error_.empty()) {
      const char* nl = static_cast<const char*>(std::memchr(p, '\n', n));
      const std::size_t len = nl ? static_cast<std::size_t>(nl - p) : n;
      if (partial_.empty() && !overlong_ && nl) {
        line(std::string_view(p, len));  // whole in this piece: not copied
      } else {
        if (!overlong_ && partial_.size() + len > kMaxLine) {
          overlong_ = true;
          partial_.clear();
        }
        if (!overlong_) partial_.append(p, len);
        if (nl) {
          line(partial_);
          partial_.clear();
          overlong_ = false;
        }
      }
      if (!nl) break;
      p = nl + 1;
      n -= len + 1;
    }
  }
  // At the end of the file: its last line, if it has no newline, and a facet cut short.
  void finish() {
    if (!error_.empty()) return;
    if (!partial_.empty() || overlong_) line(partial_);
    if (error_.empty() && corners_due_ > 0)
      error_ = "the file ends " + std::to_string(corners_due_) +
               " vertex line(s) short of the facet opened on line " + std::to_string(loop_line_);
  }
  const std::string& error() const { return error_; }
  /// Facets opened so far: the triangles OpenMesh's reader will try to add, to compare with those
  /// it added. (The word "facet" is no count: a solid may be named "facet_x".)
  long long facets() const { return facets_; }

 private:
  static constexpr std::size_t kMaxLine = std::size_t(1) << 20;
  static constexpr const char* kBlank = " \t\r\n\v\f";

  static std::string quoted(std::string_view s) {
    const auto b = s.find_first_not_of(kBlank);
    if (b == std::string_view::npos) return "an empty line";
    s = s.substr(b, s.find_last_not_of(kBlank) - b + 1);
    return "'" + std::string(s.substr(0, 80)) + (s.size() > 80 ? "...'" : "'");
  }
  // Splits off the next blank-separated word of s (empty at the end).
  static std::string_view word(std::string_view& s) {
    const auto b = s.find_first_not_of(kBlank);
    if (b == std::string_view::npos) return s = {};
    const auto e = std::min(s.find_first_of(kBlank, b), s.size());
    const std::string_view w = s.substr(b, e - b);
    s.remove_prefix(e);
    return w;
  }
  void problem(const std::string& what) {
    error_ = "line " + std::to_string(number_) + ": " + what;
  }

  void line(std::string_view s) {
    ++number_;
    if (overlong_) return problem("longer than 1 MiB (not an STL line)");
    std::string_view rest = s;
    const std::string_view first = word(rest);
    if (corners_due_ == 0) {
      if (is_keyword(first, "vertex"))
        return problem(
            "a vertex line outside a facet's three corners (OpenMesh's reader skips it): " +
            quoted(s));
      if (s.find("outer") != std::string_view::npos || s.find("OUTER") != std::string_view::npos) {
        corners_due_ = 3;
        loop_line_ = number_;
        ++facets_;
      } else if (is_keyword(first, "outer")) {
        return problem(
            quoted(s) +
            ": OpenMesh's reader opens a facet only at 'outer' or 'OUTER' (STL's keywords "
            "are lowercase), and would skip this one");
      }
      return;
    }
    --corners_due_;
    if (!is_keyword(first, "vertex"))
      return problem("expected 'vertex x y z', corner " + std::to_string(3 - corners_due_) +
                     " of the facet opened by 'outer' on line " + std::to_string(loop_line_) +
                     ", found " + quoted(s));
    int count = 0;
    for (std::string_view w = word(rest); !w.empty(); w = word(rest), ++count) {
      if (count == 3) return problem("vertex line with more than 3 coordinates: " + quoted(s));
      // Decimal text only, as `>>` reads it (no hex, inf or nan), and finite as a float: STL
      // stores 32-bit floats and `>>` turns 1e39 into FLT_MAX without a word. from_chars takes
      // the common case fast; strtof the rest ('+', and out of range: underflow is fine).
      float y = 0;
      const auto [ptr, ec] = std::from_chars(w.data(), w.data() + w.size(), y);
      if (ec == std::errc() && ptr == w.data() + w.size()) {
        if (std::isfinite(y)) continue;
        return problem("non-finite vertex coordinate '" + std::string(w) +
                       "' (STL coordinates are 32-bit floats, at most about 3.4e38): " + quoted(s));
      }
      number_text_.assign(w);
      char* end = nullptr;
      const float x = std::strtof(number_text_.c_str(), &end);
      const bool whole = end == number_text_.c_str() + number_text_.size();
      if (whole && !std::isfinite(x))
        return problem("non-finite vertex coordinate '" + number_text_ +
                       "' (STL coordinates are 32-bit floats, at most about 3.4e38): " + quoted(s));
      if (!whole || number_text_.find_first_not_of("0123456789+-.eE") != std::string::npos)
        return problem("vertex coordinate '" + number_text_ + "' is not a number: " + quoted(s));
    }
    if (count < 3)
      return problem("vertex line with " + std::to_string(count) +
                     " of 3 coordinates: " + quoted(s));
  }

  std::string partial_;      // the current line's bytes from earlier pieces
  bool overlong_ = false;    // the current line passed kMaxLine (its bytes are dropped)
  long long number_ = 0;     // lines ended so far
  int corners_due_ = 0;      // vertex lines the open facet still needs
  long long facets_ = 0;     // facets opened ('outer' lines): the triangles OpenMesh tries to add
  long long loop_line_ = 0;  // the line that opened it
  std::string number_text_;  // a coordinate, NUL-terminated for strtof
  std::string error_;
};

// The offset of the first byte no text holds (a control character other than a blank or a line
// end), or npos. A binary STL's count and float records all but always hold one (0 is four NUL
// bytes, 1.0f is 00 00 80 3f); an ASCII STL, UTF-8 names included, none.
std::size_t first_non_text_byte(std::string_view bytes) {
  const auto it = std::find_if(bytes.begin(), bytes.end(), [](char ch) {
    const auto c = static_cast<unsigned char>(ch);
    return (c < 0x20 && !std::isspace(c)) || c == 0x7f;
  });
  return it == bytes.end() ? std::string_view::npos : static_cast<std::size_t>(it - bytes.begin());
}

// Whether the file's bytes from offset `from` to its end are all zero.
bool zeros_from(const std::string& path, unsigned long long from) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  in.seekg(static_cast<std::streamoff>(from));
  std::vector<char> chunk(std::size_t(1) << 16);
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const auto end = chunk.begin() + in.gcount();
    if (std::any_of(chunk.begin(), end, [](char c) { return c != 0; })) return false;
  }
  return in.eof();
}

// Binary STL: an 80-byte header, the triangle count N at byte 80, then 50 bytes a triangle.
// OpenMesh reads exactly N (when told the file is binary: read_stl_through_openmesh), so bytes
// after them are accepted as padding, as some exporters write, when they cannot hold a triangle
// (fewer than 50) or are all zero (a zero record would be a degenerate triangle at the origin);
// other bytes after them may be triangles a wrong count leaves out, and are refused, as is a
// file too short for its count. `why` says why the file is not read as ASCII.
long long binary_stl_triangles(const std::string& path, const std::string& head,
                               const std::string& why) {
  if (head.size() < 84) fail(path, "binary STL shorter than its 84-byte header (" + why + ")");
  std::uint32_t n = 0;
  std::memcpy(&n, head.data() + 80, 4);
  std::error_code ec;
  const unsigned long long size = fs::file_size(path, ec);
  if (ec) fail(path, "cannot read the file's size: " + ec.message());
  const unsigned long long need = 84 + 50ull * n;
  const std::string announced =
      "binary STL announces " + std::to_string(n) + " triangles (84 + 50 * " + std::to_string(n) +
      " = " + std::to_string(need) + " bytes) but the file has " + std::to_string(size) + " bytes";
  if (size < need) fail(path, announced + " (" + why + ")");
  if (size - need >= 50 && !zeros_from(path, need))
    fail(path, announced + ": the " + std::to_string(size - need) +
                   " bytes after its last triangle, too many for padding and not all zero, may be "
                   "triangles "
                   "its count leaves out");
  return n;
}

// STL: the layout OpenMesh is told to read, and the triangles the file holds, to compare with
// those OpenMesh added. OpenMesh's own guess (OpenMesh 9, STLReader.cc, check_stl_type) takes a
// file for binary only when its length is exactly 84 + 50 N, so a binary file with bytes after
// its triangles was read as ASCII: as nothing, or as garbage.
struct StlLayout {
  bool binary = false;
  long long triangles = 0;  // ASCII: the facets OpenMesh opens ('outer' lines, AsciiStlLines)
};

// A file is ASCII if it starts with "solid", in any case (a file in capitals is ASCII too), and its
// first 84 + 1 MiB bytes are text: some binary exporters start their header with "solid" too, and
// words like "facet" after it, so no word in the file decides it. An ASCII file is streamed in an
// 84-byte head and then 1 MiB chunks, never held whole, and the same pass checks its lines
// (AsciiStlLines) and counts its facets. Any other file is binary, and is not read here beyond its
// header and its length (OpenMesh reads it next). Vertices are merged by OpenMesh (STL has no
// shared vertices), so their count is unknown in advance.
StlLayout scan_stl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  const auto read = [&](std::string& bytes, std::size_t n) {
    bytes.resize(n);
    in.read(bytes.data(), static_cast<std::streamsize>(n));
    bytes.resize(static_cast<std::size_t>(in.gcount()));
  };
  constexpr std::size_t kChunk = std::size_t(1) << 20;
  std::string head, chunk;
  read(head, 84);
  read(chunk, kChunk);
  const auto start = head.find_first_not_of(" \t\r\n");
  if (start == std::string::npos || !is_keyword(std::string_view(head).substr(start, 5), "solid"))
    return {true, binary_stl_triangles(path, head,
                                       "it does not start with 'solid', so it is no ASCII STL")};
  std::size_t bad = first_non_text_byte(head);
  if (bad == std::string::npos && (bad = first_non_text_byte(chunk)) != std::string::npos)
    bad += head.size();
  if (bad != std::string::npos) {
    const auto c =
        static_cast<unsigned char>(bad < head.size() ? head[bad] : chunk[bad - head.size()]);
    char byte[8];
    std::snprintf(byte, sizeof byte, "0x%02x", c);
    return {true, binary_stl_triangles(
                      path, head,
                      "it starts with 'solid', as some binary headers do, but its byte " +
                          std::to_string(bad) + " is " + byte + ", which no ASCII STL holds")};
  }
  AsciiStlLines lines;
  lines.feed(head.data(), head.size());
  while (!chunk.empty() && lines.error().empty()) {  // after a bad line, no need to read on
    lines.feed(chunk.data(), chunk.size());
    read(chunk, kChunk);
  }
  lines.finish();
  if (!lines.error().empty()) fail(path, lines.error());
  return {false, lines.facets()};
}

// STL: OpenMesh reads it in the layout scan_stl found (from a stream, whose reader takes the
// layout from the Binary option, not from the file's length), merging the file's corners into
// vertices; what it dropped or duplicated is detected by counts.
TriangleMesh read_stl_through_openmesh(const std::string& path, const StlLayout& layout) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  IoMesh om;
  OpenMesh::IO::Options opt;
  if (layout.binary) opt += OpenMesh::IO::Options::Binary;
  if (!OpenMesh::IO::read_mesh(om, in, ".stl", opt))
    fail(path, "OpenMesh could not parse the file");
  const long long file_triangles = layout.triangles;
  const long long nv = static_cast<long long>(om.n_vertices());
  const long long nf = static_cast<long long>(om.n_faces());
  {
    // STL has no vertex list to count against; OpenMesh merges equal corners, so two loaded
    // vertices at exactly the same position mean it split a vertex to add a non-manifold face.
    std::vector<std::array<double, 3>> points;
    points.reserve(nv);
    for (auto vh : om.vertices()) {
      const auto& p = om.point(vh);
      points.push_back({p[0], p[1], p[2]});
    }
    std::sort(points.begin(), points.end());
    if (std::adjacent_find(points.begin(), points.end()) != points.end())
      fail(
          path,
          "non-manifold mesh: OpenMesh had to duplicate vertices to add faces around complex edges "
          "or vertices (an edge in more than two faces, or inconsistently oriented faces)");
  }
  if (nf < file_triangles)
    fail(path, "only " + std::to_string(nf) + " of the file's " + std::to_string(file_triangles) +
                   " triangles could be added: the mesh has non-manifold (complex) edges, repeated "
                   "vertex indices in a face, or inconsistently oriented faces");
  TriangleMesh mesh;
  mesh.vertices.resize(nv, 3);
  for (auto vh : om.vertices()) {
    const auto& p = om.point(vh);
    mesh.vertices.row(vh.idx()) << p[0], p[1], p[2];
  }
  mesh.faces.resize(nf, 3);
  for (auto fh : om.faces()) {
    int c = 0;
    for (auto vh : om.fv_range(fh)) {
      if (c == 3)
        fail(path, "face " + std::to_string(fh.idx()) + " is not a triangle after loading");
      mesh.faces(fh.idx(), c++) = vh.idx();
    }
  }
  return mesh;
}

}  // namespace

TriangleMesh read_stl(const std::string& path) {
  return read_stl_through_openmesh(path, scan_stl(path));
}

}  // namespace mcf
