#pragma once
/// \file scene_json.hpp
/// Internal: typed access to scene JSON values with key-path error messages.
#include <initializer_list>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "strata/app/scene_parser.hpp"

namespace strata::app::detail {

/// A JSON value at a key path of a scene file.
class SceneValue {
 public:
  SceneValue(const nlohmann::json& value, std::string path, const std::string& file)
      : m_value(value), m_path(std::move(path)), m_file(file) {}

  const nlohmann::json& json() const { return m_value; }
  const std::string& path() const { return m_path; }
  /// What the value is, for messages: a string quoted, else "a number", "a boolean", "an array",
  /// "an object" or "null".
  std::string describe() const;

  /// Throws SceneKeyError "<file>: <path>: <message>".
  [[noreturn]] void fail(const std::string& message) const;

  /// Requires an object whose keys are all in `allowed` (else "<path>.<key>: unknown key").
  void expect_object(std::initializer_list<const char*> allowed) const;
  bool has(const char* key) const;
  /// The member `key` (which must exist; else "<path>.<key>: missing required key").
  SceneValue at(const char* key) const;
  /// Array elements (requires an array).
  std::vector<SceneValue> elements() const;

  double number() const;  ///< a finite number
  double positive() const;
  double non_negative() const;
  int integer(int min_value) const;  ///< an integer ≥ min_value
  bool boolean() const;
  std::string string() const;
  Vector3d vec3() const;          ///< an array of 3 finite numbers
  Vector3d nonzero_vec3() const;  ///< ... not all zero
  std::array<int, 3> int3(int min_value) const;
  /// One of `names`; else `unknown value "x" (expected a, b, c)`; returns its index.
  int choice(std::initializer_list<const char*> names) const;
  int choice(const std::vector<std::string>& names) const;

 private:
  const nlohmann::json& m_value;
  std::string m_path;
  const std::string& m_file;
};

}  // namespace strata::app::detail
