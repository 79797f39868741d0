#pragma once
// The library's meaning of "threads = 0": every CPU this process may run on.
#include <algorithm>
#include <thread>

#if defined(__linux__)
#include <sched.h>
#endif

namespace vitri {

/// The number of CPUs this process may run on (at least 1): its CPU affinity mask where the system
/// reports one (Linux: `taskset`, a container's cpuset), else std::thread::hardware_concurrency().
/// Every option `threads = 0` of the library resolves to this, so a process pinned to 4 of 16 cores
/// starts 4 workers, not 16.
inline unsigned available_cpus() {
#if defined(__linux__) && defined(CPU_COUNT)
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) {
    const int n = CPU_COUNT(&set);
    if (n > 0) return unsigned(n);
  }
#endif
  return std::max(1u, std::thread::hardware_concurrency());
}

/// `requested`, or available_cpus() when it is 0.
inline unsigned resolve_thread_count(unsigned requested) { return requested ? requested : available_cpus(); }

}  // namespace vitri
