// PLY read and written in double precision (ply_format.h). The format: Paul Bourke's description
// of Greg Turk's PLY ("PLY - Polygon File Format"): a text header of `element NAME COUNT` lines,
// each followed by its `property TYPE NAME` / `property list COUNT_TYPE ITEM_TYPE NAME` lines,
// then the records of every element in header order, as whitespace-separated text (ascii) or
// packed values (binary_little_endian, binary_big_endian).

#include "datasets/ply_format.h"

#include "datasets/mesh_error.h"

#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace mcf {
namespace {

enum class Encoding { Ascii, LittleEndian, BigEndian };

// The scalar types, both spellings of the format: the original (char, uchar, ...) and the sized
// one (int8, uint8, ...). Resolved once from the header, so the body's values switch on an enum.
enum class Scalar : unsigned char {
  Int8,
  UInt8,
  Int16,
  UInt16,
  Int32,
  UInt32,
  Float32,
  Float64,
  None
};

Scalar scalar_type(const std::string& t) {
  if (t == "char" || t == "int8") return Scalar::Int8;
  if (t == "uchar" || t == "uint8") return Scalar::UInt8;
  if (t == "short" || t == "int16") return Scalar::Int16;
  if (t == "ushort" || t == "uint16") return Scalar::UInt16;
  if (t == "int" || t == "int32") return Scalar::Int32;
  if (t == "uint" || t == "uint32") return Scalar::UInt32;
  if (t == "float" || t == "float32") return Scalar::Float32;
  if (t == "double" || t == "float64") return Scalar::Float64;
  return Scalar::None;
}

int scalar_size(Scalar t) {
  switch (t) {
    case Scalar::Int8:
    case Scalar::UInt8:
      return 1;
    case Scalar::Int16:
    case Scalar::UInt16:
      return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32:
      return 4;
    case Scalar::Float64:
      return 8;
    case Scalar::None:
      break;
  }
  return 0;
}

struct Property {
  std::string name;
  Scalar type = Scalar::None;        // the item type of a list
  Scalar count_type = Scalar::None;  // None: a scalar property
  bool is_list() const { return count_type != Scalar::None; }
};

struct Element {
  std::string name;
  long long count = 0;
  std::vector<Property> properties;
};

struct Header {
  Encoding encoding = Encoding::Ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0;  // first byte after the end_header line
  long long body_line = 1;      // line number of the body's first line (ASCII)
};

Header parse_header(const std::string& path, const std::string& data) {
  auto fail = [&](long long line, const std::string& problem) -> void {
    throw MeshError(path + ": line " + std::to_string(line) + ": " + problem);
  };
  Header h;
  bool have_format = false;
  std::size_t pos = 0;
  long long line_number = 0;
  while (true) {
    if (pos >= data.size()) fail(line_number, "the header has no end_header line");
    const std::size_t eol = data.find('\n', pos);
    // Words are read with >>, which skips blanks and the '\r' of a CRLF file.
    const std::string line =
        data.substr(pos, eol == std::string::npos ? std::string::npos : eol - pos);
    pos = eol == std::string::npos ? data.size() : eol + 1;
    ++line_number;
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (line_number == 1) {
      if (word != "ply") throw MeshError(path + ": not a PLY file (no 'ply' magic)");
      continue;
    }
    if (word.empty() || word == "comment" || word == "obj_info") continue;
    if (word == "end_header") {
      if (!have_format) fail(line_number, "the header has no format line");
      // Records of an element without properties hold nothing, so nothing bounds their count:
      // reading 1e16 of them would never end. No writer produces such an element.
      for (const Element& e : h.elements)
        if (e.count > 0 && e.properties.empty())
          fail(line_number, "element '" + e.name + "' has " + std::to_string(e.count) +
                                " records but no properties");
      h.body_offset = pos;
      h.body_line = line_number + 1;
      return h;
    }
    if (word == "format") {
      std::string encoding, version;
      ls >> encoding >> version;
      if (encoding == "ascii")
        h.encoding = Encoding::Ascii;
      else if (encoding == "binary_little_endian")
        h.encoding = Encoding::LittleEndian;
      else if (encoding == "binary_big_endian")
        h.encoding = Encoding::BigEndian;
      else
        fail(line_number,
             "unknown format '" + encoding + "' (ascii, binary_little_endian, binary_big_endian)");
      have_format = true;
    } else if (word == "element") {
      Element e;
      if (!(ls >> e.name >> e.count) || e.count < 0)
        fail(line_number, "bad element line '" + line + "'");
      h.elements.push_back(e);
    } else if (word == "property") {
      if (h.elements.empty()) fail(line_number, "property before any element");
      Property p;
      std::string first, count_type, type;
      ls >> first;
      const bool list = first == "list";
      if (list)
        ls >> count_type >> type >> p.name;
      else {
        type = first;
        ls >> p.name;
      }
      if (p.name.empty()) fail(line_number, "bad property line '" + line + "'");
      for (const std::string* t : {&type, &count_type})
        if ((t == &type || list) && scalar_type(*t) == Scalar::None)
          fail(line_number, "unknown property type '" + *t + "'");
      p.type = scalar_type(type);
      p.count_type = list ? scalar_type(count_type) : Scalar::None;
      h.elements.back().properties.push_back(p);
    } else {
      fail(line_number, "unknown header keyword '" + word + "'");
    }
  }
}

// Reads the body value by value, in either encoding, knowing where it is for error messages.
class BodyReader {
 public:
  BodyReader(const std::string& path, const std::string& data, const Header& h)
      : path_(path),
        data_(data),
        encoding_(h.encoding),
        pos_(h.body_offset),
        line_(h.body_line),
        swap_(h.encoding != Encoding::Ascii && (h.encoding == Encoding::LittleEndian) !=
                                                   (std::endian::native == std::endian::little)) {}

