#pragma once
/// \file progress_bar.hpp
/// A one-line progress bar with ETA on stderr, redrawn at most ~10 times per second, and
/// optionally the same progress as a small file for other programs (`strata run
/// --progress-file`).
#include <chrono>
#include <filesystem>
#include <string>

namespace strata::app {

class ProgressBar {
 public:
  /// `enabled` false draws nothing (use `stderr_is_terminal() && !quiet`). A non-empty
  /// `file` is rewritten at most twice a second with one line, "<fraction done> <seconds
  /// elapsed>", whether or not the bar is drawn; it is written once at construction ("0 0"),
  /// which throws InputError if it cannot be (a missing folder, a folder of that name).
  explicit ProgressBar(bool enabled, std::filesystem::path file = {});
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// Shows `fraction` ∈ [0, 1] done, with `label` (e.g. "t = 0.25 s") after the bar.
  void update(double fraction, const std::string& label);
  /// Erases the bar (call before printing anything else to stderr).
  void clear();

 private:
  /// Rewrites the file; returns why it could not, or an empty string.
  std::string write_file(double fraction, double elapsed);

  bool m_enabled;
  bool m_drawn = false;
  std::filesystem::path m_file;
  std::chrono::steady_clock::time_point m_start;
  std::chrono::steady_clock::time_point m_last_draw;
  std::chrono::steady_clock::time_point m_last_write;
};

/// Whether stderr is a terminal.
bool stderr_is_terminal();

/// "1.5 s", "2 min 05 s", "1 h 02 min".
std::string format_duration(double seconds);

}  // namespace strata::app
