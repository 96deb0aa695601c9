#include "strata/app/scene_overrides.hpp"

#include <charconv>
#include <vector>

#include "strata/core/common/error.hpp"

namespace strata::app {
namespace {

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = path.find('.', begin);
    parts.push_back(path.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin));
    if (dot == std::string::npos) break;
    begin = dot + 1;
  }
  return parts;
}

bool parse_index(const std::string& text, std::size_t& index) {
  if (text.empty()) return false;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), index);
  return error == std::errc() && end == text.data() + text.size();
}

}  // namespace

SceneOverride parse_override(const std::string& text) {
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw InputError("--set " + text + ": expected key.path=value");
  }
  SceneOverride result;
  result.path = text.substr(0, equals);
  for (const std::string& part : split_path(result.path)) {
    if (part.empty()) throw InputError("--set " + text + ": empty component in key path");
  }
  const std::string value = text.substr(equals + 1);
  result.value = nlohmann::json::parse(value, nullptr, /*allow_exceptions=*/false);
  if (result.value.is_discarded()) result.value = value;
  return result;
}

void apply_override(nlohmann::json& root, const SceneOverride& override_) {
  const std::vector<std::string> parts = split_path(override_.path);
  nlohmann::json* node = &root;
  std::string walked;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& key = parts[i];
    const bool last = i + 1 == parts.size();
    if (node->is_null()) *node = nlohmann::json::object();
    if (node->is_array()) {
      std::size_t index = 0;
      if (!parse_index(key, index)) {
        throw InputError("--set " + override_.path + ": " + walked + " is an array, \"" + key +
                         "\" is not an index");
      }
      if (index > node->size()) {
        throw InputError("--set " + override_.path + ": index " + key + " out of range (" + walked +
                         " has " + std::to_string(node->size()) + " entries)");
      }
      if (index == node->size()) node->push_back(nullptr);
      node = &(*node)[index];
    } else if (node->is_object()) {
      node = &(*node)[key];
    } else {
      throw InputError("--set " + override_.path + ": " + (walked.empty() ? "the scene" : walked) +
                       " is not an object or array");
    }
    walked += (walked.empty() ? "" : ".") + key;
    if (last) *node = override_.value;
  }
}

}  // namespace strata::app
