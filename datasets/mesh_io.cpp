// Mesh file I/O. OFF, OBJ and PLY are walked here (and in ply_format.cpp) once, in exact doubles,
// with errors that name the line; OpenMesh's half-edge insertion then checks the topology, which
// its own readers would instead repair silently by dropping faces or duplicating vertices
// (docs/flow.md "Formats"). Binary OFF is walked here too, in the layout OpenMesh reads. STL
// is read by OpenMesh, in the layout (ASCII or binary) decided here rather than by its guess from
// the file's length, and checked by counts, after a streaming pass that checks its lines.

#include "datasets/mesh_io.h"

#include "core/atomic_file.h"
#include "datasets/orientation.h"
#include "datasets/ply_format.h"
#include "datasets/walked_mesh.h"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>

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

// Double-precision points: the default traits store floats, which would round every coordinate
// of an ASCII file we read and of every file we write.
struct IoTraits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;
  using Normal = OpenMesh::Vec3d;
};
using IoMesh = OpenMesh::TriMesh_ArrayKernelT<IoTraits>;

// OpenMesh prints warnings (e.g. "complex edge") on its own streams; we report problems through
// MeshError instead, so its chatter only confuses logs of batch runs.
void silence_openmesh() {
  static std::once_flag once;
  std::call_once(once, [] {
    ::omerr().disable();
    ::omlog().disable();
    ::omout().disable();
  });
}

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

[[noreturn]] void fail(const std::string& path, const std::string& problem) {
  throw MeshError(path + ": " + problem);
}

// Strips '#' comments and surrounding blanks.
std::string clean_line(std::string line) {
  if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
  while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
  size_t start = 0;
  while (start < line.size() && std::isspace(static_cast<unsigned char>(line[start]))) ++start;
  return line.substr(start);
}

void check_int_range(const std::string& path, long long count, const char* what) {
  if (count > std::numeric_limits<int>::max())
    fail(path, std::to_string(count) + " " + what + ": more than a mesh's int indices can address");
}

// The OFF keyword's prefixes, "[ST][C][N][4][n]OFF" (Geomview's OFF format): colours, normals and
// texture coordinates follow a vertex's coordinates and are ignored, but "4" makes the coordinates
// homogeneous (x y z w, the point is (x, y, z)/w) and "n" puts a dimension before the counts.
// Reading 4OFF's first three numbers as the point would silently scale every vertex by w.
struct OffKeyword {
  bool homogeneous = false;  ///< "4": four coordinates per vertex
  bool dimension = false;    ///< "n": the header gives the dimension before the counts
};

OffKeyword parse_off_keyword(const std::string& path, const std::string& magic) {
  if (magic.size() < 3 || magic.compare(magic.size() - 3, 3, "OFF") != 0)
    fail(path, "not an OFF file (header '" + magic + "')");
  OffKeyword k;
  std::string_view prefix(magic.data(), magic.size() - 3);
  auto take = [&](std::string_view letters) {
    if (!prefix.starts_with(letters)) return false;
    prefix.remove_prefix(letters.size());
    return true;
  };
  take("ST");  // texture coordinates, as one prefix (as walk_off_binary reads it too)
  take("C");
  take("N");
  k.homogeneous = take("4");
  k.dimension = take("n");
  if (!prefix.empty())
    fail(path, "not an OFF file (header '" + magic + "'; the keyword is [ST][C][N][4][n]OFF)");
  return k;
}

// ASCII OFF's header: the keyword, then (after nOFF's dimension) the counts.
struct OffHeader {
  OffKeyword keyword;
  long long vertices = -1, faces = -1;
};

