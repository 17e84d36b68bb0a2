#include "config/config_reader.h"

#include <cmath>
#include <fstream>
#include <sstream>

namespace mcf {

nlohmann::json read_config_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path + ": cannot open config file");
  // nlohmann keeps the last of two equal keys without a word, and its number-overflow error names
  // no key: follow the open objects and arrays to name the dotted path ("axes.dt[]") either way.
  struct Level {
    bool array = false;
    std::string key;  // the object's current key
    std::set<std::string> keys;
  };
  std::vector<Level> open;
  auto dotted = [&open] {
    std::string p;
    for (const Level& l : open) {
      if (l.array)
        p += "[]";
      else if (!l.key.empty())
        p += (p.empty() ? "" : ".") + l.key;
    }
    return p;
  };
  std::string duplicate;
  const nlohmann::json::parser_callback_t track = [&](int, nlohmann::json::parse_event_t event,
                                                      nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    if (event == E::object_start || event == E::array_start) {
      open.push_back(Level{event == E::array_start, "", {}});
    } else if (event == E::object_end || event == E::array_end) {
      if (!open.empty()) open.pop_back();
    } else if (event == E::key && !open.empty()) {
      open.back().key = parsed.get<std::string>();
      if (!open.back().keys.insert(open.back().key).second && duplicate.empty())
        duplicate = dotted();
    }
    return true;
  };
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in, track);
  } catch (const nlohmann::json::parse_error& e) {
    throw ConfigError(path + ": JSON parse error: " + e.what());
  } catch (const nlohmann::json::exception& e) {  // out_of_range.406: a number beyond double range
    throw ConfigError(path + ": " + (open.empty() ? std::string() : dotted() + ": ") + e.what());
  }
  if (!duplicate.empty())
    throw ConfigError(path + ": " + duplicate +
                      ": key appears twice in one object (JSON would keep the last)");
  return j;
}

const nlohmann::json& ConfigReader::empty_object() {
  static const nlohmann::json e = nlohmann::json::object();
  return e;
}

ConfigReader::ConfigReader(const nlohmann::json& object, std::string source, std::string prefix)
    : object_(object.is_null() ? empty_object() : object),
      source_(std::move(source)),
      prefix_(std::move(prefix)) {
  if (!object_.is_object())
    throw ConfigError(source_ + ": " + (prefix_.empty() ? std::string("config") : prefix_) +
                      ": expected an object, got " + object_.dump());
}

void ConfigReader::fail(const std::string& key, const std::string& what) const {
  throw ConfigError(source_ + ": " + path(key) + ": " + what);
}

std::string ConfigReader::get_string(const std::string& key, const std::string& fallback,
                                     const std::vector<std::string>& allowed) {
  read_.insert(key);
  if (!object_.contains(key)) return fallback;
  const auto& v = object_.at(key);
  if (!v.is_string()) fail(key, "expected a string, got " + v.dump());
  const std::string s = v.get<std::string>();
  if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), s) == allowed.end()) {
    std::ostringstream msg;
    msg << "unknown value \"" << s << "\" (one of:";
    for (const auto& a : allowed) msg << ' ' << a;
    msg << ")";
    fail(key, msg.str());
  }
  return s;
}

double ConfigReader::get_number(const std::string& key, double fallback, double min, double max) {
  read_.insert(key);
  if (!object_.contains(key)) return fallback;
  const auto& v = object_.at(key);
  if (!v.is_number()) fail(key, "expected a number, got " + v.dump());
  const double d = v.get<double>();
  if (!std::isfinite(d) || d < min || d > max) {
    std::ostringstream msg;
    msg << "value " << d << " out of range [" << min << ", " << max << "]";
    fail(key, msg.str());
  }
  return d;
}

long long ConfigReader::get_integer(const std::string& key, long long fallback, long long min,
                                    long long max) {
  read_.insert(key);
  if (!object_.contains(key)) return fallback;
  const auto& v = object_.at(key);
  if (!v.is_number_integer()) fail(key, "expected an integer, got " + v.dump());
  const long long i = v.get<long long>();
  if (i < min || i > max)
    fail(key, "value " + std::to_string(i) + " out of range [" + std::to_string(min) + ", " +
                  std::to_string(max) + "]");
  return i;
}

bool ConfigReader::get_bool(const std::string& key, bool fallback) {
  read_.insert(key);
  if (!object_.contains(key)) return fallback;
  const auto& v = object_.at(key);
  if (!v.is_boolean()) fail(key, "expected true or false, got " + v.dump());
  return v.get<bool>();
}

ConfigReader ConfigReader::child(const std::string& key) {
  read_.insert(key);
  if (!object_.contains(key)) return ConfigReader(empty_object(), source_, path(key));
  const auto& v = object_.at(key);
  if (!v.is_object()) fail(key, "expected an object, got " + v.dump());
  return ConfigReader(v, source_, path(key));
}

void ConfigReader::finish() const {
  for (auto it = object_.begin(); it != object_.end(); ++it)
    if (!read_.count(it.key())) fail(it.key(), "unknown key");
}

}  // namespace mcf
