#include "strata/app/huge_pages.hpp"

#include <gnu/libc-version.h>
#include <limits.h>
#include <sys/auxv.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>

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

/// The value glibc applies for the tunable (its last `name=value` in GLIBC_TUNABLES), or "" when
/// the variable does not set it.
std::string tunable_value(const std::string& tunables) {
  const std::string key = std::string(kTunable) + "=";
  std::string value;
  std::size_t start = 0;
  while (start <= tunables.size()) {
    const std::size_t end = std::min(tunables.find(':', start), tunables.size());
    const std::string entry = tunables.substr(start, end - start);
    if (entry.compare(0, key.size(), key) == 0) value = entry.substr(key.size());
    start = end + 1;
  }
  return value;
}

}  // namespace

std::string huge_page_heap_state() {
  const std::string mode = thp_mode();
  if (mode == "always") return "always (kernel)";
  const std::string value = tunable_value(environment("GLIBC_TUNABLES"));
  if (value.empty() || value == "0") return "off";
  if (value == "1" && mode == "madvise" && glibc_has_hugetlb_tunable()) return "on";
  return std::string(kTunable) + "=" + value;
}

void use_huge_page_heap(char** argv) {
  const bool tunables_set = std::getenv("GLIBC_TUNABLES") != nullptr;
  const std::string tunables = environment("GLIBC_TUNABLES");
  if (tunables.find(kTunable) != std::string::npos) return;
  if (environment("STRATA_HUGE_PAGES") == "0") return;
  if (!glibc_has_hugetlb_tunable() || thp_mode() != "madvise") return;
  // A secure-execution process (setuid, capabilities) has its tunables filtered, so the
  // re-executed one would not see the tunable either; a program started by invoking the dynamic
  // loader (no interpreter of its own: AT_BASE is 0) is not what /proc/self/exe names.
  if (getauxval(AT_SECURE) != 0 || getauxval(AT_BASE) == 0) return;
  // The program's own path, so that the process keeps its name (exec of /proc/self/exe would
  // name it "exe").
  char path[PATH_MAX];
  const ssize_t length = readlink("/proc/self/exe", path, sizeof(path) - 1);
  if (length <= 0) return;
  path[length] = '\0';
  const std::string value = (tunables.empty() ? "" : tunables + ":") + std::string(kTunable) + "=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv(path, argv);
  // The exec failed: run on as started, without the tunable.
  if (tunables_set)
    setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
  else
    unsetenv("GLIBC_TUNABLES");
}

}  // namespace strata::app
