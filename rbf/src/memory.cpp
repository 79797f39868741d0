// Memory needed by the dense fit, and the budget it is checked against (see RbfOptions::max_memory_bytes).
//
// What Rbf::fit allocates, read from rbf_fit.cpp: with the Cholesky solver, the factor L of the reduced
// (N - 4) x (N - 4) system with 1/8 headroom plus 16 rows for edits, column-major doubles (the system
// is assembled in place in L); with FullLu, the (N + 4)^2 saddle matrix and Eigen's LU copy of it. Both
// also keep O(N) arrays (scaled positions, weights, basis rows, permutations, residuals): a generous 512
// bytes per constraint covers them.

#include "memory.hpp"

#include "vitri/core/error.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

namespace vitri {

namespace {

constexpr double kPerConstraintBytes = 512.0;

std::string gigabytes(double bytes) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3g GB", bytes / 1e9);
  return buf;
}

}  // namespace

std::size_t rbf_fit_memory_bytes(std::size_t n, RbfSolver solver) {
  const double N = static_cast<double>(n);
  double bytes = 0;
  if (solver == RbfSolver::FullLu) {
    bytes = 2.0 * (N + 4) * (N + 4) * sizeof(double);
  } else {
    const double reduced = N > 4 ? N - 4 : 0;
    const double cap = reduced + std::floor(reduced / 8) + 16;
    bytes = cap * cap * sizeof(double);
  }
  return rbf_detail::saturated_bytes(bytes + kPerConstraintBytes * N);
}

std::size_t physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 0;
  return static_cast<std::size_t>(pages) * static_cast<std::size_t>(page);
}

std::size_t available_memory_bytes() {
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    unsigned long long kb = 0;
    bool found = false;
    while (!found && std::fgets(line, sizeof line, f)) found = std::sscanf(line, "MemAvailable: %llu kB", &kb) == 1;
    std::fclose(f);
    if (found) return static_cast<std::size_t>(kb) * 1024;
  }
  return physical_memory_bytes();
}

namespace rbf_detail {

std::size_t saturated_bytes(double bytes) {
  const double max = static_cast<double>(std::numeric_limits<std::size_t>::max());
  return bytes >= max ? std::numeric_limits<std::size_t>::max() : static_cast<std::size_t>(bytes);
}

std::size_t memory_budget(const RbfOptions& options) {
  return options.max_memory_bytes ? options.max_memory_bytes : physical_memory_bytes();
}

void require_memory(std::size_t bytes, const std::string& what, const RbfOptions& options) {
  const std::size_t limit = memory_budget(options);
  if (limit == 0 || bytes <= limit) return;
  const std::string source =
      options.max_memory_bytes ? "RbfOptions::max_memory_bytes" : "the physical memory";
  throw LimitError(
      what + " needs about " + gigabytes(static_cast<double>(bytes)) + " (" + std::to_string(bytes) +
      " bytes: the dense global RBF system grows as N^2), more than the limit of " +
      gigabytes(static_cast<double>(limit)) + " (" + std::to_string(limit) + " bytes, " + source +
      "); use the local function (--function local; vitri/rbf/local_rbf.hpp) for large inputs, or fewer "
      "constraints (ConstraintBuildOptions::max_constraints)");
}

}  // namespace rbf_detail

}  // namespace vitri
