#include "strata/app/run_outputs.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <sstream>
#include <system_error>

#include "strata/core/common/error.hpp"
#include "strata/core/io/atomic_file.hpp"
#include "strata/core/io/number_text.hpp"

namespace strata::app {

void check_output_folder(const std::filesystem::path& folder) {
  if (folder.empty()) throw InputError("--out: the output folder must not be empty");
  // The folder itself, then each of its parents: the first that exists must be a folder.
  std::filesystem::path part = folder;
  while (!part.empty()) {
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::status(part, error);
    if (std::filesystem::exists(status)) {
      if (std::filesystem::is_directory(status)) return;
      throw InputError("output folder '" + folder.string() + "': '" + part.string() +
                       "' is a file, not a folder");
    }
    const std::filesystem::path parent = part.parent_path();
    if (parent == part) return;
    part = parent;
  }
}

OutputFolder::OutputFolder(const std::filesystem::path& folder)
    : m_folder(folder), m_exceptions(std::uncaught_exceptions()) {
  check_output_folder(folder);
  std::error_code error;
  m_created = !std::filesystem::exists(folder, error);
  std::filesystem::create_directories(folder, error);
  if (error)
    throw InputError("output folder '" + folder.string() + "': cannot create it (" +
                     error.message() + ")");
  m_lock_path = folder / ".strata.lock";
  m_lock = ::open(m_lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (m_lock < 0)
    throw InputError("output folder '" + folder.string() + "': cannot write in it (" +
                     std::strerror(errno) + ")");
  if (::flock(m_lock, LOCK_EX | LOCK_NB) != 0) {
    ::close(m_lock);
    m_lock = -1;
    throw InputError("output folder '" + folder.string() +
                     "': another strata run is writing to it (give each run its own --out)");
  }
}

OutputFolder::~OutputFolder() {
  // A run that failed before writing anything leaves no folder it created behind: the lock file
  // and the folder (only if empty) go while the lock is still held.
  if (m_lock >= 0 && m_created && std::uncaught_exceptions() > m_exceptions) {
    std::error_code error;
    std::filesystem::remove(m_lock_path, error);
    std::filesystem::remove(m_folder, error);
  }
  if (m_lock >= 0) ::close(m_lock);  // closing releases the lock
}

std::string format_double(double value) {
  std::ostringstream out;
  write_double(out, value);
  return out.str();
}

CsvSeries::CsvSeries(std::filesystem::path path, std::string header, double save_interval)
    : m_path(std::move(path)),
      m_header(std::move(header)),
      m_save_interval(save_interval),
      m_last_save(std::chrono::steady_clock::now()) {}

void CsvSeries::add_row(std::string row) {
  m_rows.push_back(std::move(row));
}

void CsvSeries::save_if_due() {
  const auto now = std::chrono::steady_clock::now();
  if (std::chrono::duration<double>(now - m_last_save).count() >= m_save_interval) save();
}

void CsvSeries::save() {
  write_file_atomically(m_path, [this](std::ostream& out) {
    out << m_header << '\n';
    for (const std::string& row : m_rows)
      out << row << '\n';
  });
  m_last_save = std::chrono::steady_clock::now();
}

ProbeRecorder::ProbeRecorder(const std::filesystem::path& path, const TetMesh& rest_mesh,
                             std::vector<Vector3d> probes, std::vector<TetLocation> locations)
    : m_csv(path, "time,probe,x,y,z,ux,uy,uz"),
      m_tets(rest_mesh.tets),
      m_probes(std::move(probes)),
      m_locations(std::move(locations)) {}

Vector3d ProbeRecorder::probe_displacement(std::size_t i, ConstRef<VectorXd> displacement) const {
  const TetLocation& location = m_locations[i];
  Vector3d u = Vector3d::Zero();
  for (int k = 0; k < 4; ++k) {
    u += location.barycentric(k) * displacement.segment<3>(3 * m_tets(location.tet, k));
  }
  return u;
}

void ProbeRecorder::record(double time, ConstRef<VectorXd> displacement) {
  MatrixX3d u(static_cast<Index>(m_probes.size()), 3);
  for (std::size_t i = 0; i < m_probes.size(); ++i)
    u.row(static_cast<Index>(i)) = probe_displacement(i, displacement).transpose();
  record_displacements(time, u);
}

void ProbeRecorder::record_displacements(double time, ConstRef<MatrixX3d> displacements) {
  for (std::size_t i = 0; i < m_probes.size(); ++i) {
    const Vector3d u = displacements.row(static_cast<Index>(i)).transpose();
    std::ostringstream row;
    write_double(row, time);
    row << ',' << i;
    for (int a = 0; a < 3; ++a)
      row << ',' << format_double(m_probes[i](a));
    for (int a = 0; a < 3; ++a)
      row << ',' << format_double(u(a));
    m_csv.add_row(row.str());
  }
}

ReactionRecorder::ReactionRecorder(const std::filesystem::path& path)
    : m_csv(path, "time,group,fx,fy,fz,mx,my,mz") {}

void ReactionRecorder::record(double time, const std::vector<GroupReaction>& reactions) {
  for (std::size_t g = 0; g < reactions.size(); ++g) {
    std::ostringstream row;
    write_double(row, time);
    row << ',' << g;
    for (int a = 0; a < 3; ++a)
      row << ',' << format_double(reactions[g].force(a));
    for (int a = 0; a < 3; ++a)
      row << ',' << format_double(reactions[g].moment(a));
    m_csv.add_row(row.str());
  }
}

}  // namespace strata::app