/// Reads the header; false for binary OFF (walk_off_binary's).
bool read_off_header(const std::string& path, std::ifstream& in, OffHeader& h) {
  std::string line, header;
  while (std::getline(in, line)) {
    header = clean_line(line);
    if (!header.empty()) break;
  }
  if (header.empty()) fail(path, "empty file (no OFF header)");
  std::istringstream hs(header);
  std::string magic;
  hs >> magic;
  h.keyword = parse_off_keyword(path, magic);
  std::string rest;
  std::getline(hs, rest);
  if (rest.find("BINARY") != std::string::npos) return false;
  // The counts (after nOFF's dimension) may follow on the keyword's line or on a later one.
  const auto skip_blank_lines = [&] {
    rest = clean_line(rest);
    while (rest.empty() && std::getline(in, line)) rest = clean_line(line);
  };
  skip_blank_lines();
  if (h.keyword.dimension) {  // "nOFF": the dimension, then the counts (same line or the next)
    std::istringstream ds(rest);
    long long dim = -1;
    if (!(ds >> dim)) fail(path, "bad " + magic + " dimension line '" + rest + "'");
    if (dim != 3)
      fail(path, magic + " of dimension " + std::to_string(dim) +
                     ": only surfaces in 3 dimensions are read");
    rest.clear();  // getline leaves it alone when the dimension ended the line
    std::getline(ds, rest);
    skip_blank_lines();
  }
  std::istringstream cs(rest);
  if (!(cs >> h.vertices >> h.faces) || h.vertices < 0 || h.faces < 0)
    fail(path, "bad OFF counts line '" + rest + "'");
  return true;
}

/// The vertex lines: finite coordinates, a homogeneous w neither 0 nor overflowing x/w.
void read_off_vertices(const std::string& path, std::ifstream& in, const OffHeader& h,
                       WalkedMesh& walk) {
  const int coordinates = h.keyword.homogeneous ? 4 : 3;
  std::string line;
  long long v = 0;
  while (v < h.vertices && std::getline(in, line)) {
    line = clean_line(line);
    if (line.empty()) continue;
    const char* p = line.c_str();
    double x[4] = {0, 0, 0, 1};
    for (int c = 0; c < coordinates; ++c) {
      char* end = nullptr;
      x[c] = std::strtod(p, &end);
      if (end == p)
        fail(path, "vertex " + std::to_string(v) + ": cannot parse coordinates '" + line + "'");
      if (!std::isfinite(x[c]))
        fail(path, "vertex " + std::to_string(v) + " has a non-finite coordinate ('" + line + "')");
      p = end;
    }
    if (x[3] == 0.0)
      fail(path, "vertex " + std::to_string(v) +
                     " has homogeneous coordinate w = 0, a point at infinity ('" + line + "')");
    for (int c = 0; c < 3; ++c) {
      const double y = x[c] / x[3];  // exact when w = 1
      if (!std::isfinite(y))
        fail(path, "vertex " + std::to_string(v) + ": x/w overflows ('" + line + "')");
      walk.coords.push_back(y);
    }
    ++v;
  }
  if (v < h.vertices)
    fail(path, "file ends after " + std::to_string(v) + " of " + std::to_string(h.vertices) +
                   " vertices");
}

/// The face lines: a count of at least 3, then that many indices of existing vertices.
void read_off_faces(const std::string& path, std::ifstream& in, const OffHeader& h,
                    WalkedMesh& walk) {
  const long long nv = h.vertices;
  std::string line;
  long long f = 0;
  std::vector<int> corner;
  while (f < h.faces && std::getline(in, line)) {
    line = clean_line(line);
    if (line.empty()) continue;
    const char* p = line.c_str();
    char* end = nullptr;
    const long long k = std::strtoll(p, &end, 10);
    if (end == p || k < 3)
      fail(path, "face " + std::to_string(f) + ": bad vertex count in '" + line + "'");
    corner.clear();
    for (long long i = 0; i < k; ++i) {
      p = end;
      const long long idx = std::strtoll(p, &end, 10);
      if (end == p)
        fail(path, "face " + std::to_string(f) + ": expected " + std::to_string(k) +
                       " indices in '" + line + "'");
      if (idx < 0 || idx >= nv)
        fail(path, "face " + std::to_string(f) + " references vertex " + std::to_string(idx) +
                       " but the mesh has " + std::to_string(nv) + " vertices");
      corner.push_back(static_cast<int>(idx));
    }
    add_fan(walk, corner, f);
    ++f;
  }
  if (f < h.faces)
    fail(path,
         "file ends after " + std::to_string(f) + " of " + std::to_string(h.faces) + " faces");
}

// ASCII OFF: header counts, finite coordinates, index range; OpenMesh's reader is lenient about
// all of these. Returns false for binary OFF (walk_off_binary).
bool walk_off(const std::string& path, WalkedMesh& walk) {
  std::ifstream in(path);
  if (!in) fail(path, "cannot open file");
  OffHeader h;
  if (!read_off_header(path, in, h)) return false;
  check_int_range(path, h.vertices, "vertices");
  read_off_vertices(path, in, h, walk);
  read_off_faces(path, in, h, walk);
  return true;
}

