#pragma once
// One table of named rows per extension axis (solvers, preconditioners, bases, flows): the row
// holds everything the harness knows about a name, so nothing else compares the name with a
// literal (docs/extending.md). In the style of AMGCL's runtime selection and of the mesh
// generators' table in datasets/mesh_spec.cpp.
//
// Rows are kept in registration order, which is the order of every list printed from them
// (allowed values in error messages, --help, docs/flow.md). The table lives in a function-local
// static, so a row registered from another translation unit's static initializer (examples/)
// finds it constructed.

#include <deque>
#include <stdexcept>
#include <string>
#include <vector>

namespace mcf {

template <class Row>
class NamedTable {
 public:
  /// `axis` names the table in messages ("solver", "basis").
  explicit NamedTable(std::string axis) : axis_(std::move(axis)) {}

  /// Adds a row. Throws std::logic_error for an empty or repeated name: a registration bug,
  /// found when the program starts.
  const Row& add(Row row) {
    if (row.name.empty()) throw std::logic_error(axis_ + " registered without a name");
    if (find(row.name)) throw std::logic_error(axis_ + " \"" + row.name + "\" registered twice");
    rows_.push_back(std::move(row));
    return rows_.back();
  }
  /// The row called `name`, or nullptr.
  const Row* find(const std::string& name) const {
    for (const Row& r : rows_)
      if (r.name == name) return &r;
    return nullptr;
  }
  /// The row called `name`; throws std::invalid_argument ("unknown solver \"x\"") otherwise.
  const Row& at(const std::string& name) const {
    if (const Row* r = find(name)) return *r;
    throw std::invalid_argument("unknown " + axis_ + " \"" + name + "\"");
  }
  /// The rows' names, in registration order.
  std::vector<std::string> names() const {
    std::vector<std::string> n;
    for (const Row& r : rows_) n.push_back(r.name);
    return n;
  }
  const std::deque<Row>& rows() const { return rows_; }

 private:
  std::string axis_;
  std::deque<Row> rows_;  // a deque: references to rows stay valid as rows are added
};

}  // namespace mcf
