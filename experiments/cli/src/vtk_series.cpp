#include "strata/app/vtk_series.hpp"

#include <algorithm>
#include <cstdio>
#include <regex>

#include "strata/core/io/vtp.hpp"
#include "strata/core/io/vtu.hpp"

namespace strata::app {
namespace {

/// Removes the frames of an older run and returns the .pvd path.
std::filesystem::path prepare_series(const std::filesystem::path& folder, const std::string& stem) {
  std::error_code error;
  if (!std::filesystem::is_directory(folder, error)) return folder / (stem + ".pvd");
  const std::regex frame_name(
      std::regex_replace(stem, std::regex(R"([.^$|()\[\]{}*+?\\])"), R"(\$&)") +
      R"((_surface)?_\d{6}\.vt[up])");
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    if (entry.is_regular_file() && std::regex_match(entry.path().filename().string(), frame_name)) {
      std::filesystem::remove(entry.path(), error);
    }
  }
  return folder / (stem + ".pvd");
}

}  // namespace

VtkSeries::VtkSeries(const std::filesystem::path& folder, const std::string& stem, bool mesh_frames,
                     VtkEncoding encoding)
    : m_folder(folder),
      m_stem(stem),
      m_pvd(prepare_series(folder, stem)),
      m_mesh_frames(mesh_frames),
      m_encoding(encoding) {}

void VtkSeries::write_frame(double time, const Simulation& simulation, const VectorXi* levels) {
  if (!m_mesh_frames) {
    ++m_frames;  // numbers the surface frames
    return;
  }
  const TetMesh& mesh = simulation.mesh();
  const MatrixX3d positions = unflatten(simulation.positions());
  const TetFields tet_fields = simulation.model().tet_fields(simulation.positions());
  VtuFields fields;
  fields.add_point_data("displacement", Eigen::MatrixXd(positions - mesh.vertices));
  fields.add_point_data("velocity", Eigen::MatrixXd(unflatten(simulation.velocities())));
  fields.add_cell_data("green_strain", Eigen::MatrixXd(tet_fields.green_strain));
  fields.add_cell_data("stress", Eigen::MatrixXd(tet_fields.cauchy_stress));
  fields.add_cell_data("von_mises", Eigen::MatrixXd(tet_fields.von_mises));
  if (simulation.has_obstacles()) {
    // The obstacles' forces on the DOFs (normal and friction), at the DOF vertices; a hanging
    // vertex's share is carried by the vertices it follows.
    const VectorXd on_mesh =
        simulation.embedded_model().at_dof_vertices(simulation.contact_forces());
    fields.add_point_data("contact_force", Eigen::MatrixXd(unflatten(on_mesh)));
  }
  if (simulation.is_plastic()) {
    fields.add_cell_data("plastic_strain",
                         Eigen::MatrixXd(simulation.plastic_state().equivalent_strain));
  }
  fields.add_cell_data("level", levels
                                    ? Eigen::MatrixXi(*levels)
                                    : Eigen::MatrixXi(Eigen::MatrixXi::Zero(mesh.tets.rows(), 1)));

  char name[32];
  std::snprintf(name, sizeof name, "_%06d.vtu", m_frames);
  const std::string file = m_stem + name;
  write_vtu(m_folder / file, positions, mesh.tets, fields, m_encoding, &m_mesh_arrays);
  m_pvd.add_frame(time, file);
  ++m_frames;
}

void VtkSeries::write_surface_frame(double time, ConstRef<MatrixX3d> positions,
                                    ConstRef<MatrixX3i> triangles, const VtuFields& fields) {
  char name[40];
  std::snprintf(name, sizeof name, "_surface_%06d.vtp", std::max(m_frames - 1, 0));
  const std::string file = m_stem + name;
  write_vtp(m_folder / file, positions, triangles, fields, m_encoding, &m_surface_arrays);
  m_pvd.add_frame(time, file, 1);
}

}  // namespace strata::app
