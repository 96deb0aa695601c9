#include "strata/app/scene_parser.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "scene_hierarchy.hpp"
#include "scene_implicit.hpp"
#include "scene_json.hpp"
#include "strata/app/scene_overrides.hpp"
#include "strata/core/fem/material_registry.hpp"

namespace strata::app {
namespace {

using detail::SceneValue;

constexpr double kPi = 3.14159265358979323846;

Region parse_region(const SceneValue& value) {
  value.expect_object({"box", "plane", "sphere"});
  const int kinds = value.has("box") + value.has("plane") + value.has("sphere");
  if (kinds != 1) value.fail("must have exactly one of box, plane, sphere");
  if (value.has("box")) {
    const SceneValue box = value.at("box");
    box.expect_object({"min", "max"});
    BoxRegion region{box.at("min").vec3(), box.at("max").vec3()};
    if ((region.min.array() > region.max.array()).any()) {
      box.at("max").fail("must be >= min in every coordinate");
    }
    return region;
  }
  if (value.has("plane")) {
    const SceneValue plane = value.at("plane");
    plane.expect_object({"point", "normal", "tolerance"});
    PlaneRegion region;
    region.point = plane.at("point").vec3();
    region.normal = plane.at("normal").nonzero_vec3();
    region.distance = plane.has("tolerance") ? plane.at("tolerance").non_negative() : 0.0;
    return region;
  }
  const SceneValue sphere = value.at("sphere");
  sphere.expect_object({"center", "radius"});
  return SphereRegion{sphere.at("center").vec3(), sphere.at("radius").non_negative()};
}

/// `[[t, s], ...]`: at least one point, t strictly increasing.
Amplitude parse_amplitude(const SceneValue& value) {
  Amplitude amplitude;
  for (const SceneValue& point : value.elements()) {
    const std::vector<SceneValue> pair = point.elements();
    if (pair.size() != 2) point.fail("must be a pair [t, s]");
    const double t = pair[0].number();
    if (!amplitude.points.empty() && !(t > amplitude.points.back()[0])) {
      pair[0].fail("times must increase strictly");
    }
    amplitude.points.push_back({t, pair[1].number()});
  }
  if (amplitude.points.empty()) value.fail("must hold at least one point [t, s]");
  return amplitude;
}

std::filesystem::path parse_path(const SceneValue& value, const std::filesystem::path& folder) {
  const std::string name = value.string();
  if (name.empty()) value.fail("must not be empty");
  const std::filesystem::path path(name);
  return path.is_absolute() ? path : folder / path;
}

/// Throws SceneKeyError naming `key` unless `path` is an existing file.
void check_input_file(const std::string& scene_file, const std::string& key,
                      const std::filesystem::path& path) {
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (!std::filesystem::exists(status))
    throw SceneKeyError(scene_file, key, "cannot read '" + path.string() + "': no such file",
                        false);
  if (std::filesystem::is_directory(status))
    throw SceneKeyError(scene_file, key, "cannot read '" + path.string() + "': it is a folder",
                        false);
}

/// The files a scene names, checked when it is loaded (parse_scene alone reads none of them).
void check_input_files(const Scene& scene) {
  const std::string file = scene.file.string();
  if (scene.mesh.file) check_input_file(file, "mesh.file", *scene.mesh.file);
  if (scene.mesh.surface) check_input_file(file, "mesh.surface", *scene.mesh.surface);
  if (scene.mesh.level_set) check_input_file(file, "mesh.level_set", *scene.mesh.level_set);
  for (std::size_t i = 0; i < scene.obstacles.size(); ++i) {
    const std::string key = "obstacles." + std::to_string(i);
    if (scene.obstacles[i].surface)
      check_input_file(file, key + ".surface", *scene.obstacles[i].surface);
    if (scene.obstacles[i].level_set)
      check_input_file(file, key + ".level_set", *scene.obstacles[i].level_set);
  }
}

/// The Mesh_3 keys beside "surface".
MeshingOptions parse_meshing_options(const SceneValue& value) {
  MeshingOptions options;
  options.cell_size = value.at("cell_size").positive();
  if (value.has("facet_size")) options.facet_size = value.at("facet_size").positive();
  if (value.has("facet_distance")) options.facet_distance = value.at("facet_distance").positive();
  if (value.has("facet_angle")) {
    const SceneValue angle = value.at("facet_angle");
    options.facet_angle = angle.number();
    if (options.facet_angle <= 0.0 || options.facet_angle > 30.0) {
      angle.fail("must be in (0, 30] degrees (Mesh_3 need not terminate above 30)");
    }
  }
  if (value.has("radius_edge_ratio")) {
    const SceneValue ratio = value.at("radius_edge_ratio");
    options.cell_radius_edge_ratio = ratio.number();
    if (options.cell_radius_edge_ratio < 2.0) {
      ratio.fail("must be >= 2 (Mesh_3 need not terminate below 2)");
    }
  }
  if (value.has("sharp_features")) options.sharp_features = value.at("sharp_features").boolean();
  if (value.has("perturb")) options.perturb = value.at("perturb").boolean();
  if (value.has("exude")) options.exude = value.at("exude").boolean();
  if (value.has("odt")) options.odt = value.at("odt").boolean();
  if (value.has("lloyd")) options.lloyd = value.at("lloyd").boolean();
  if (value.has("seed")) options.seed = static_cast<std::uint32_t>(value.at("seed").integer(0));
  return options;
}

/// `meshing`: a surface is tetrahedralised (its Mesh_3 keys apply); false for a body of skeleton
/// springs, which takes the surface as it is (only "surface").
MeshSpec parse_mesh(const SceneValue& value, const std::filesystem::path& folder,
                    bool meshing = true) {
  if (!meshing) {
    value.expect_object({"surface"});
    MeshSpec mesh;
    mesh.surface = parse_path(value.at("surface"), folder);
    return mesh;
  }
  value.expect_object({"file", "box", "surface", "level_set", "grid", "implicit", "voxel_size",
                       "cell_size", "facet_size", "facet_distance", "facet_angle",
                       "radius_edge_ratio", "sharp_features", "perturb", "exude", "odt", "lloyd",
                       "seed"});
  const int sources = value.has("file") + value.has("box") + value.has("surface") +
                      value.has("level_set") + value.has("implicit");
  if (sources != 1) value.fail("must have exactly one of file, box, surface, level_set, implicit");
  if (value.has("grid") && !value.has("level_set")) {
    value.at("grid").fail("only allowed with level_set");
  }
  if (value.has("voxel_size") && !value.has("implicit")) {
    value.at("voxel_size").fail("only allowed with implicit");
  }
  MeshSpec mesh;
  if (value.has("surface") || value.has("level_set") || value.has("implicit")) {
    if (value.has("surface")) mesh.surface = parse_path(value.at("surface"), folder);
    if (value.has("level_set")) mesh.level_set = parse_path(value.at("level_set"), folder);
    if (value.has("grid")) {
      mesh.grid = value.at("grid").string();
      if (mesh.grid.empty()) value.at("grid").fail("must not be empty");
    }
    if (value.has("implicit")) mesh.implicit = detail::parse_implicit_shape(value.at("implicit"));
    if (value.has("voxel_size")) mesh.voxel_size = value.at("voxel_size").positive();
    mesh.meshing = parse_meshing_options(value);
    return mesh;
  }
  for (const char* key :
       {"cell_size", "facet_size", "facet_distance", "facet_angle", "radius_edge_ratio",
        "sharp_features", "perturb", "exude", "odt", "lloyd", "seed"}) {
    if (value.has(key)) {
      value.at(key).fail("is a meshing key: only allowed with surface, level_set, implicit");
    }
  }
  if (value.has("file")) {
    mesh.file = parse_path(value.at("file"), folder);
    return mesh;
  }
  const SceneValue box = value.at("box");
  box.expect_object({"min", "max", "cells"});
  mesh.box_min = box.at("min").vec3();
  mesh.box_max = box.at("max").vec3();
  if ((mesh.box_min.array() >= mesh.box_max.array()).any()) {
    box.at("max").fail("must be > min in every coordinate");
  }
  mesh.box_cells = box.at("cells").int3(1);
  return mesh;
}

Plasticity parse_plasticity(const SceneValue& value) {
  value.expect_object({"yield_stress", "hardening", "max_plastic_strain"});
  Plasticity plasticity;
  plasticity.yield_stress = value.at("yield_stress").positive();
  if (value.has("hardening")) plasticity.hardening = value.at("hardening").non_negative();
  if (value.has("max_plastic_strain")) {
    plasticity.max_plastic_strain = value.at("max_plastic_strain").positive();
  }
  return plasticity;
}

SurfaceSpringSettings parse_surface_springs(const SceneValue& value) {
  value.expect_object({"youngs_modulus", "yield_strain", "fraction", "seed"});
  SurfaceSpringSettings springs;
  springs.youngs_modulus = value.at("youngs_modulus").positive();
  if (value.has("yield_strain")) springs.yield_strain = value.at("yield_strain").positive();
  if (value.has("fraction")) {
    const SceneValue fraction = value.at("fraction");
    springs.fraction = fraction.positive();
    if (springs.fraction > 1.0) fraction.fail("must be in (0, 1]");
  }
  if (value.has("seed")) springs.seed = static_cast<std::uint32_t>(value.at("seed").integer(0));
  return springs;
}

Material parse_material(const SceneValue& value) {
  value.expect_object({"model", "youngs_modulus", "poisson_ratio", "density", "damping",
                       "plasticity", "surface_springs"});
  Material material;
  const int model = value.at("model").choice(material_model_names());
  material.model = material_registry()[model].model;
  material.youngs_modulus = value.at("youngs_modulus").positive();
  const SceneValue nu = value.at("poisson_ratio");
  material.poisson_ratio = nu.number();
  if (material.poisson_ratio < 0.0 || material.poisson_ratio >= 0.5) nu.fail("must be in [0, 0.5)");
  material.density = value.at("density").positive();
  if (value.has("damping")) {
    const SceneValue damping = value.at("damping");
    damping.expect_object({"mass", "stiffness"});
    if (damping.has("mass")) material.mass_damping = damping.at("mass").non_negative();
    if (damping.has("stiffness")) {
      material.stiffness_damping = damping.at("stiffness").non_negative();
    }
  }
  if (value.has("plasticity")) material.plasticity = parse_plasticity(value.at("plasticity"));
  return material;
}

DirichletSpec parse_prescribed(const SceneValue& value) {
  value.expect_object({"region", "displacement", "rotation", "amplitude"});
  DirichletSpec spec;
  spec.name = value.path();
  spec.region = parse_region(value.at("region"));
  if (value.has("amplitude")) spec.amplitude = parse_amplitude(value.at("amplitude"));
  if (value.has("displacement") == value.has("rotation")) {
    value.fail("must have exactly one of displacement, rotation");
  }
  if (value.has("displacement")) {
    spec.kind = DirichletKind::displacement;
    spec.displacement = value.at("displacement").vec3();
    return spec;
  }
  const SceneValue rotation = value.at("rotation");
  rotation.expect_object({"axis", "center", "angle_degrees"});
  spec.kind = DirichletKind::rotation;
  spec.axis = rotation.at("axis").nonzero_vec3().normalized();
  spec.has_center = true;
  spec.center = rotation.at("center").vec3();
  spec.angle = rotation.at("angle_degrees").number() * kPi / 180.0;
  return spec;
}

SolverSettings parse_solver(const SceneValue& value) {
  value.expect_object({"mode", "integrator", "dt", "duration", "load_steps", "linear_solver",
                       "newton_tolerance", "max_newton_iterations", "hessian", "max_plastic_passes",
                       "plastic_tolerance", "contact_distance", "friction_slip"});
  SolverSettings solver;
  solver.mode = static_cast<SimulationMode>(value.at("mode").choice({"dynamic", "static"}));
  if (value.has("integrator")) {
    solver.integrator = static_cast<Integrator>(
        value.at("integrator").choice({"symplectic_euler", "rk4", "implicit_euler"}));
  }
  if (solver.mode == SimulationMode::dynamic) {
    solver.dt = value.at("dt").positive();
    solver.duration = value.at("duration").positive();
  } else {
    if (value.has("dt")) solver.dt = value.at("dt").positive();
    if (value.has("duration")) solver.duration = value.at("duration").positive();
  }
  if (value.has("load_steps")) solver.load_steps = value.at("load_steps").integer(1);
  if (value.has("linear_solver")) {
    static const std::vector<std::string> kinds = {"cholmod", "cg", "multigrid", "amg", "auto"};
    solver.newton.linear_solver =
        linear_solver_from_string(kinds[value.at("linear_solver").choice(kinds)]);
  }
  if (value.has("newton_tolerance")) {
    solver.newton.tolerance = value.at("newton_tolerance").positive();
  }
  if (value.has("max_newton_iterations")) {
    solver.newton.max_iterations = value.at("max_newton_iterations").integer(1);
  }
  if (value.has("hessian"))
    solver.newton.exact_hessian = value.at("hessian").choice({"projected", "exact_where_pd"}) == 1;
  if (value.has("max_plastic_passes")) {
    solver.plasticity.max_passes = value.at("max_plastic_passes").integer(1);
  }
  if (value.has("plastic_tolerance")) {
    solver.plasticity.tolerance = value.at("plastic_tolerance").positive();
  }
  if (value.has("contact_distance")) {
    solver.contact.distance = value.at("contact_distance").positive();
  }
  if (value.has("friction_slip"))
    solver.contact.friction_slip = value.at("friction_slip").positive();
  return solver;
}

ObstacleSpec parse_obstacle(const SceneValue& value, const std::filesystem::path& folder) {
  value.expect_object(
      {"plane", "implicit", "level_set", "grid", "surface", "voxel_size", "friction", "motion"});
  const int kinds =
      value.has("plane") + value.has("implicit") + value.has("level_set") + value.has("surface");
  if (kinds != 1) value.fail("must have exactly one of plane, implicit, level_set, surface");
  ObstacleSpec spec;
  spec.name = value.path();
  if (value.has("plane")) {
    const SceneValue plane = value.at("plane");
    plane.expect_object({"point", "normal"});
    spec.plane_point = plane.at("point").vec3();
    spec.plane_normal = plane.at("normal").nonzero_vec3();
  }
  if (value.has("implicit")) spec.implicit = detail::parse_implicit_shape(value.at("implicit"));
  if (value.has("level_set")) spec.level_set = parse_path(value.at("level_set"), folder);
  if (value.has("surface")) spec.surface = parse_path(value.at("surface"), folder);
  if (value.has("grid")) {
    if (!value.has("level_set")) value.at("grid").fail("only allowed with level_set");
    spec.grid = value.at("grid").string();
  }
  if (value.has("voxel_size")) {
    if (!value.has("implicit") && !value.has("surface")) {
      value.at("voxel_size").fail("only allowed with implicit or surface");
    }
    spec.voxel_size = value.at("voxel_size").positive();
  }
  if (value.has("friction")) spec.friction = value.at("friction").non_negative();
  if (value.has("motion")) {
    const SceneValue motion = value.at("motion");
    motion.expect_object({"velocity"});
    spec.velocity = motion.at("velocity").vec3();
  }
  return spec;
}

OutputSpec parse_output(const SceneValue& value) {
  value.expect_object({"every", "probes", "vtk", "vtk_encoding"});
  OutputSpec output;
  if (value.has("every")) output.every = value.at("every").integer(1);
  if (value.has("probes")) {
    for (const SceneValue& probe : value.at("probes").elements()) {
      output.probes.push_back(probe.vec3());
    }
  }
  if (value.has("vtk")) {
    const SceneValue vtk = value.at("vtk");
    if (vtk.json().is_string() && vtk.string() == "surface") {
      output.vtk_mesh = false;
    } else if (vtk.json().is_boolean()) {
      output.vtk = vtk.boolean();
    } else {
      vtk.fail("must be true, false or \"surface\", got " + vtk.describe());
    }
  }
  if (value.has("vtk_encoding")) {
    output.vtk_encoding = value.at("vtk_encoding").choice({"binary", "ascii"}) == 1
                              ? VtkEncoding::ascii
                              : VtkEncoding::binary;
  }
  return output;
}

/// Finds the first key that appears twice in one JSON object (nlohmann keeps the last one
/// silently) and records its path, "material.youngs_modulus" or "fixed.1.box".
struct DuplicateKeyCheck {
  struct Frame {
    bool array = false;
    long index = 0;
    std::string key;
    std::set<std::string> keys;
  };
  std::vector<Frame> frames;
  std::string duplicate;

