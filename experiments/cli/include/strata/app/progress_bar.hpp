#pragma once
/// \file progress_bar.hpp
/// A one-line progress bar with ETA on stderr, redrawn at most ~10 times per second.
#include <chrono>
#include <string>

namespace strata::app {

class ProgressBar {
 public:
  /// `enabled` false makes every call a no-op (use `stderr_is_terminal() && !quiet`).
  explicit ProgressBar(bool enabled);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  /// Shows `fraction` ∈ [0, 1] done, with `label` (e.g. "t = 0.25 s") after the bar.
  void update(double fraction, const std::string& label);
  /// Erases the bar (call before printing anything else to stderr).
  void clear();

 private:
  bool m_enabled;
  bool m_drawn = false;
  std::chrono::steady_clock::time_point m_start;
  std::chrono::steady_clock::time_point m_last_draw;
};

/// Whether stderr is a terminal.
bool stderr_is_terminal();

/// "1.5 s", "2 min 05 s", "1 h 02 min".
std::string format_duration(double seconds);

}  // namespace strata::app
