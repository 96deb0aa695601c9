#pragma once
/// \file run_outputs.hpp
/// The table outputs of a run: probes.csv and reactions.csv.
///
/// Rows are kept in memory and each file is rewritten atomically (write_file_atomically), at most
/// every `save_interval` seconds of wall time while the run goes and always by `save()`: a reader
/// (or a killed run) never sees a half-written file, and the run's cost stays linear in its rows.
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "strata/core/mesh/point_location.hpp"
#include "strata/core/mesh/tet_mesh.hpp"
#include "strata/core/sim/simulation.hpp"

namespace strata::app {

/// Throws InputError unless `folder` can be an output folder: it is a folder or does not exist
/// yet, and no part of its path is a file. Creates nothing; a run calls it before its set-up.
void check_output_folder(const std::filesystem::path& folder);

/// A run's output folder, created and held for the run: a second run into the same folder while
/// this one holds it is refused (an advisory lock on `.strata.lock` inside it, released when the
/// run ends, however it ends).
class OutputFolder {
 public:
  /// Creates `folder` if needed and takes it; throws InputError if it cannot be created or
  /// another run holds it. A folder it created is removed again if it is destroyed by an
  /// exception while it holds nothing but the lock file (a run that failed before writing any
  /// output); folders above it that it created stay.
  explicit OutputFolder(const std::filesystem::path& folder);
  ~OutputFolder();
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

 private:
  std::filesystem::path m_folder;
  std::filesystem::path m_lock_path;
  int m_exceptions = 0;  ///< uncaught exceptions at construction
  bool m_created = false;
  int m_lock = -1;
};

/// A CSV file with a header line, rewritten atomically as rows accumulate.
class CsvSeries {
 public:
  CsvSeries(std::filesystem::path path, std::string header, double save_interval = 2.0);

  void add_row(std::string row);
  /// Rewrites the file if `save_interval` seconds passed since the last write.
  void save_if_due();
  /// Rewrites the file now.
  void save();

  const std::filesystem::path& path() const { return m_path; }
  std::size_t num_rows() const { return m_rows.size(); }

 private:
  std::filesystem::path m_path;
  std::string m_header;
  std::vector<std::string> m_rows;
  double m_save_interval;
  std::chrono::steady_clock::time_point m_last_save;
};

/// probes.csv: `time,probe,x,y,z,ux,uy,uz`, one row per probe and frame; (x, y, z) is the probe's
/// rest position and u the displacement of that material point, interpolated linearly
/// (barycentric) in its rest tet.
class ProbeRecorder {
 public:
  /// `probes` are rest positions, `locations` their tets (locate_points), same order.
  ProbeRecorder(const std::filesystem::path& path, const TetMesh& rest_mesh,
                std::vector<Vector3d> probes, std::vector<TetLocation> locations);

  /// Adds the rows of one frame: `displacement` is x − X, 3·#V.
  void record(double time, ConstRef<VectorXd> displacement);
  /// Adds the rows of one frame from the probes' displacements (#probes × 3), computed elsewhere
  /// (e.g. on the active cut of a refinement tree).
  void record_displacements(double time, ConstRef<MatrixX3d> displacements);
  CsvSeries& csv() { return m_csv; }

  /// Displacement of probe `i` for a 3·#V displacement vector.
  Vector3d probe_displacement(std::size_t i, ConstRef<VectorXd> displacement) const;

 private:
  CsvSeries m_csv;
  MatrixX4i m_tets;
  std::vector<Vector3d> m_probes;
  std::vector<TetLocation> m_locations;
};

/// reactions.csv: `time,group,fx,fy,fz,mx,my,mz`, one row per Dirichlet group (scene order, fixed
/// groups first) and frame.
class ReactionRecorder {
 public:
  explicit ReactionRecorder(const std::filesystem::path& path);
  void record(double time, const std::vector<GroupReaction>& reactions);
  CsvSeries& csv() { return m_csv; }

 private:
  CsvSeries m_csv;
};

/// Formats a double in the shortest round-trip form.
std::string format_double(double value);

}  // namespace strata::app