  std::string path() const {
    std::string result;
    for (const Frame& frame : frames) {
      const std::string part = frame.array ? std::to_string(frame.index) : frame.key;
      result += (result.empty() ? "" : ".") + part;
    }
    return result;
  }

  /// A value inside an array moves the array's index on.
  void value_done() {
    if (!frames.empty() && frames.back().array) ++frames.back().index;
  }

  bool operator()(int /*depth*/, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
        frames.push_back({});
        break;
      case Event::array_start:
        frames.emplace_back();
        frames.back().array = true;
        break;
      case Event::key: {
        Frame& frame = frames.back();
        frame.key = parsed.get<std::string>();
        if (!frame.keys.insert(frame.key).second && duplicate.empty()) duplicate = path();
        break;
      }
      case Event::object_end:
      case Event::array_end:
        frames.pop_back();
        value_done();
        break;
      case Event::value:
        value_done();
        break;
    }
    return true;
  }
};

}  // namespace

SceneKeyError::SceneKeyError(const std::string& file, std::string key_path, const std::string& what,
                             bool unknown_key)
    : InputError(file + ": " + (key_path.empty() ? std::string("scene") : key_path) + ": " + what),
      m_key_path(std::move(key_path)),
      m_unknown_key(unknown_key) {}

namespace {

/// Where the number `literal` stands in the JSON text `content` (outside strings, as a whole
/// number), or npos.
std::size_t find_number(const std::string& content, const std::string& literal) {
  const auto part_of_number = [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == 'e' || c == 'E' ||
           c == '+' || c == '-';
  };
  bool in_string = false;
  for (std::size_t i = 0; i < content.size(); ++i) {
    const char c = content[i];
    if (in_string) {
      if (c == '\\')
        ++i;  // the escaped character
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
      continue;
    }
    if (content.compare(i, literal.size(), literal) == 0 &&
        (i == 0 || !part_of_number(content[i - 1])) &&
        (i + literal.size() == content.size() || !part_of_number(content[i + literal.size()])))
      return i;
  }
  return std::string::npos;
}

}  // namespace

