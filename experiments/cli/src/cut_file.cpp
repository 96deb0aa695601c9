#include "strata/app/cut_file.hpp"

#include <nlohmann/json.hpp>

#include "strata/app/scene_parser.hpp"
#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"

namespace strata::app {
namespace {

constexpr const char* kFormat = "strata precomputed cut";
constexpr int kVersion = 1;

const nlohmann::json& member(const nlohmann::json& object, const char* key,
                             const std::string& where) {
  if (!object.is_object() || !object.contains(key))
    throw InputError(where + (where.empty() ? "" : ".") + key + ": missing");
  return object.at(key);
}

double number(const nlohmann::json& value, const std::string& where) {
  if (!value.is_number()) throw InputError(where + ": must be a number");
  return value.get<double>();
}

Index count(const nlohmann::json& value, const std::string& where) {
  if (!value.is_number_integer() || value.get<long long>() < 0)
    throw InputError(where + ": must be a non-negative integer");
  return static_cast<Index>(value.get<long long>());
}

/// Throws for a key of `object` outside `allowed`, naming it ("cut.json: windows.0.extra").
void expect_keys(const nlohmann::json& object, std::initializer_list<const char*> allowed,
                 const std::string& where) {
  if (!object.is_object()) return;
  for (const auto& [key, value] : object.items()) {
    bool known = false;
    for (const char* name : allowed)
      known = known || key == name;
    if (!known) throw InputError(where + (where.empty() ? "" : ".") + key + ": unknown key");
  }
}

}  // namespace

PrecomputedCut read_cut_file(const std::filesystem::path& file) {
  const nlohmann::json root = read_json_file(file);
  const std::string name = file.string();
  const auto at = [&](const std::string& key) { return name + ": " + key; };
  try {
    if (!root.is_object()) throw InputError(name + ": must be a JSON object");
    expect_keys(root,
                {"format", "version", "coarse_mesh", "levels", "tolerance", "sources", "windows"},
                "");
    if (member(root, "format", "") != kFormat)
      throw InputError(at("format") + ": expected \"" + kFormat + "\"");
    if (member(root, "version", "") != kVersion)
      throw InputError(at("version") + ": expected " + std::to_string(kVersion));
    PrecomputedCut cut;
    cut.name = name;
    const nlohmann::json& coarse = member(root, "coarse_mesh", "");
    expect_keys(coarse, {"vertices", "tets", "centroid"}, "coarse_mesh");
    cut.coarse_vertices =
        count(member(coarse, "vertices", "coarse_mesh"), at("coarse_mesh.vertices"));
    cut.coarse_tets = count(member(coarse, "tets", "coarse_mesh"), at("coarse_mesh.tets"));
    const nlohmann::json& centroid = member(coarse, "centroid", "coarse_mesh");
    if (!centroid.is_array() || centroid.size() != 3)
      throw InputError(at("coarse_mesh.centroid") + ": must be 3 numbers");
    for (int k = 0; k < 3; ++k)
      cut.coarse_centroid[k] = number(centroid[k], at("coarse_mesh.centroid"));
    cut.levels = static_cast<int>(count(member(root, "levels", ""), at("levels")));
    if (root.contains("tolerance")) cut.tolerance = number(root["tolerance"], at("tolerance"));
    if (root.contains("sources"))
      for (const nlohmann::json& source : root["sources"])
        if (source.is_string()) cut.sources.push_back(source.get<std::string>());
    const nlohmann::json& windows = member(root, "windows", "");
    if (!windows.is_array() || windows.empty())
      throw InputError(at("windows") + ": must be a non-empty array");
    for (std::size_t w = 0; w < windows.size(); ++w) {
      const std::string key = "windows." + std::to_string(w);
      expect_keys(windows[w], {"start", "end", "refined"}, key);
      CutWindow window;
      window.start = number(member(windows[w], "start", key), at(key + ".start"));
      window.end = number(member(windows[w], "end", key), at(key + ".end"));
      const nlohmann::json& refined = member(windows[w], "refined", key);
      if (!refined.is_array()) throw InputError(at(key + ".refined") + ": must be an array");
      for (std::size_t i = 0; i < refined.size(); ++i) {
        const std::string where = at(key + ".refined." + std::to_string(i));
        if (!refined[i].is_string()) throw InputError(where + ": must be a node path string");
        window.refined.push_back(parse_node_path(refined[i].get<std::string>(), where));
      }
      cut.windows.push_back(std::move(window));
    }
    return cut;
  } catch (const InputError& error) {
    const std::string text = error.what();
    if (text.rfind(name, 0) == 0) throw;
    throw InputError(name + ": " + text);
  }
}

void write_cut_file(const std::filesystem::path& file, const PrecomputedCut& cut) {
  nlohmann::json root;
  root["format"] = kFormat;
  root["version"] = kVersion;
  root["coarse_mesh"] = {
      {"vertices", cut.coarse_vertices},
      {"tets", cut.coarse_tets},
      {"centroid", {cut.coarse_centroid.x(), cut.coarse_centroid.y(), cut.coarse_centroid.z()}}};
  root["levels"] = cut.levels;
  root["tolerance"] = cut.tolerance;
  root["sources"] = cut.sources;
  nlohmann::json windows = nlohmann::json::array();
  for (const CutWindow& window : cut.windows) {
    nlohmann::json refined = nlohmann::json::array();
    for (const NodePath& path : window.refined)
      refined.push_back(to_string(path));
    windows.push_back({{"start", window.start}, {"end", window.end}, {"refined", refined}});
  }
  root["windows"] = windows;
  write_file_atomically(file, [&root](std::ostream& out) { out << root.dump(1) << '\n'; });
}

}  // namespace strata::app
