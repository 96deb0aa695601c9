#include "strata/app/progress_bar.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <system_error>
#include <utility>

#include "strata/core/common/error.hpp"

namespace strata::app {

bool stderr_is_terminal() {
  return isatty(STDERR_FILENO) == 1;
}

std::string format_duration(double seconds) {
  char text[64];
  if (!std::isfinite(seconds) || seconds < 0.0) return "?";
  if (seconds < 60.0) {
    std::snprintf(text, sizeof text, "%.1f s", seconds);
  } else if (seconds < 3600.0) {
    const int s = static_cast<int>(seconds);
    std::snprintf(text, sizeof text, "%d min %02d s", s / 60, s % 60);
  } else {
    const int m = static_cast<int>(seconds / 60.0);
    std::snprintf(text, sizeof text, "%d h %02d min", m / 60, m % 60);
  }
  return text;
}

ProgressBar::ProgressBar(bool enabled, std::filesystem::path file)
    : m_enabled(enabled),
      m_file(std::move(file)),
      m_start(std::chrono::steady_clock::now()),
      m_last_draw(m_start),
      m_last_write(m_start) {
  if (m_file.empty()) return;
  const std::string problem = write_file(0.0, 0.0);
  if (!problem.empty())
    throw InputError("--progress-file '" + m_file.string() + "': cannot write it (" + problem +
                     ")");
}

ProgressBar::~ProgressBar() {
  clear();
}

std::string ProgressBar::write_file(double fraction, double elapsed) {
  // Written beside and renamed over the file, so that a reader never sees it half-written.
  std::filesystem::path part = m_file;
  part += ".part";
  {
    std::ofstream out(part, std::ios::trunc);
    if (!out) {
      std::error_code error;
      const std::filesystem::path folder =
          m_file.parent_path().empty() ? std::filesystem::path(".") : m_file.parent_path();
      return std::filesystem::is_directory(folder, error) ? "not writable"
                                                          : "no folder '" + folder.string() + "'";
    }
    out << fraction << ' ' << elapsed << '\n';
    if (!out) return "write failed";
  }
  std::error_code error;
  std::filesystem::rename(part, m_file, error);
  if (error) {
    std::filesystem::remove(part, error);
    return std::filesystem::is_directory(m_file, error) ? "it is a folder"
                                                        : "cannot rename onto it";
  }
  return {};
}

void ProgressBar::update(double fraction, const std::string& label) {
  const auto now = std::chrono::steady_clock::now();
  if (!m_file.empty() &&
      (now - m_last_write >= std::chrono::milliseconds(500) || fraction >= 1.0)) {
    m_last_write = now;
    write_file(std::clamp(fraction, 0.0, 1.0),
               std::chrono::duration<double>(now - m_start).count());
  }
  if (!m_enabled) return;
  if (m_drawn && now - m_last_draw < std::chrono::milliseconds(100) && fraction < 1.0) return;
  m_last_draw = now;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const double elapsed = std::chrono::duration<double>(now - m_start).count();
  const std::string eta =
      fraction > 0.0 ? format_duration(elapsed * (1.0 - fraction) / fraction) : std::string("?");
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(fraction * kWidth);
  std::string bar(kWidth, ' ');
  std::fill(bar.begin(), bar.begin() + filled, '=');
  if (filled < kWidth) bar[filled] = '>';
  std::fprintf(stderr, "\r[%s] %3d%%  %s  ETA %s\033[K", bar.c_str(),
               static_cast<int>(fraction * 100.0), label.c_str(), eta.c_str());
  std::fflush(stderr);
  m_drawn = true;
}

void ProgressBar::clear() {
  if (!m_enabled || !m_drawn) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
  m_drawn = false;
}

}  // namespace strata::app