nlohmann::json read_json_file(const std::filesystem::path& file) {
  std::error_code error_code;
  if (std::filesystem::is_directory(file, error_code))
    throw InputError(file.string() + ": is a folder, not a JSON file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open (no such file or not readable)");
  std::ostringstream text;
  text << in.rdbuf();
  try {
    DuplicateKeyCheck duplicates;
    nlohmann::json root = nlohmann::json::parse(
        text.str(),
        [&duplicates](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
          return duplicates(depth, event, parsed);
        });
    if (!duplicates.duplicate.empty())
      throw InputError(file.string() + ": " + duplicates.duplicate +
                       ": duplicate key (each key may appear once in an object)");
    return root;
  } catch (const nlohmann::json::parse_error& error) {
    // "[json.exception.parse_error.101] parse error at line 3, column 7: syntax error ..."
    const std::string what = error.what();
    std::smatch match;
    static const std::regex pattern(R"(at line (\d+), column (\d+): (.*))");
    if (std::regex_search(what, match, pattern)) {
      throw InputError(file.string() + ": line " + match[1].str() + ", column " + match[2].str() +
                       ": " + match[3].str());
    }
    throw InputError(file.string() + ": malformed JSON at byte " + std::to_string(error.byte) +
                     ": " + what);
  } catch (const nlohmann::json::out_of_range& error) {
    // "[json.exception.out_of_range.406] number overflow parsing '1e400'"
    const std::string what = error.what();
    const std::size_t start = what.find("] ");
    std::string where;
    const std::size_t open = what.find('\''), close = what.rfind('\'');
    if (open != std::string::npos && close > open + 1) {
      const std::string content = text.str();
      const std::size_t at = find_number(content, what.substr(open + 1, close - open - 1));
      if (at != std::string::npos) {
        const std::size_t line_start = content.rfind('\n', at);
        const auto line = 1 + std::count(content.begin(), content.begin() + at, '\n');
        const std::size_t column = at - (line_start == std::string::npos ? 0 : line_start + 1) + 1;
        where = "line " + std::to_string(line) + ", column " + std::to_string(column) + ": ";
      }
    }
    throw InputError(file.string() + ": " + where +
                     (start == std::string::npos ? what : what.substr(start + 2)) +
                     " (not a finite double)");
  }
}

