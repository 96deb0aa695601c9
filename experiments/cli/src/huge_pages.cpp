#include "strata/app/huge_pages.hpp"

#include <gnu/libc-version.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace strata::app {
namespace {

constexpr const char* kTunable = "glibc.malloc.hugetlb";

std::string environment(const char* name) {
  const char* value = std::getenv(name);
  return value != nullptr ? value : "";
}

/// The kernel's THP mode: the bracketed word of /sys/kernel/mm/transparent_hugepage/enabled
/// ("always", "madvise" or "never"), or "" when the file is missing.
std::string thp_mode() {
  std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  if (!std::getline(file, line)) return "";
  const auto open = line.find('[');
  const auto close = line.find(']', open);
  if (open == std::string::npos || close == std::string::npos) return "";
  return line.substr(open + 1, close - open - 1);
}

bool glibc_has_hugetlb_tunable() {
  int major = 0, minor = 0;
  if (std::sscanf(gnu_get_libc_version(), "%d.%d", &major, &minor) != 2) return false;
  return major > 2 || (major == 2 && minor >= 35);
}

}  // namespace

std::string huge_page_heap_state() {
  const std::string tunables = environment("GLIBC_TUNABLES");
  const auto at = tunables.find(std::string(kTunable) + "=");
  const std::string mode = thp_mode();
  if (mode == "always") return "always (kernel)";
  if (at == std::string::npos) return "off";
  std::istringstream rest(tunables.substr(at + std::string(kTunable).size() + 1));
  std::string value;
  std::getline(rest, value, ':');
  if (value == "0" || mode != "madvise" || !glibc_has_hugetlb_tunable()) return "off";
  return "on";
}

void use_huge_page_heap(char** argv) {
  const std::string tunables = environment("GLIBC_TUNABLES");
  if (tunables.find(kTunable) != std::string::npos) return;
  if (environment("STRATA_HUGE_PAGES") == "0") return;
  if (!glibc_has_hugetlb_tunable() || thp_mode() != "madvise") return;
  const std::string value = (tunables.empty() ? "" : tunables + ":") + std::string(kTunable) + "=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // The exec failed: run on as started, without the tunable.
  if (tunables.empty())
    unsetenv("GLIBC_TUNABLES");
  else
    setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
}

}  // namespace strata::app
