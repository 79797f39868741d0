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
/// Resident memory of this process now, in bytes (VmRSS of /proc/self/status; 0 where unknown).
std::size_t current_rss_bytes();
/// Gives the heap's free pages back to the system (glibc's malloc_trim; nothing elsewhere). A phase's
/// freed memory otherwise stays resident in the arena of the thread that freed it (the fit's worker
/// threads, the seeds' insertion threads), where the next phase's allocations on other threads do not
/// reuse it: the resident memory, and the peak, grow by it (docs/memory.md).
void release_free_memory();
/// CPU seconds (user + system, all threads) of this process so far (getrusage; 0 where unknown).
double cpu_seconds();

class PhaseTimes {
 public:
  /// quiet: nothing is announced (the times are still kept).
  explicit PhaseTimes(bool quiet) : quiet_(quiet), start_(Clock::now()), cpu_start_(cpu_seconds()) {}
  /// Ends the running phase and starts `name`, announced on stderr as "[elapsed] text..." (text
  /// defaults to the name). Phases of the same name add up in the table.
  void start(const std::string& name, const std::string& text = "");
  /// Ends the running phase (no-op when none runs), giving the heap's free pages back
  /// (release_free_memory()).
  void stop();
  /// Seconds of phase `name` so far (0 when it never ran).
  double seconds(const std::string& name) const;
  /// Seconds since construction.
  double elapsed() const;
  /// The table: one row per phase (wall seconds, share of the total wall time, CPU seconds of all
  /// threads: on a loaded machine the CPU time says what the phase costs, the wall time what it took;
  /// the process's peak resident memory when the phase ended: the first phase whose value jumps is the
  /// one that needed the memory; and the resident memory at its end, free pages given back: what the
  /// phase left held), the totals and the peak resident memory (getrusage).
  void print(std::FILE* out) const;

 private:
  using Clock = std::chrono::steady_clock;
  struct Phase {
    std::string name;
    double seconds = 0;      // wall
    double cpu_seconds = 0;  // CPU time of the process (all threads)
    std::size_t peak_rss = 0;  // peak resident memory of the process when the phase last ended
    std::size_t rss = 0;       // resident memory of the process when the phase last ended
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