Scene parse_scene(const nlohmann::json& root, const std::filesystem::path& file) {
  const std::string file_name = file.string();
  const SceneValue top(root, "", file_name);
  top.expect_object({"mesh", "material", "gravity", "fixed", "prescribed", "forces", "ground",
                     "obstacles", "solver", "output", "hierarchy", "body"});
  Scene scene;
  scene.file = file;
  scene.name = file.stem().string();
  if (top.has("body")) {
    const SceneValue body = top.at("body");
    body.expect_object({"model", "shell_ratio", "surface_scale", "tie_scale", "skeleton_scale",
                        "surface_vertices"});
    scene.body.skeleton_springs = body.at("model").choice({"tets", "skeleton_springs"}) == 1;
    SpringBodyRule& rule = scene.body.rule;
    const std::pair<const char*, double*> factors[] = {{"shell_ratio", &rule.shell_ratio},
                                                       {"surface_scale", &rule.surface_scale},
                                                       {"tie_scale", &rule.tie_scale},
                                                       {"skeleton_scale", &rule.skeleton_scale}};
    for (const auto& [key, target] : factors) {
      if (!body.has(key)) continue;
      if (!scene.body.skeleton_springs) body.at(key).fail("only with model \"skeleton_springs\"");
      *target = body.at(key).positive();
    }
    if (body.has("surface_vertices")) {
      const SceneValue count = body.at("surface_vertices");
      if (!scene.body.skeleton_springs) count.fail("only with model \"skeleton_springs\"");
      scene.body.surface_vertices = count.integer(0);
      if (scene.body.surface_vertices > 0 && scene.body.surface_vertices < 4)
        count.fail("expected 0 (the surface as given) or at least 4 vertices, got " +
                   std::to_string(scene.body.surface_vertices));
    }
    if (scene.body.skeleton_springs) {
      if (!top.at("mesh").has("surface"))
        body.at("model").fail("skeleton_springs needs mesh.surface (a closed surface file)");
      if (top.has("hierarchy"))
        throw SceneKeyError(file_name, "hierarchy",
                            "not supported with body.model skeleton_springs", false);
      if (top.at("material").has("surface_springs") || top.at("material").has("plasticity"))
        throw SceneKeyError(file_name, "material",
                            "surface_springs and plasticity are not supported with body.model "
                            "skeleton_springs",
                            false);
    }
  }
  scene.mesh = parse_mesh(top.at("mesh"), file.parent_path(), !scene.body.skeleton_springs);
  scene.material = parse_material(top.at("material"));
  if (top.at("material").has("surface_springs")) {
    scene.surface_springs = parse_surface_springs(top.at("material").at("surface_springs"));
    if (top.has("hierarchy")) {
      throw SceneKeyError(file_name, "material.surface_springs",
                          "not supported with hierarchy (the springs live on one mesh's surface)",
                          false);
    }
  }
  if (top.has("gravity")) scene.gravity = top.at("gravity").vec3();
  if (top.has("fixed")) {
    for (const SceneValue& entry : top.at("fixed").elements()) {
      DirichletSpec spec;
      spec.name = entry.path();
      spec.region = parse_region(entry);
      scene.fixed.push_back(spec);
    }
  }
  if (top.has("prescribed")) {
    for (const SceneValue& entry : top.at("prescribed").elements()) {
      scene.prescribed.push_back(parse_prescribed(entry));
    }
  }
  if (top.has("forces")) {
    for (const SceneValue& entry : top.at("forces").elements()) {
      entry.expect_object({"region", "total_force", "amplitude"});
      RegionLoad load{entry.path(), parse_region(entry.at("region")),
                      entry.at("total_force").vec3()};
      if (entry.has("amplitude")) load.amplitude = parse_amplitude(entry.at("amplitude"));
      scene.forces.push_back(std::move(load));
    }
  }
  if (top.has("ground")) {
    const SceneValue ground = top.at("ground");
    ground.expect_object({"point", "normal", "friction"});
    GroundPlane spec;
    spec.point = ground.at("point").vec3();
    spec.normal = ground.at("normal").nonzero_vec3().normalized();
    if (ground.has("friction")) spec.friction = ground.at("friction").non_negative();
    scene.ground = spec;
  }
  if (top.has("obstacles")) {
    for (const SceneValue& entry : top.at("obstacles").elements()) {
      scene.obstacles.push_back(parse_obstacle(entry, file.parent_path()));
    }
  }
  scene.solver = parse_solver(top.at("solver"));
  {
    const SceneValue solver = top.at("solver");
    const bool dynamic = scene.solver.mode == SimulationMode::dynamic;
    for (const char* key : {"integrator", "dt", "duration"})
      if (!dynamic && solver.has(key))
        scene.ignored_keys.push_back(std::string("solver.") + key +
                                     ": applies to dynamic runs only (ignored)");
    if (dynamic && solver.has("load_steps"))
      scene.ignored_keys.push_back("solver.load_steps: applies to static runs only (ignored)");
    // Static runs place the obstacles where they stand at t = 0.
    if (!dynamic && top.has("obstacles")) {
      const std::vector<SceneValue> obstacles = top.at("obstacles").elements();
      for (std::size_t i = 0; i < obstacles.size(); ++i)
        if (obstacles[i].has("motion"))
          scene.ignored_keys.push_back("obstacles." + std::to_string(i) +
                                       ".motion: applies to dynamic runs only (ignored)");
    }
    if (dynamic && scene.solver.duration < scene.solver.dt * (1.0 - 1e-9)) {
      std::ostringstream warning;
      warning << "solver.duration: " << scene.solver.duration << " s is shorter than solver.dt "
              << scene.solver.dt << " s (the run takes one step of dt)";
      scene.ignored_keys.push_back(warning.str());
    }
  }
  if (top.has("output")) {
    scene.output = parse_output(top.at("output"));
    if (scene.output.vtk && !scene.output.vtk_mesh && !scene.mesh.surface) {
      top.at("output").at("vtk").fail(
          "\"surface\" writes the fine surface, and the scene has none (mesh.surface)");
    }
  }
  if (top.has("hierarchy"))
    scene.hierarchy = detail::parse_hierarchy(top.at("hierarchy"), file.parent_path());
  if (scene.hierarchy && scene.hierarchy->mode == HierarchyMode::full) {
    // Every key but levels and mode is one of adaptation (parse_hierarchy refuses unknown keys).
    for (const auto& item : top.at("hierarchy").json().items()) {
      const std::string& key = item.key();
      if (key == "levels" || key == "mode") continue;
      const char* reason = key == "level" ? "runs on the finest level"
                           : key == "cut" ? "plays back no precomputed cut"
                                          : "does not adapt";
      scene.ignored_keys.push_back("hierarchy." + key + ": mode \"full\" " + reason + " (ignored)");
    }
  }
  if (scene.solver.mode == SimulationMode::static_equilibrium && scene.fixed.empty() &&
      scene.prescribed.empty()) {
    throw SceneKeyError(file_name, "fixed",
                        "static mode needs at least one fixed or prescribed group", false);
  }
  return scene;
}

Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  nlohmann::json root = read_json_file(file);
  std::vector<SceneOverride> parsed;
  for (const std::string& text : overrides) {
    parsed.push_back(parse_override(text));
    apply_override(root, parsed.back());
  }
  try {
    Scene scene = parse_scene(root, file);
    check_input_files(scene);
    return scene;
  } catch (const SceneKeyError& error) {
    if (!error.unknown_key()) throw;
    for (const SceneOverride& override_ : parsed) {
      const std::string& key = error.key_path();
      if (override_.path == key || override_.path.rfind(key + ".", 0) == 0) {
        throw InputError("--set " + override_.path + ": unknown key " + key);
      }
    }
    throw;
  }
}

std::vector<DirichletSpec> Scene::dirichlet_groups() const {
  std::vector<DirichletSpec> groups = fixed;
  groups.insert(groups.end(), prescribed.begin(), prescribed.end());
  return groups;
}

}  // namespace strata::app
