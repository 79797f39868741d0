#pragma once
// Benchmark support: wall time since a point and the process's peak resident memory.
#include <sys/resource.h>

#include <chrono>

namespace vitri::bench {

using Clock = std::chrono::steady_clock;

/// Seconds from t to now.
inline double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// Peak resident memory of this process so far, in MB (getrusage; Linux reports kilobytes).
inline double peak_mb() {
  rusage r{};
  getrusage(RUSAGE_SELF, &r);
  return static_cast<double>(r.ru_maxrss) / 1024.0;
}

}  // namespace vitri::bench
