#include "harness/json_path.h"

namespace mcf {

namespace {

/// The value at a dotted path, const or not (nullptr if absent).
template <class Json>
Json* at_path(Json& j, const std::string& dotted) {
  Json* node = &j;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = dotted.find('.', start);
    const std::string part =
        dotted.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (!node->is_object()) return nullptr;
    const auto it = node->find(part);
    if (it == node->end()) return nullptr;
    node = &*it;
    if (dot == std::string::npos) return node;
    start = dot + 1;
  }
}

}  // namespace

const nlohmann::json* json_at_path(const nlohmann::json& j, const std::string& dotted) {
  return at_path(j, dotted);
}

void set_json_path(nlohmann::json& j, const std::string& dotted, const nlohmann::json& value) {
  nlohmann::json* node = &j;
  std::size_t start = 0;
  for (std::size_t dot = dotted.find('.'); dot != std::string::npos;
       dot = dotted.find('.', start)) {
    node = &(*node)[dotted.substr(start, dot - start)];
    start = dot + 1;
  }
  (*node)[dotted.substr(start)] = value;
}

void erase_json_path(nlohmann::json& j, const std::string& dotted) {
  const std::size_t dot = dotted.rfind('.');
  nlohmann::json* parent = dot == std::string::npos ? &j : at_path(j, dotted.substr(0, dot));
  if (parent && parent->is_object())
    parent->erase(dotted.substr(dot == std::string::npos ? 0 : dot + 1));
}

}  // namespace mcf
