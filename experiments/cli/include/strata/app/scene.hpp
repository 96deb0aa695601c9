#pragma once
/// \file scene.hpp
/// A simulation scene as read from a scene file (see scene_reference.md for every key). Plain data:
/// parsing and validation live in scene_parser.hpp, running in scene_runner.hpp.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/sim/region.hpp"

namespace strata::app {

/// "mesh": either a mesh file or a procedural box.
struct MeshSpec {
  std::optional<std::filesystem::path> file;  ///< absolute or relative to the scene's folder
  Vector3d box_min = Vector3d::Zero();        ///< used when `file` is empty [m]
  Vector3d box_max = Vector3d::Ones();        ///< [m]
  std::array<int, 3> box_cells{1, 1, 1};      ///< hexahedral cells per axis (6 tets each)
};

/// A "prescribed" entry: the region's vertices follow a displacement or a rigid rotation.
struct PrescribedSpec {
  Region region;
  bool is_rotation = false;
  Vector3d displacement = Vector3d::Zero();  ///< [m], when !is_rotation
  Vector3d axis = Vector3d::UnitZ();         ///< rotation axis (normalised), when is_rotation
  Vector3d center = Vector3d::Zero();        ///< rotation center [m]
  double angle_degrees = 0.0;                ///< full rotation angle [°]
};

/// A "forces" entry: a dead load spread as uniform traction over the region's boundary faces.
struct ForceSpec {
  Region region;
  Vector3d total_force = Vector3d::Zero();  ///< [N]
};

/// "ground": a frictional half-space the body cannot penetrate.
struct GroundSpec {
  Vector3d point = Vector3d::Zero();
  Vector3d normal = Vector3d::UnitZ();  ///< normalised, points out of the ground
  double friction = 0.0;                ///< Coulomb coefficient μ ≥ 0
};

enum class SolverMode { dynamic, quasi_static };
enum class IntegratorKind { symplectic_euler, rk4, implicit_euler };

/// Scene-file names: "dynamic", "static"; "symplectic_euler", "rk4", "implicit_euler".
std::string to_string(SolverMode mode);
std::string to_string(IntegratorKind kind);

/// "solver".
struct SolverSpec {
  SolverMode mode = SolverMode::dynamic;
  IntegratorKind integrator = IntegratorKind::implicit_euler;
  double dt = 0.0;                 ///< time step [s] (dynamic)
  double duration = 0.0;           ///< simulated time [s] (dynamic)
  int load_steps = 10;             ///< equal load increments (static)
  double newton_tolerance = 1e-8;  ///< relative residual-force tolerance of Newton solves
  int max_newton_iterations = 50;  ///< per step / load increment
};

/// "output".
struct OutputSpec {
  int every = 1;                 ///< write a frame every this many steps (and the last one)
  std::vector<Vector3d> probes;  ///< rest positions of tracked material points [m]
  bool vtk = true;               ///< write <stem>.pvd + one .vtu per frame
};

/// A whole scene.
struct Scene {
  std::filesystem::path file;  ///< the scene file (as given)
  std::string name;            ///< its stem, e.g. "cantilever"
  MeshSpec mesh;
  Material material;
  Vector3d gravity = Vector3d::Zero();  ///< [m/s²]
  std::vector<Region> fixed;
  std::vector<PrescribedSpec> prescribed;
  std::vector<ForceSpec> forces;
  std::optional<GroundSpec> ground;
  SolverSpec solver;
  OutputSpec output;
};

}  // namespace strata::app
