#include "datasets/off_format.h"

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

namespace fs = std::filesystem;
using namespace walk_detail;

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

}  // namespace

WalkedMesh scan_off(const std::string& path) {
  WalkedMesh walk;
  if (!walk_off(path, walk)) walk_off_binary(path, walk);
  return walk;
}

}  // namespace mcf
