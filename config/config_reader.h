#pragma once
// Strict reading of JSON configs: every error names the source file and the dotted key path
// ("demo.json: solver.cycles: expected an integer >= 1, got \"two\""), and keys nobody read
// are reported as unknown — a typo never silently falls back to a default.

#include <nlohmann/json.hpp>

#include <functional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace mcf {

struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Reads a JSON config file strictly: a file that cannot be opened, a syntax error (with line
/// and column), a number out of double range ("dt": 1e400) and a key given twice in one object
/// (JSON would silently keep the last) all throw ConfigError naming `path`.
nlohmann::json read_config_file(const std::string& path);

class ConfigReader {
 public:
  /// `source` names the file (or "command line"); `prefix` is the dotted path of this object.
  ConfigReader(const nlohmann::json& object, std::string source, std::string prefix = "");

  std::string path(const std::string& key) const {
    return prefix_.empty() ? key : prefix_ + "." + key;
  }
  bool has(const std::string& key) const { return object_.contains(key); }

  std::string get_string(const std::string& key, const std::string& fallback,
                         const std::vector<std::string>& allowed = {});
  double get_number(const std::string& key, double fallback, double min, double max);
  long long get_integer(const std::string& key, long long fallback, long long min, long long max);
  bool get_bool(const std::string& key, bool fallback);
  /// A nested object (empty if absent); the returned reader must be finish()ed too.
  ConfigReader child(const std::string& key);

  /// Throws for the first key present but never read.
  void finish() const;

  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  const nlohmann::json& object_;
  std::string source_, prefix_;
  std::set<std::string> read_;
  static const nlohmann::json& empty_object();
};

}  // namespace mcf
