#pragma once
// Malloc tuned for the planning's large arrays. The planning allocates large arrays (a SkullFix
// CT as floats, its surface, grids of millions of voxels) and touches each page once: with 4 KB
// pages the kernel serves a page fault per 4 KB, and on virtual machines those are dear
// (docs/decisions/0030-memory-huge-pages-one-arena-no-copies.md). glibc's malloc asks for
// transparent huge pages (2 MB) when its tunable glibc.malloc.hugetlb=1 is set (the kernel
// takes the advice unless its mode is "never"). With glibc.malloc.arena_max=1 the worker
// threads allocate from the main heap, whose memory is kept and reused, instead of arenas of
// their own that are given back to the kernel and faulted in again at the next parallel loop
// (what each gains: docs/BENCHMARKS.md, "Memory in huge pages, one malloc arena"). Tunables are
// read when a process starts, so the programs start themselves once more with them. The
// allocations change, not the arithmetic: the same implant bytes either way (tested). The
// installed programs are small launchers (app/launcher.cpp) that set the tunables before the
// program and its libraries are loaded; run directly, a program starts itself again.
#include <optional>
#include <string>

namespace cranioplan {

/// The GLIBC_TUNABLES value to start again with, given the present one (null when unset) and
/// CRANIOPLAN_HUGE_PAGES's (null when unset): the present one with glibc.malloc.hugetlb=1 and
/// glibc.malloc.arena_max=1 added, each unless it names that tunable already (the second
/// start, or the user's own choice); nothing when it names both or when CRANIOPLAN_HUGE_PAGES is
/// "0".
std::optional<std::string> huge_page_tunables(const char* glibc_tunables,
                                              const char* cranioplan_huge_pages);

/// Sets GLIBC_TUNABLES to huge_page_tunables's value for the programs this process starts, when
/// it gives one; whether it did.
bool ask_for_huge_pages();

/// Starts this program again (same arguments and environment) with huge_page_tunables's value
/// of GLIBC_TUNABLES, when it gives one; returns (and the program goes on as it is) when not, or
/// when starting again fails. Call it first thing in main, before any thread or file is opened.
void start_with_huge_pages(char** argv);

}  // namespace cranioplan
