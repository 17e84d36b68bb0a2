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
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace mcf {

template <class Row>
class NamedTable {
 public:
  /// `axis` names the table in messages ("solver", "basis"); `check` throws std::logic_error for
  /// a row that lacks what the axis requires (a factory, a memory model).
  explicit NamedTable(std::string axis, std::function<void(const Row&)> check = {})
      : axis_(std::move(axis)), check_(std::move(check)) {}

  /// Adds a row. Throws std::logic_error for an empty or repeated name or a row `check` refuses:
  /// a registration bug, found when the program starts.
  const Row& add(Row row) {
    if (row.name.empty()) throw std::logic_error(axis_ + " registered without a name");
    if (check_) check_(row);
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
  /// Each row's name and help, in registration order (an option's allowed values).
  std::vector<std::pair<std::string, std::string>> choices() const {
    std::vector<std::pair<std::string, std::string>> c;
    for (const Row& r : rows_) c.emplace_back(r.name, r.help);
    return c;
  }
  const std::deque<Row>& rows() const { return rows_; }

 private:
  std::string axis_;
  std::function<void(const Row&)> check_;
  std::deque<Row> rows_;  // a deque: references to rows stay valid as rows are added
};

}  // namespace mcf