  /// What the next values are, for error messages only (composed by what(), on failure).
  enum class Part { value, list_length, corner };

  /// The next value, converted to double (exact for every PLY type).
  double next(Scalar type) {
    if (encoding_ == Encoding::Ascii) return next_text(/*integer=*/false);
    return next_binary(type);
  }
  /// The next value, which must be an integer (list counts, vertex indices).
  long long next_integer(Scalar type, Part part, long long corner = -1) {
    part_ = part;
    corner_ = corner;
    const double v = encoding_ == Encoding::Ascii ? next_text(/*integer=*/true) : next_binary(type);
    if (encoding_ != Encoding::Ascii && v != std::floor(v))
      fail(what() + " is not an integer (" + std::to_string(v) + ")");
    // A float property can hold any magnitude (and infinity); converting one beyond long long's
    // range is undefined, so it is refused here (every valid count and index is far below 2^62).
    if (!(std::fabs(v) < 0x1p62)) fail(what() + " is out of range (" + std::to_string(v) + ")");
    part_ = Part::value;
    return static_cast<long long>(v);
  }
  /// ASCII records are one line each (every writer does so); checking it turns a missing or extra
  /// value into an error on its own line rather than a misread of every record after it.
  void start_record(const Element& element, long long index) {
    element_ = &element;
    index_ = index;
    record_values_ = 0;
  }
  /// "face 2 of 4", the record being read.
  std::string record() const {
    return element_->name + " " + std::to_string(index_) + " of " + std::to_string(element_->count);
  }
  void end_record() {
    if (encoding_ != Encoding::Ascii || record_values_ == 0) return;
    std::size_t p = pos_;
    while (p < data_.size() && data_[p] != '\n' &&
           std::isspace(static_cast<unsigned char>(data_[p])))
      ++p;
    if (p < data_.size() && data_[p] != '\n')
      throw MeshError(path_ + ": line " + std::to_string(line_) + ": " + record() +
                      " has more values than its " + std::to_string(record_values_) +
                      " declared in the header");
  }
  /// "line 12" (ASCII) or "byte 4711" (binary): where the last value read began.
  std::string where() const {
    return encoding_ == Encoding::Ascii ? "line " + std::to_string(token_line_)
                                        : "byte " + std::to_string(token_pos_);
  }
  [[noreturn]] void fail(const std::string& problem) const {
    throw MeshError(path_ + ": " + where() + ": " + problem);
  }
  [[noreturn]] void fail_at_end() const {
    throw MeshError(path_ + ": the file ends at " +
                    (encoding_ == Encoding::Ascii ? "line " + std::to_string(line_)
                                                  : "byte " + std::to_string(data_.size())) +
                    " before " + record() + " is complete");
  }