/// The words of a binary OFF file after its header line, through a 1 MiB buffer; `at` is the
/// file offset of the next one.
class OffWords {
 public:
  OffWords(const std::string& path, std::ifstream& in, unsigned long long size,
           unsigned long long body)
      : path_(path), in_(in), size_(size), at_(body), buffer_(std::size_t(1) << 20) {}

  unsigned long long at() const { return at_; }

  /// The next word; fails naming `where` when the file ends.
  std::uint32_t word(const std::string& where) {
    if (next_ + 4 > filled_) {
      std::memmove(buffer_.data(), buffer_.data() + next_, filled_ - next_);
      filled_ -= next_;
      next_ = 0;
      in_.read(buffer_.data() + filled_, static_cast<std::streamsize>(buffer_.size() - filled_));
      filled_ += static_cast<std::size_t>(in_.gcount());
      if (filled_ < 4)
        fail(path_, "binary OFF ends at byte " + std::to_string(size_) + ", inside " + where);
    }
    std::uint32_t w;
    std::memcpy(&w, buffer_.data() + next_, 4);
    next_ += 4;
    at_ += 4;
    return w;
  }

 private:
  const std::string& path_;
  std::ifstream& in_;
  const unsigned long long size_;
  unsigned long long at_;
  std::vector<char> buffer_;
  std::size_t next_ = 0, filled_ = 0;
};

/// The header line, as OpenMesh's can_u_read parses it: prefixes in this order, "OFF", one
/// separator, "BINARY", the rest of the line ignored. Returns the words per vertex; `body` is
/// the offset of the first word.
std::size_t read_binary_off_header(const std::string& path, std::ifstream& in,
                                   unsigned long long& body) {
  std::string header;
  for (char c; in.get(c) && c != '\n';) {
    header += c;
    if (header.size() > 4096) fail(path, "binary OFF: no end to its header line in 4096 bytes");
  }
  if (!in) fail(path, "binary OFF: no end to its header line");
  std::size_t p = 0, vertex_words = 3;
  const auto prefix = [&](const char* letters, std::size_t words) {
    const std::size_t n = std::strlen(letters);
    if (header.compare(p, n, letters) != 0) return;
    p += n;
    vertex_words += words;
  };
  prefix("ST", 2);  // texture coordinate: 2 floats, after the colour
  prefix("C", 3);   // vertex colour: 3 ints (OpenMesh reads no face colour unless asked)
  prefix("N", 3);   // normal: 3 floats, after the point
  if (p < header.size() && (header[p] == '4' || header[p] == 'n'))
    fail(path,
         "binary OFF with other than 3 coordinates per vertex ('" + header + "') is not supported");
  if (header.size() < p + 10 || header.compare(p, 3, "OFF") != 0 ||
      header.compare(p + 4, 6, "BINARY") != 0)
    fail(path,
         "binary OFF header must be the first line, '[ST][C][N]OFF BINARY', not '" + header + "'");
  body = header.size() + 1;
  return vertex_words;
}

/// The least the counts need (a face is at least 4 words) against what the file holds, before
/// anything is allocated; a file that would fit read big-endian is said to be Geomview's.
void check_binary_off_counts(const std::string& path, std::uint32_t nv, std::uint32_t nf,
                             std::size_t vertex_words, unsigned long long bytes) {
  const unsigned long long need = 12 + 4ull * vertex_words * nv + 16ull * nf;
  if (need <= bytes) return;
  std::string why = "binary OFF announces " + std::to_string(nv) + " vertices and " +
                    std::to_string(nf) + " faces, at least " + std::to_string(need) +
                    " bytes, but has " + std::to_string(bytes) + " after its header line";
  const std::uint32_t snv = __builtin_bswap32(nv), snf = __builtin_bswap32(nf);
  const unsigned long long swapped_need = 12 + 4ull * vertex_words * snv + 16ull * snf;
  if (swapped_need <= bytes)
    why += "; read big-endian (Geomview's byte order) the counts would be " + std::to_string(snv) +
           " and " + std::to_string(snf) +
           ", but binary OFF is read here as OpenMesh reads and writes it, little-endian";
  fail(path, why);
}

