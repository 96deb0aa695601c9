#pragma once
/// \file huge_pages.hpp
/// Transparent huge pages for the heap of a run. The first write to each 4 KiB page of fresh memory
/// is a page fault; a run touches its matrices, patterns and assembly plans once when it builds
/// them, and on a virtual machine a fault can cost about 10 µs (2.5 ms per MiB: 4 s of a 13 s
/// full-resolution run of 786k tets were faults). glibc's malloc backs its memory with 2 MiB
/// transparent huge pages, 512 times fewer faults, when the process starts with
/// `glibc.malloc.hugetlb=1` in GLIBC_TUNABLES (glibc ≥ 2.35) and the kernel's THP mode is
/// `madvise`. glibc reads the variable only at start-up, so the CLI re-executes itself with it.
#include <string>

namespace strata::app {

/// The heap this process runs on, for stats.json: "on" (glibc.malloc.hugetlb=1 on a kernel in
/// `madvise` mode), "always (kernel)" (the kernel gives huge pages to all memory), "off", or the
/// tunable as the user set it to another value (e.g. "glibc.malloc.hugetlb=2": hugetlbfs pages).
std::string huge_page_heap_state();

/// Re-executes this program (its path from /proc/self/exe, the same arguments and environment)
/// with `glibc.malloc.hugetlb=1` added to GLIBC_TUNABLES. It does not (and returns) when
/// GLIBC_TUNABLES already names that tunable (whatever its value), STRATA_HUGE_PAGES is `0`,
/// glibc is older than 2.35, the kernel's THP mode is not `madvise` (`always` needs nothing,
/// `never` allows nothing, no sysfs file: no THP), the process runs in secure-execution mode or
/// was started by invoking the dynamic loader, or the exec fails.
void use_huge_page_heap(char** argv);

}  // namespace strata::app
