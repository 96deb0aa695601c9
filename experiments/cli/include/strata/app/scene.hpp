#pragma once
/// \file scene.hpp
/// A simulation scene as read from a scene file (README.md, "Scene file and CLI reference",
/// documents every key). Plain data in the core's own types: parsing lives in scene_parser.hpp,
/// running in scene_runner.hpp.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "strata/core/common/types.hpp"
#include "strata/core/fem/material.hpp"
#include "strata/core/io/vtu.hpp"
#include "strata/core/sim/dirichlet.hpp"
#include "strata/core/sim/ground_contact.hpp"
#include "strata/core/sim/loads.hpp"
#include "strata/core/sim/solver_settings.hpp"
#include "strata/core/sim/spring_body.hpp"
#include "strata/hierarchy/adaptive_simulation.hpp"
#include "strata/meshing/implicit_shape.hpp"
#include "strata/meshing/meshing_options.hpp"

namespace strata::app {

/// "mesh": a tet mesh file, a procedural box, or a solid to tetrahedralise (a surface, a .vdb
/// level set or an implicit CSG shape); exactly one of file, box, surface, level_set, implicit.
struct MeshSpec {
  std::optional<std::filesystem::path> file;  ///< absolute, or relative to the working folder
  /// Closed surface (.off, .obj, .ply, .stl) meshed with CGAL Mesh_3 using `meshing`; absolute, or
  /// relative to the working folder.
  std::optional<std::filesystem::path> surface;
  /// OpenVDB level set (.vdb) whose inside (φ < 0) is meshed using `meshing`; absolute, or
  /// relative to the working folder.
  std::optional<std::filesystem::path> level_set;
  std::string grid;  ///< float grid of `level_set` to mesh; empty: the file's first float grid
  /// Implicit primitives and CSG meshed through a level set using `meshing`.
  std::optional<ImplicitShape> implicit;
  double voxel_size = 0.0;  ///< voxels of `implicit` [m]; 0: implicit_voxel_size(meshing)
  MeshingOptions meshing;   ///< used with surface, level_set or implicit
  Vector3d box_min = Vector3d::Zero();    ///< used when `file` is empty [m]
  Vector3d box_max = Vector3d::Ones();    ///< [m]
  std::array<int, 3> box_cells{1, 1, 1};  ///< hexahedral cells per axis (6 tets each)
};

/// One entry of "obstacles": a rigid body the contact points contact (obstacle.hpp); exactly
/// one of plane, implicit, level_set, surface.
struct ObstacleSpec {
  std::string name;  ///< its key path, "obstacles.0"
  std::optional<Vector3d> plane_point, plane_normal;
  std::optional<ImplicitShape> implicit;
  std::optional<std::filesystem::path> level_set;  ///< .vdb
  std::string grid;                                ///< grid of `level_set`; empty: the first
  std::optional<std::filesystem::path> surface;    ///< closed surface turned into a level set
  double voxel_size = 0.0;  ///< implicit / surface voxels [m]; 0: half the mesh's mean edge
  double friction = 0.0;
  Vector3d velocity = Vector3d::Zero();  ///< "motion": {"velocity"} [m/s]
};

/// "body": the body model — tets (the mesh; default) or skeleton springs on mesh.surface
/// (spring_body.hpp).
struct BodySpec {
  bool skeleton_springs = false;
  SpringBodyRule rule;
  /// skeleton_springs: the springs live on mesh.surface simplified to at most this many vertices
  /// (surface_simplification.hpp) and carry the full surface; 0: on mesh.surface itself.
  Index surface_vertices = 2000;
};

/// "output".
struct OutputSpec {
  int every = 1;                 ///< write a frame every this many steps (and after the last)
  std::vector<Vector3d> probes;  ///< rest positions of tracked material points [m]
  bool vtk = true;               ///< write <stem>.pvd + one .vtu per frame
  /// With vtk: the simulation mesh's .vtu frames too; false ("vtk": "surface"): only the bound
  /// fine surface's .vtp frames.
  bool vtk_mesh = true;
  /// "vtk_encoding": how the frames store their arrays ("binary": appended, zlib-compressed).
  VtkEncoding vtk_encoding = VtkEncoding::binary;
};

/// A whole scene. Dirichlet groups are named by their key paths ("fixed.0", "prescribed.1"),
/// loads likewise ("forces.0"), so errors of the core name the scene key.
struct Scene {
  std::filesystem::path file;  ///< the scene file (as given)
  std::string name;            ///< its stem, e.g. "cantilever"
  MeshSpec mesh;
  Material material;
  /// "material.surface_springs": yielding springs on the surface (surface_springs.hpp); runs
  /// without `hierarchy` only.
  std::optional<SurfaceSpringSettings> surface_springs;
  Vector3d gravity = Vector3d::Zero();    ///< [m/s²]
  std::vector<DirichletSpec> fixed;       ///< kind fixed
  std::vector<DirichletSpec> prescribed;  ///< kind displacement or rotation (angle in radians)
  std::vector<RegionLoad> forces;
  std::optional<GroundPlane> ground;
  SolverSettings solver;
  OutputSpec output;
  /// "hierarchy": run on an active cut of a refinement tree over the mesh (full, uniform or
  /// adaptive); absent: the mesh itself, as a plain Simulation.
  std::optional<HierarchySettings> hierarchy;
  std::vector<ObstacleSpec> obstacles;
  BodySpec body;
  /// Keys the scene gives that its run does not use ("solver.load_steps: applies to static runs
  /// only (ignored)"); the runner prints each as a warning.
  std::vector<std::string> ignored_keys;

  /// fixed groups first, then prescribed ones: the order of reactions.csv's `group` column.
  std::vector<DirichletSpec> dirichlet_groups() const;
};

}  // namespace strata::app