/// One face record: k >= 3 corners, each an existing vertex.
void read_binary_off_face(const std::string& path, OffWords& words, std::uint32_t f,
                          std::uint32_t nv, unsigned long long size, std::vector<int>& corner) {
  const unsigned long long record = words.at();
  const std::string where = "face " + std::to_string(f);
  const std::uint32_t k = words.word(where);
  if (k < 3)
    fail(path, "face " + std::to_string(f) + " (byte " + std::to_string(record) + ") has " +
                   std::to_string(k) + " corners" +
                   (f > 0 && k <= 1 ? std::string(" (a Geomview colour count after face ") +
                                          std::to_string(f - 1) +
                                          "'s indices? OpenMesh's binary OFF, read here, has none)"
                                    : std::string()));
  if (4ull * k > size - words.at())
    fail(path, "face " + std::to_string(f) + " (byte " + std::to_string(record) + ") announces " +
                   std::to_string(k) + " corners, more than the rest of the file holds");
  corner.clear();
  for (std::uint32_t i = 0; i < k; ++i) {
    const std::uint32_t idx = words.word(where);
    if (idx >= nv)
      fail(path, "face " + std::to_string(f) + " (byte " + std::to_string(record) +
                     ") references vertex " + std::to_string(idx) + " but the mesh has " +
                     std::to_string(nv) + " vertices");
    corner.push_back(static_cast<int>(idx));
  }
}

// Binary OFF, in the layout OpenMesh's reader (OpenMesh 9, OFFReader.cc) reads and its writer
// writes: the first line "[ST][C][N]OFF BINARY", then 32-bit words in the machine's byte order
// (little-endian here; Geomview's spec says big-endian): nV nF nE, per vertex x y z as floats
// [normal: 3 floats] [colour: 3 ints] [texture: 2 floats], per face k and k vertex indices, and
// nothing after the last face (no per-face colour count, which Geomview writes after each face's
// indices). OpenMesh reads a file in another layout without a word: Geomview's colour count 0
// after a face is read as the next face's corner count, an empty face it skips, and that face's
// own record is lost (a tetrahedron so written loaded as 2 faces). So the file is walked here
// instead, every record checked, and errors name the vertex or face and its byte.
void walk_off_binary(const std::string& path, WalkedMesh& walk) {
  static_assert(std::endian::native == std::endian::little,
                "binary OFF is read as little-endian words");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open file");
  std::error_code ec;
  const unsigned long long size = fs::file_size(path, ec);
  if (ec) fail(path, "cannot read the file's size: " + ec.message());
  unsigned long long body = 0;
  const std::size_t vertex_words = read_binary_off_header(path, in, body);
  OffWords words(path, in, size, body);
  const std::uint32_t nv = words.word("its counts"), nf = words.word("its counts");
  words.word("its counts");  // edges, unused
  check_binary_off_counts(path, nv, nf, vertex_words, size - body);
  check_int_range(path, nv, "vertices");
  walk.coords.reserve(3ull * nv);
  for (std::uint32_t v = 0; v < nv; ++v) {
    const unsigned long long record = words.at();
    const std::string where = "vertex " + std::to_string(v);
    for (std::size_t w = 0; w < vertex_words; ++w) {
      const std::uint32_t bits = words.word(where);
      if (w >= 3) continue;  // normal, colour, texture coordinate: not kept
      const float x = std::bit_cast<float>(bits);
      if (!std::isfinite(x))
        fail(path, "vertex " + std::to_string(v) + " has a non-finite coordinate (byte " +
                       std::to_string(record) + ")");
      walk.coords.push_back(x);
    }
  }
  std::vector<int> corner;
  for (std::uint32_t f = 0; f < nf; ++f) {
    read_binary_off_face(path, words, f, nv, size, corner);
    add_fan(walk, corner, f);
  }
  if (words.at() != size)
    fail(path, std::to_string(size - words.at()) + " bytes after the last of its " +
                   std::to_string(nf) + " faces (byte " + std::to_string(words.at()) +
                   "): not the layout OpenMesh reads (per-face colours, or a wrong count?)");
}

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

