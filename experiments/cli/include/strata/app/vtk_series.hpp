#pragma once
/// \file vtk_series.hpp
/// ParaView output of a run: `<stem>.pvd` plus one `<stem>_NNNNNN.vtu` per frame, with point data
/// displacement and velocity (#V × 3) and cell data green_strain and stress (Cauchy, Voigt 6:
/// xx yy zz xy yz xz), von_mises and level (0 for single-level meshes).
/// With a fine surface, each frame also has `<stem>_surface_NNNNNN.vtp` (same NNNNNN and time),
/// listed in the same .pvd as part 1 (the volume is part 0): ParaView shows both as blocks of one
/// multiblock dataset.
#include <filesystem>
#include <string>

#include "strata/core/io/pvd.hpp"
#include "strata/core/io/vtu.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata::app {

class VtkSeries {
 public:
  /// Removes frames `<stem>_NNNNNN.vtu` of an older run in `folder` and starts an empty .pvd.
  /// `mesh_frames` false: write_frame writes no .vtu (only the surface frames are kept). Frames are
  /// written in `encoding`.
  VtkSeries(const std::filesystem::path& folder, const std::string& stem, bool mesh_frames = true,
            VtkEncoding encoding = VtkEncoding::binary);

  /// Writes the simulation's current state as the next frame at `time` (load factor when static).
  /// `levels` (#T, optional): the tree level of each cell (active cut of a hierarchy); 0 without.
  void write_frame(double time, const Simulation& simulation, const VectorXi* levels = nullptr);

  /// Writes the fine surface of the last frame: `positions` #Vs × 3, `triangles` #F × 3 and point
  /// `fields`, as `<stem>_surface_NNNNNN.vtp`, part 1 of the .pvd at `time`.
  void write_surface_frame(double time, ConstRef<MatrixX3d> positions,
                           ConstRef<MatrixX3i> triangles, const VtuFields& fields);

  int num_frames() const { return m_frames; }
  const std::filesystem::path& pvd_path() const { return m_pvd.path(); }

 private:
  std::filesystem::path m_folder;
  std::string m_stem;
  PvdWriter m_pvd;
  int m_frames = 0;
  bool m_mesh_frames = true;
  VtkEncoding m_encoding = VtkEncoding::binary;
  /// The integer arrays of the last frames (mesh and surface): between cut changes they repeat.
  VtuArrayCache m_mesh_arrays, m_surface_arrays;
};

}  // namespace strata::app