 private:
  // "face 1 corner 2", "face 1 of 4 (list length)" or "face 1 of 4".
  std::string what() const {
    if (part_ == Part::corner)
      return element_->name + " " + std::to_string(index_) + " corner " + std::to_string(corner_);
    return record() + (part_ == Part::list_length ? " (list length)" : "");
  }

  double next_text(bool integer) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) {
      if (data_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= data_.size()) fail_at_end();
    if (record_values_ > 0 && line_ != token_line_)
      throw MeshError(path_ + ": line " + std::to_string(token_line_) + ": " + record() +
                      " ends after " + std::to_string(record_values_) +
                      " values (the header declares more)");
    ++record_values_;
    token_line_ = line_;
    token_pos_ = pos_;
    std::size_t stop = pos_;
    while (stop < data_.size() && !std::isspace(static_cast<unsigned char>(data_[stop]))) ++stop;
    // Parsed in place: data_ is a std::string, so the text ends in '\0' and the parse stops at the
    // blank after the token at the latest; the token is copied only for an error message.
    const char* first = data_.c_str() + pos_;
    const char* last = data_.c_str() + stop;
    pos_ = stop;
    char* end = nullptr;
    const double v =
        integer ? static_cast<double>(std::strtoll(first, &end, 10)) : std::strtod(first, &end);
    if (end != last)
      fail(what() + ": '" + std::string(first, last) +
           (integer ? "' is not an integer" : "' cannot be parsed as a number"));
    return v;
  }

  double next_binary(Scalar type) {
    const int size = scalar_size(type);
    if (pos_ + size > data_.size()) fail_at_end();
    token_pos_ = pos_;
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, size);
    pos_ += size;
    if (swap_)
      for (int i = 0; i < size / 2; ++i) std::swap(b[i], b[size - 1 - i]);
    auto as = [&b]<typename T>(T) {
      T v;
      std::memcpy(&v, b, sizeof v);
      return static_cast<double>(v);
    };
    switch (type) {
      case Scalar::Int8:
        return as(std::int8_t{});
      case Scalar::UInt8:
        return as(std::uint8_t{});
      case Scalar::Int16:
        return as(std::int16_t{});
      case Scalar::UInt16:
        return as(std::uint16_t{});
      case Scalar::Int32:
        return as(std::int32_t{});
      case Scalar::UInt32:
        return as(std::uint32_t{});
      case Scalar::Float32:
        return as(float{});
      case Scalar::Float64:
        return as(double{});
      case Scalar::None:
        break;
    }
    return 0.0;  // not reached: the header admits known types only
  }

  const std::string& path_;
  const std::string& data_;
  Encoding encoding_;
  std::size_t pos_;
  long long line_;
  bool swap_;  // binary body in the other byte order than this machine's
  long long token_line_ = 0;
  const Element* element_ = nullptr;
  long long index_ = 0;
  Part part_ = Part::value;
  long long corner_ = -1;
  int record_values_ = 0;
  std::size_t token_pos_ = 0;
};

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw MeshError(path + ": cannot open file");
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// The vertex element and the property index of its x, y and z (`axis_of`); its count is
/// checked against the body's size (every value takes at least one byte, a digit or a binary
/// char, so a count beyond that is a broken header) before the coordinates are allocated.
const Element& vertex_element(const std::string& path, const Header& header, std::size_t file_size,
                              int axis_of[3]) {
  const Element* vertex = nullptr;
  for (const Element& e : header.elements)
    if (e.name == "vertex") vertex = &e;
  if (!vertex) throw MeshError(path + ": the header declares no vertex element");
  for (std::size_t i = 0; i < vertex->properties.size(); ++i) {
    const Property& p = vertex->properties[i];
    for (int c = 0; c < 3; ++c)
      if (p.name == std::string(1, char('x' + c)) && !p.is_list()) axis_of[c] = static_cast<int>(i);
  }
  for (int c = 0; c < 3; ++c)
    if (axis_of[c] < 0)
      throw MeshError(path + ": the vertex element has no scalar property '" +
                      std::string(1, char('x' + c)) + "'");
  if (static_cast<double>(vertex->count) * vertex->properties.size() >
      static_cast<double>(file_size - header.body_offset))
    throw MeshError(path + ": the header declares " + std::to_string(vertex->count) +
                    " vertices, more than the file's body can hold");
  if (vertex->count > std::numeric_limits<int>::max())
    throw MeshError(path + ": the header declares " + std::to_string(vertex->count) +
                    " vertices, more than a mesh's int indices can address");
  return *vertex;
}