// Face f's corners are vertices of the mesh, three different ones; else throws naming the face.
void check_corners(const std::string& path, const std::string& prefix, const TriangleMesh& mesh,
                   Eigen::Index f, const std::function<std::string(Eigen::Index)>& name_face,
                   const std::function<std::string(int)>& name_vertex) {
  const Eigen::Index nv = mesh.num_vertices();
  const int a = mesh.faces(f, 0), b = mesh.faces(f, 1), c = mesh.faces(f, 2);
  for (int v : {a, b, c})
    if (v < 0 || v >= nv)
      fail(path, prefix + name_face(f) + " references vertex " + std::to_string(v) +
                     " but the mesh has " + std::to_string(nv) + " vertices");
  // OpenMesh's add_face does not expect a repeated corner (its readers skip such faces).
  if (a == b || b == c || c == a)
    fail(path, prefix + name_face(f) + " repeats vertex " + name_vertex(a == b || a == c ? a : b) +
                   " (a degenerate face)");
}

// Orients the faces consistently (datasets/orientation.h) before the half-edge mesh is built, so
// that a manifold surface listed with mixed orientation loads; what cannot be oriented is an error
// naming the faces and the edge, and whether the mesh is non-manifold or non-orientable. Returns
// how many faces were reversed.
long long orient_or_fail(const std::string& path, TriangleMesh& mesh,
                         const std::function<std::string(Eigen::Index)>& name_face,
                         const std::function<std::string(int)>& name_vertex) {
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f)
    check_corners(path, "", mesh, f, name_face, name_vertex);
  const OrientationResult o = orient_faces(mesh.faces);
  auto face_with_corners = [&](Eigen::Index f) {
    return name_face(f) + " (vertices " + name_vertex(mesh.faces(f, 0)) + ", " +
           name_vertex(mesh.faces(f, 1)) + ", " + name_vertex(mesh.faces(f, 2)) + ")";
  };
  const std::string edge = "(" + name_vertex(o.edge[0]) + ", " + name_vertex(o.edge[1]) + ")";
  switch (o.problem) {
    case OrientationResult::Problem::none:
      return o.reoriented;
    case OrientationResult::Problem::non_manifold_edge:
      fail(path, "non-manifold mesh: " + face_with_corners(o.faces[2]) +
                     " cannot be added: its edge " + edge + " already has a face on each side (" +
                     name_face(o.faces[0]) + " and " + name_face(o.faces[1]) +
                     "): an edge in three or more faces is non-manifold");
    case OrientationResult::Problem::non_orientable:
      fail(path, "non-orientable mesh: " + face_with_corners(o.faces[1]) +
                     " cannot be oriented to agree with both its neighbours (reached across edge " +
                     edge + " from " + name_face(o.faces[0]) +
                     "): the surface is one-sided, like a Möbius strip, so no consistent "
                     "orientation of its faces exists");
  }
  return o.reoriented;
}

