#pragma once
/// Refusing a mesh the machine cannot hold before it is built.
#include <unistd.h>

#include <cstdio>
#include <string>

#include "strata/core/common/error.hpp"

namespace strata::app {

/// Memory a run takes per tet, about: an implicit step of a 384k-tet box peaked at 849 MB
/// (README, "Solver: measured"), 2.2 kB per tet.
inline constexpr double kBytesPerTet = 2.2e3;

/// InputError "`what`: about N tets would need about X GB; this machine has Y GB" when `tets`
/// tets would take more than the machine's physical memory.
inline void check_fits_in_memory(double tets, const std::string& what) {
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page_size <= 0) return;
  const double memory = static_cast<double>(pages) * static_cast<double>(page_size);
  const double needed = tets * kBytesPerTet;
  if (needed <= memory) return;
  char text[160];
  std::snprintf(text, sizeof(text),
                ": about %.3g tets would need about %.3g GB; this machine has %.3g GB", tets,
                needed / 1e9, memory / 1e9);
  throw InputError(what + text);
}

}  // namespace strata::app
