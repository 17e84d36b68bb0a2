#pragma once
// The values that cross mcfbench's public API: Eigen matrices, option values, and the error bad
// input raises (docs/library.md).
//
// The dense matrices are DontAlign: their storage is plain malloc'ed and read without alignment
// assumptions, so a program compiled with other vectorization flags than the library (which is
// built with -march=native) can create, pass and free them. Eigen's aligned types are not
// compatible between such builds.

#include "mcfbench/export.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace mcfbench {

/// Vertex positions, one row per vertex (n x 3), in the mesh's own units.
using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::ColMajor | Eigen::DontAlign>;
/// Triangles, one row per face (m x 3): 0-based vertex indices, counter-clockwise seen from
/// outside.
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::ColMajor | Eigen::DontAlign>;
/// Dense blocks: coefficients, right-hand sides, solutions (n x k, column-major).
using DenseMatrix =
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor | Eigen::DontAlign>;
/// Compressed sparse columns with int indices; the symmetric matrices (M, K, a M + b K) store
/// both triangles, so the same arrays also read as compressed sparse rows.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;
/// A read-only view of vertex positions the library owns (valid during the call that gives it).
using VerticesView = Eigen::Map<const Vertices>;

/// One option's value: what a flag of `mcfbench flow` or a key of a flow config takes.
struct Value {
  std::variant<bool, long long, double, std::string> value;
  Value(bool b) : value(b) {}
  Value(int i) : value(static_cast<long long>(i)) {}
  Value(long i) : value(static_cast<long long>(i)) {}
  Value(long long i) : value(i) {}
  Value(double x) : value(x) {}
  Value(const char* s) : value(std::string(s)) {}
  Value(std::string s) : value(std::move(s)) {}
};

/// The options of a flow, and of everything built from one (a mesh as a flow loads it, a basis,
/// a solver): the flow config's schema reads them, the one that `mcfbench flow`'s flags and
/// experiment configs go through, so the same keys, values and checks apply
/// (docs/flow.md#flow lists them).
struct Options {
  /// A flow config to start from, as JSON text (an object with the keys of result.json's
  /// "config", as `mcfbench flow --config FILE` reads it); empty: none.
  std::string config_json;
  /// The same from a JSON file (read first; config_json, if also given, is refused).
  std::string config_file;
  /// Set on top of it, in order. A key is a flag of `mcfbench flow` without its dashes ("dt",
  /// "cycles", "normalize-area"; '_' may stand for '-'), or a dotted config key
  /// ("solver.cycles"). A flag that takes no value on the command line ("normalize-area",
  /// "frozen") takes true or false here.
  std::vector<std::pair<std::string, Value>> settings;
  /// The memory budget a flow's estimated peak is checked against before it starts: "" = the
  /// memory available now, "none" = no check, or a size ("8G", "512M").
  std::string max_memory;
  /// flow(): show `mcfbench flow`'s progress line and the mesh's loading notes on stderr.
  bool progress = false;
  /// What error messages call these options ("options: solver.cycles: ...").
  std::string name = "options";

  Options& set(std::string key, Value value) {
    settings.emplace_back(std::move(key), std::move(value));
    return *this;
  }
};

/// Bad input: an unknown or out-of-range option, a config that contradicts itself, a mesh spec,
/// file or arrays that cannot be used, a missing file. what() names the option, key, file or
/// face, as `mcfbench` does before it runs anything. Other failures (a file that cannot be
/// written, a flow whose memory estimate does not fit) are std::runtime_error.
class MCFBENCH_API InputError : public std::invalid_argument {
 public:
  explicit InputError(const std::string& what);
  ~InputError() override;
};

}  // namespace mcfbench