// Adds the faces to an OpenMesh half-edge mesh in order, as its readers do. A face it cannot add
// means a non-manifold ("complex") edge or vertex, or inconsistently oriented faces: the error
// names the first such face (name_face(f)) and why, after prefix. The half-edge mesh is
// returned for the STL writer.
IoMesh half_edge_mesh(const std::string& path, const std::string& prefix, const TriangleMesh& mesh,
                      const std::function<std::string(Eigen::Index)>& name_face,
                      const std::function<std::string(int)>& name_vertex) {
  const Eigen::Index nv = mesh.num_vertices(), nf = mesh.num_faces();
  IoMesh om;
  om.reserve(nv, nf + nv + 2, nf);  // edges: nf + nv - χ for a closed mesh
  std::vector<IoMesh::VertexHandle> vh(nv);
  for (Eigen::Index i = 0; i < nv; ++i)
    vh[i] =
        om.add_vertex(IoMesh::Point(mesh.vertices(i, 0), mesh.vertices(i, 1), mesh.vertices(i, 2)));
  for (Eigen::Index f = 0; f < nf; ++f) {
    check_corners(path, prefix, mesh, f, name_face, name_vertex);
    const int a = mesh.faces(f, 0), b = mesh.faces(f, 1), c = mesh.faces(f, 2);
    if (om.add_face(vh[a], vh[b], vh[c]).is_valid()) continue;
    // Why OpenMesh refused it, from the half-edge structure as it stood (a failed add_face
    // changes nothing).
    std::string why;
    const int corner[3] = {a, b, c};
    for (int j = 0; j < 3 && why.empty(); ++j) {
      const auto h = om.find_halfedge(vh[corner[j]], vh[corner[(j + 1) % 3]]);
      if (h.is_valid() && !om.is_boundary(h))
        why = "its edge (" + name_vertex(corner[j]) + ", " + name_vertex(corner[(j + 1) % 3]) +
              ") already has a face on the same side: the edge is in more than two faces, or the "
              "faces "
              "around it are inconsistently oriented";
    }
    for (int j = 0; j < 3 && why.empty(); ++j)
      if (!om.is_boundary(vh[corner[j]]))
        why = "its vertex " + name_vertex(corner[j]) +
              " is already surrounded by a closed fan of faces";
    if (why.empty())
      why = "its faces around a vertex cannot be ordered into one fan (a non-manifold vertex)";
    fail(path, prefix + "non-manifold mesh: " + name_face(f) + " (vertices " + name_vertex(a) +
                   ", " + name_vertex(b) + ", " + name_vertex(c) + ") cannot be added: " + why);
  }
  return om;
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

TriangleMesh read_mesh(const std::string& path, ReadReport* report) {
  if (report) *report = ReadReport{};
  silence_openmesh();
  std::error_code ec;
  if (!fs::exists(path, ec)) fail(path, "no such file");
  if (!fs::is_regular_file(path, ec)) fail(path, "not a regular file");
  if (fs::file_size(path, ec) == 0) fail(path, "empty file");

  const std::string ext = lower_extension(path);
  WalkedMesh walk;
  if (ext == ".off") {
    if (!walk_off(path, walk)) walk_off_binary(path, walk);
  } else if (ext == ".obj") {
    walk_obj(path, walk);
  } else if (ext == ".ply") {
    walk = scan_ply(path);  // a full walk of header and body (ply_format.cpp)
  } else if (ext == ".stl") {
    return read_stl_through_openmesh(path, scan_stl(path));
  } else {
    fail(path, "unknown mesh extension '" + ext + "' (supported: .off .ply .obj .stl)");
  }

  // One walk of the file gives the mesh; OpenMesh's half-edge insertion checks its topology.
  TriangleMesh mesh;
  const Eigen::Index nv = static_cast<Eigen::Index>(walk.coords.size() / 3);
  const Eigen::Index nt = static_cast<Eigen::Index>(walk.source.size());
  mesh.vertices = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      walk.coords.data(), nv, 3);
  std::vector<double>().swap(walk.coords);
  mesh.faces = Eigen::Map<const Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>>(
      walk.triangles.data(), nt, 3);
  std::vector<int>().swap(walk.triangles);
  auto name_face = [&](Eigen::Index t) {
    std::string face =
        (walk.source_is_line ? "the face on line " : "face ") + std::to_string(walk.source[t]);
    // A polygon's triangles share its name: say which one.
    Eigen::Index first = t, last = t;
    while (first > 0 && walk.source[first - 1] == walk.source[t]) --first;
    while (last + 1 < nt && walk.source[last + 1] == walk.source[t]) ++last;
    if (last == first) return face;
    return "triangle " + std::to_string(t - first + 1) + " of " + std::to_string(last - first + 1) +
           " fanned from " + face;
  };
  auto name_vertex = [&](int v) { return std::to_string(v + walk.index_base); };
  const long long reoriented = orient_or_fail(path, mesh, name_face, name_vertex);
  if (report) report->reoriented_faces = reoriented;
  half_edge_mesh(path, "", mesh, name_face, name_vertex);
  return mesh;
}

namespace {

// half_edge_mesh for a mesh in memory: faces and vertices named by their 0-based indices.
IoMesh half_edge_mesh_in_memory(const std::string& name, const std::string& prefix,
                                const TriangleMesh& mesh) {
  return half_edge_mesh(
      name, prefix, mesh, [](Eigen::Index f) { return "face " + std::to_string(f); },
      [](int v) { return std::to_string(v); });
}

}  // namespace

void check_half_edge_faces(const TriangleMesh& mesh, const std::string& name) {
  half_edge_mesh_in_memory(name, "", mesh);
}

