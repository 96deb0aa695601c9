#include "scene_json.hpp"

#include <cmath>
#include <limits>

namespace strata::app::detail {
namespace {

std::string type_name(const nlohmann::json& value) {
  if (value.is_number()) return "a number";
  if (value.is_string()) return "a string";
  if (value.is_boolean()) return "a boolean";
  if (value.is_array()) return "an array";
  if (value.is_object()) return "an object";
  return "null";
}

std::string join_path(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

}  // namespace

std::string SceneValue::describe() const {
  return m_value.is_string() ? m_value.dump() : type_name(m_value);
}

void SceneValue::fail(const std::string& message) const {
  throw SceneKeyError(m_file, m_path, message, false);
}

void SceneValue::expect_object(std::initializer_list<const char*> allowed) const {
  if (!m_value.is_object()) fail("must be an object, got " + type_name(m_value));
  for (const auto& [key, value] : m_value.items()) {
    bool known = false;
    for (const char* name : allowed)
      known = known || key == name;
    if (!known) throw SceneKeyError(m_file, join_path(m_path, key), "unknown key", true);
  }
}

bool SceneValue::has(const char* key) const {
  return m_value.contains(key);
}

SceneValue SceneValue::at(const char* key) const {
  if (!m_value.contains(key)) {
    throw SceneKeyError(m_file, join_path(m_path, key), "missing required key", false);
  }
  return SceneValue(m_value.at(key), join_path(m_path, key), m_file);
}

std::vector<SceneValue> SceneValue::elements() const {
  if (!m_value.is_array()) fail("must be an array, got " + type_name(m_value));
  std::vector<SceneValue> result;
  for (std::size_t i = 0; i < m_value.size(); ++i) {
    result.emplace_back(m_value[i], join_path(m_path, std::to_string(i)), m_file);
  }
  return result;
}

double SceneValue::number() const {
  if (!m_value.is_number()) fail("must be a number, got " + type_name(m_value));
  const double value = m_value.get<double>();
  if (!std::isfinite(value)) fail("must be finite");
  return value;
}

double SceneValue::positive() const {
  const double value = number();
  if (!(value > 0.0)) fail("must be > 0");
  return value;
}

double SceneValue::non_negative() const {
  const double value = number();
  if (value < 0.0) fail("must be >= 0");
  return value;
}

int SceneValue::integer(int min_value) const {
  if (!m_value.is_number()) fail("must be an integer, got " + type_name(m_value));
  const double value = m_value.get<double>();
  if (value != std::floor(value)) fail("must be an integer");
  if (value < min_value) fail("must be >= " + std::to_string(min_value));
  if (value > std::numeric_limits<int>::max())
    fail("must be an integer of at most " + std::to_string(std::numeric_limits<int>::max()));
  return static_cast<int>(value);
}

bool SceneValue::boolean() const {
  if (!m_value.is_boolean()) fail("must be true or false, got " + type_name(m_value));
  return m_value.get<bool>();
}

std::string SceneValue::string() const {
  if (!m_value.is_string()) fail("must be a string, got " + type_name(m_value));
  return m_value.get<std::string>();
}

Vector3d SceneValue::vec3() const {
  if (!m_value.is_array() || m_value.size() != 3) fail("must be an array of 3 numbers");
  Vector3d result;
  for (int i = 0; i < 3; ++i) {
    if (!m_value[i].is_number()) fail("must be an array of 3 numbers");
    result(i) = m_value[i].get<double>();
    if (!std::isfinite(result(i))) fail("must be finite");
  }
  return result;
}

Vector3d SceneValue::nonzero_vec3() const {
  const Vector3d result = vec3();
  if (result.norm() == 0.0) fail("must not be the zero vector");
  return result;
}

std::array<int, 3> SceneValue::int3(int min_value) const {
  if (!m_value.is_array() || m_value.size() != 3) fail("must be an array of 3 integers");
  std::array<int, 3> result{};
  for (std::size_t i = 0; i < 3; ++i) {
    result[i] =
        SceneValue(m_value[i], join_path(m_path, std::to_string(i)), m_file).integer(min_value);
  }
  return result;
}

int SceneValue::choice(std::initializer_list<const char*> names) const {
  return choice(std::vector<std::string>(names.begin(), names.end()));
}

int SceneValue::choice(const std::vector<std::string>& names) const {
  const std::string value = string();
  std::string expected;
  for (std::size_t index = 0; index < names.size(); ++index) {
    if (value == names[index]) return static_cast<int>(index);
    expected += (index == 0 ? "" : ", ") + names[index];
  }
  fail("unknown value \"" + value + "\" (expected " + expected + ")");
}

}  // namespace strata::app::detail