/// The face element's corner list (found once: names are not compared per record); -1 for
/// another element.
int corner_list_of(const std::string& path, const Element& e) {
  int corner_list = -1;
  if (e.name == "face")
    for (std::size_t i = 0; i < e.properties.size(); ++i)
      if (e.properties[i].is_list() &&
          (e.properties[i].name == "vertex_indices" || e.properties[i].name == "vertex_index"))
        corner_list = static_cast<int>(i);
  if (e.name == "face" && corner_list < 0 && e.count > 0)
    throw MeshError(path + ": the face element has no list property 'vertex_indices'");
  return corner_list;
}

/// One list property of record `r`; a face's corner list (`corners`) is fan-triangulated into
/// `out`, any other list skipped.
void read_list(BodyReader& body, const Property& p, long long r, bool corners,
               long long vertex_count, std::vector<int>& corner, WalkedMesh& out) {
  const long long k = body.next_integer(p.count_type, BodyReader::Part::list_length);
  if (k < 0) body.fail(body.record() + ": negative list length " + std::to_string(k));
  if (corners && k < 3)
    body.fail("face " + std::to_string(r) + " has " + std::to_string(k) + " corners (at least 3)");
  corner.clear();
  for (long long j = 0; j < k; ++j) {
    if (!corners) {
      body.next(p.type);
      continue;
    }
    const long long index = body.next_integer(p.type, BodyReader::Part::corner, j);
    if (index < 0 || index >= vertex_count)
      body.fail("face " + std::to_string(r) + " references vertex " + std::to_string(index) +
                " but the mesh has " + std::to_string(vertex_count) + " vertices");
    corner.push_back(static_cast<int>(index));
  }
  if (!corners) return;
  if (out.source.size() + (k - 2) > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    body.fail("more triangles than a mesh's int indices can address");
  add_fan(out, corner, r);
}

}  // namespace

WalkedMesh scan_ply(const std::string& path) {
  const std::string data = read_file(path);
  const Header header = parse_header(path, data);
  int axis_of[3] = {-1, -1, -1};  // property index of x, y, z
  const Element& vertex = vertex_element(path, header, data.size(), axis_of);
  WalkedMesh out;
  out.coords.resize(3 * static_cast<std::size_t>(vertex.count));
  std::vector<int> corner;  // one face's corners, fan-triangulated once the face is read
  BodyReader body(path, data, header);
  for (const Element& e : header.elements) {
    const bool is_vertex = &e == &vertex;
    const int corner_list = corner_list_of(path, e);
    for (long long r = 0; r < e.count; ++r) {
      body.start_record(e, r);
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const Property& p = e.properties[i];
        if (p.is_list()) {
          read_list(body, p, r, static_cast<int>(i) == corner_list, vertex.count, corner, out);
          continue;
        }
        const double v = body.next(p.type);
        if (is_vertex)
          for (int c = 0; c < 3; ++c)
            if (axis_of[c] == static_cast<int>(i)) {
              if (!std::isfinite(v))
                body.fail("vertex " + std::to_string(r) + " has a non-finite coordinate " + p.name);
              out.coords[3 * r + c] = v;
            }
      }
      body.end_record();
    }
  }
  return out;
}

std::string ply_header(const TriangleMesh& mesh, bool binary) {
  return std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") +
         " 1.0\ncomment mcfbench: double-precision coordinates\nelement vertex " +
         std::to_string(mesh.num_vertices()) +
         "\nproperty double x\nproperty double y\nproperty double z\nelement face " +
         std::to_string(mesh.num_faces()) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
}

void write_ply_binary_body(std::FILE* out, const TriangleMesh& mesh) {
  // Little-endian bytes of a value whatever the host's order.
  auto put = [out]<typename T>(T value) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big)
      for (std::size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(b[i], b[sizeof(T) - 1 - i]);
    std::fwrite(b, 1, sizeof(T), out);
  };
  for (Eigen::Index v = 0; v < mesh.num_vertices(); ++v)
    for (int c = 0; c < 3; ++c) put(mesh.vertices(v, c));
  for (Eigen::Index f = 0; f < mesh.num_faces(); ++f) {
    put(std::uint8_t{3});
    for (int c = 0; c < 3; ++c) put(std::int32_t{mesh.faces(f, c)});
  }
}

}  // namespace mcf