namespace {

// OFF, OBJ and PLY are written here rather than by OpenMesh, whose writers round coordinates to
// float: with 17 significant digits a text file reproduces every double, and binary PLY stores
// doubles. An ASCII PLY body is line for line an OFF body; only their headers differ.
/// Returns 0, or the errno of the first call that failed (EIO if it set none).
int write_exact(const fs::path& file, const TriangleMesh& mesh, const std::string& ext,
                bool binary) {
  errno = 0;
  std::FILE* out = std::fopen(file.c_str(), "wb");
  if (!out) return errno != 0 ? errno : EIO;
  std::vector<char> buffer(1 << 20);
  std::setvbuf(out, buffer.data(), _IOFBF, buffer.size());
  const bool obj = ext == ".obj";
  const long long nv = mesh.num_vertices(), nf = mesh.num_faces();
  if (ext == ".ply")
    std::fputs(ply_header(mesh, binary).c_str(), out);
  else if (obj)
    std::fprintf(out, "# %lld vertices, %lld faces\n", nv, nf);
  else
    std::fprintf(out, "OFF\n%lld %lld 0\n", nv, nf);
  if (ext == ".ply" && binary) {
    write_ply_binary_body(out, mesh);
  } else {
    for (Eigen::Index v = 0; v < nv; ++v)
      std::fprintf(out, obj ? "v %.17g %.17g %.17g\n" : "%.17g %.17g %.17g\n", mesh.vertices(v, 0),
                   mesh.vertices(v, 1), mesh.vertices(v, 2));
    for (Eigen::Index f = 0; f < nf; ++f) {
      if (obj)
        std::fprintf(out, "f %d %d %d\n", mesh.faces(f, 0) + 1, mesh.faces(f, 1) + 1,
                     mesh.faces(f, 2) + 1);
      else
        std::fprintf(out, "3 %d %d %d\n", mesh.faces(f, 0), mesh.faces(f, 1), mesh.faces(f, 2));
    }
  }
  // A failed write leaves its errno (and later writes to the full or read-only file system the
  // same one); fclose reports a failure of its final flush.
  const int write_errno = std::ferror(out) ? (errno != 0 ? errno : EIO) : 0;
  errno = 0;
  const int close_errno = std::fclose(out) == 0 ? 0 : (errno != 0 ? errno : EIO);
  return write_errno != 0 ? write_errno : close_errno;
}

}  // namespace

void write_mesh(const std::string& path, const TriangleMesh& mesh, bool binary, FaceCheck check) {
  silence_openmesh();
  const std::string ext = lower_extension(path);
  if (ext != ".off" && ext != ".ply" && ext != ".obj" && ext != ".stl")
    fail(path, "unknown mesh extension '" + ext + "' (supported: .off .ply .obj .stl)");

  // Writing a mesh that OpenMesh cannot represent would silently drop faces in an STL file, and
  // our own writers would write a file that no reader here accepts. The STL writer needs the
  // half-edge mesh whatever the caller vouches for.
  const IoMesh om = check == FaceCheck::half_edge || ext == ".stl"
                        ? half_edge_mesh_in_memory(path, "cannot write: ", mesh)
                        : IoMesh();

  // OpenMesh writes STL only (write_exact the rest). OFF has a binary variant, but few readers
  // besides OpenMesh accept it: OFF stays ASCII.
  OpenMesh::IO::Options opt;
  if (binary) opt += OpenMesh::IO::Options::Binary;

  // Temporary name in the same folder (rename is atomic only within a file system), keeping the
  // extension because OpenMesh chooses the writer from it.
  static std::atomic<unsigned> counter{0};
  fs::path target(path);
  fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  fs::path tmp = dir / ("." + target.stem().string() + ".tmp" + std::to_string(::getpid()) + "_" +
                        std::to_string(counter++) + target.extension().string());
  const int error = ext == ".stl" ? (OpenMesh::IO::write_mesh(om, tmp.string(), opt, 17) ? 0 : -1)
                                  : write_exact(tmp, mesh, ext, binary);
  if (error != 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    fail(path, error > 0 ? std::string("could not write the file: ") + std::strerror(error)
                         : "could not write the file (folder missing or not writable?)");
  }
  try {
    publish_durably(tmp, target);  // a frame or final.ply survives a crash of the machine too
  } catch (const std::runtime_error& e) {
    throw MeshError(e.what());
  }
}

}  // namespace mcf
