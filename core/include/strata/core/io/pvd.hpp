#pragma once
/// \file pvd.hpp
/// ParaView collection files (.pvd): a time series of .vtu (or .vtp) frames.
#include <filesystem>
#include <string>
#include <vector>

namespace strata {

/// One file of a .pvd collection.
struct PvdEntry {
  double time = 0.0;  ///< simulation time [s]
  std::string file;   ///< path relative to the .pvd folder (forward slashes)
  int part = 0;       ///< part index: e.g. 0 = volume mesh (.vtu), 1 = surface or contacts (.vtp)
};

/// Writes a .pvd that lists frames as they are produced. The whole file is rewritten atomically
/// after each `add_frame`, so a run that stops at any moment leaves a valid series of the frames
/// written so far. Construction writes an empty collection (overwriting an older series).
class PvdWriter {
 public:
  /// Throws InputError naming `pvd_path` if it cannot be written.
  explicit PvdWriter(std::filesystem::path pvd_path);

  /// Appends a frame and rewrites the .pvd. `file` is relative to the .pvd's folder; frames of
  /// different parts may share a time.
  void add_frame(double time, const std::string& file, int part = 0);

  const std::filesystem::path& path() const { return m_path; }
  const std::vector<PvdEntry>& entries() const { return m_entries; }

 private:
  void write() const;

  std::filesystem::path m_path;
  std::vector<PvdEntry> m_entries;
};

}  // namespace strata
