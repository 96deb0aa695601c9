#pragma once
/// \file scene_parser.hpp
/// Scene files: JSON → validated `Scene`. Every error is an InputError of one line
/// "<file>: <key.path>: <what is wrong>", e.g. "scene.json: material.poisson_ratio: must be in
/// [0, 0.5)"; array elements appear as indices in the path ("fixed.0.box.min").
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "strata/app/scene.hpp"
#include "strata/core/common/error.hpp"

namespace strata::app {

/// An InputError about one key of a scene; keeps the key path for callers.
class SceneKeyError : public InputError {
 public:
  SceneKeyError(const std::string& file, std::string key_path, const std::string& what,
                bool unknown_key);
  const std::string& key_path() const { return m_key_path; }
  /// True for "unknown key" errors.
  bool unknown_key() const { return m_unknown_key; }

 private:
  std::string m_key_path;
  bool m_unknown_key;
};

/// Reads and parses a JSON file. Missing file → InputError "<file>: cannot open"; malformed JSON →
/// InputError "<file>: line L, column C: <parser message>".
nlohmann::json read_json_file(const std::filesystem::path& file);

/// Validates the JSON of a scene and converts it. `file` names the scene in errors and its folder
/// anchors relative paths.
Scene parse_scene(const nlohmann::json& root, const std::filesystem::path& file);

/// read_json_file + the `--set` overrides ("key.path=value", see scene_overrides.hpp) +
/// parse_scene. An unknown key created by an override is reported as "--set <path>: unknown key".
Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides);

}  // namespace strata::app
