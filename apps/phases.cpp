// PhaseTimes (phases.hpp).
#include "phases.hpp"

#include <sys/resource.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace vitri::cli {

void PhaseTimes::start(const std::string& name, const std::string& text) {
  stop();
  std::size_t k = 0;
  while (k < phases_.size() && phases_[k].name != name) ++k;
  if (k == phases_.size()) phases_.push_back({name, 0.0});
  running_ = k;
  phase_start_ = Clock::now();
  phase_cpu_start_ = cpu_seconds();
  if (!quiet_) std::fprintf(stderr, "[%7.1f s] %s...\n", elapsed(), (text.empty() ? name : text).c_str());
}

void PhaseTimes::stop() {
  if (running_ >= phases_.size()) return;
  phases_[running_].seconds += std::chrono::duration<double>(Clock::now() - phase_start_).count();
  phases_[running_].cpu_seconds += cpu_seconds() - phase_cpu_start_;
  release_free_memory();
  phases_[running_].peak_rss = peak_rss_bytes();
  phases_[running_].rss = current_rss_bytes();
  running_ = static_cast<std::size_t>(-1);
}

double PhaseTimes::seconds(const std::string& name) const {
  for (const Phase& p : phases_)
    if (p.name == name) return p.seconds;
  return 0.0;
}

double PhaseTimes::elapsed() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

void PhaseTimes::print(std::FILE* out) const {
  const double total = elapsed();
  std::fprintf(out, "%-20s %10s %7s %10s %10s %10s\n", "phase", "wall s", "share", "CPU s", "peak GB", "held GB");
  for (const Phase& p : phases_)
    std::fprintf(out, "%-20s %10.2f %6.1f%% %10.2f %10.2f %10.2f\n", p.name.c_str(), p.seconds,
                 total > 0 ? 100.0 * p.seconds / total : 0.0, p.cpu_seconds, static_cast<double>(p.peak_rss) / 1e9,
                 static_cast<double>(p.rss) / 1e9);
  std::fprintf(out, "%-20s %10.2f %6.1f%% %10.2f\n", "total", total, 100.0, cpu_seconds() - cpu_start_);
  std::fprintf(out, "peak memory (RSS)    %10.2f GB\n", static_cast<double>(peak_rss_bytes()) / 1e9);
}

std::size_t peak_rss_bytes() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0;
  return static_cast<std::size_t>(u.ru_maxrss) * 1024;  // Linux: kilobytes
}

std::size_t current_rss_bytes() {
  std::FILE* f = std::fopen("/proc/self/status", "r");
  if (!f) return 0;
  char line[256];
  unsigned long long kb = 0;
  bool found = false;
  while (!found && std::fgets(line, sizeof line, f)) found = std::sscanf(line, "VmRSS: %llu kB", &kb) == 1;
  std::fclose(f);
  return found ? static_cast<std::size_t>(kb) * 1024 : 0;
}

void release_free_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

double cpu_seconds() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return 0.0;
  auto sec = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return sec(u.ru_utime) + sec(u.ru_stime);
}

}  // namespace vitri::cli
