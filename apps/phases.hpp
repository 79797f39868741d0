#pragma once
// PhaseTimes: the wall time of the phases of a long command, announced on stderr as they start and
// printed as a table at the end (with the peak resident memory of the process).
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

namespace vitri::cli {

/// Peak resident memory of this process so far, in bytes (getrusage; 0 where unknown).
std::size_t peak_rss_bytes();
/// CPU seconds (user + system, all threads) of this process so far (getrusage; 0 where unknown).
double cpu_seconds();

class PhaseTimes {
 public:
  /// quiet: nothing is announced (the times are still kept).
  explicit PhaseTimes(bool quiet) : quiet_(quiet), start_(Clock::now()), cpu_start_(cpu_seconds()) {}
  /// Ends the running phase and starts `name`, announced on stderr as "[elapsed] text..." (text defaults
  /// to the name). Phases of the same name add up in the table.
  void start(const std::string& name, const std::string& text = "");
  /// Ends the running phase (no-op when none runs).
  void stop();
  /// Seconds of phase `name` so far (0 when it never ran).
  double seconds(const std::string& name) const;
  /// Seconds since construction.
  double elapsed() const;
  /// The table: one row per phase (wall seconds, share of the total wall time, CPU seconds of all
  /// threads: on a loaded machine the CPU time says what the phase costs, the wall time what it took;
  /// the process's peak resident memory when the phase ended: the first phase whose value jumps is the
  /// one that needed the memory), the totals and the peak resident memory (getrusage).
  void print(std::FILE* out) const;

 private:
  using Clock = std::chrono::steady_clock;
  struct Phase {
    std::string name;
    double seconds = 0;      // wall
    double cpu_seconds = 0;  // CPU time of the process (all threads)
    std::size_t peak_rss = 0;  // peak resident memory of the process when the phase last ended
  };
  bool quiet_;
  Clock::time_point start_;
  double cpu_start_;
  Clock::time_point phase_start_{};
  double phase_cpu_start_ = 0;
  std::size_t running_ = static_cast<std::size_t>(-1);  // index into phases_, or none
  std::vector<Phase> phases_;
};

}  // namespace vitri::cli
