// Tests of vitri/core/parallel.hpp: the library's one way of running work on threads.

#include "vitri/core/parallel.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

struct TaskError : std::runtime_error {
  explicit TaskError(std::size_t k) : std::runtime_error("task " + std::to_string(k)), task(k) {}
  std::size_t task;
};

}  // namespace

TEST_CASE("run_tasks runs every task once, on distinct threads, the first on the caller's", "[parallel]") {
  const std::size_t count = 5;
  std::vector<std::thread::id> ids(count);
  std::vector<int> runs(count, 0);
  vitri::run_tasks(count, [&](std::size_t k) {
    ids[k] = std::this_thread::get_id();
    ++runs[k];
  });
  CHECK(ids[0] == std::this_thread::get_id());
  for (std::size_t k = 0; k < count; ++k) {
    CHECK(runs[k] == 1);
    for (std::size_t j = 0; j < k; ++j) CHECK(ids[j] != ids[k]);
  }
  vitri::run_tasks(0, [&](std::size_t) { FAIL("no task expected"); });
}

TEST_CASE("a worker's exception reaches the caller after every task has ended", "[parallel]") {
  // Tasks 2 and 3 throw (on worker threads); the others keep running to the end. The caller gets task 2's
  // exception (the lowest index), after all five tasks have finished, and the process goes on.
  std::atomic<int> finished{0};
  std::size_t caught = 99;
  try {
    vitri::run_tasks(5, [&](std::size_t k) {
      if (k == 2 || k == 3) throw TaskError(k);
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      ++finished;
    });
  } catch (const TaskError& e) {
    caught = e.task;
    CHECK(finished.load() == 3);
  }
  CHECK(caught == 2);

  // The same through run_slices (the polygonizer's passes) and parallel_for: a slice on a worker thread.
  CHECK_THROWS_AS(vitri::run_slices(1000, 4,
                                    [](std::size_t s, std::size_t, std::size_t) {
                                      if (s == 3) throw TaskError(s);
                                    }),
                  TaskError);
  CHECK_THROWS_AS(vitri::parallel_for(
                      100000, 4, [](std::size_t i) {
                        if (i == 99999) throw TaskError(i);
                      }),
                  TaskError);
}

TEST_CASE("parallel_chunks carries a chunk's exception and skips the chunks not yet taken", "[parallel]") {
  std::atomic<std::size_t> done{0};
  CHECK_THROWS_AS(vitri::parallel_chunks(100000, 4, 10,
                                         [&](std::size_t b, std::size_t) {
                                           if (b == 500) throw TaskError(b);
                                           ++done;
                                         }),
                  TaskError);
  CHECK(done.load() < 10000);  // of 10^4 chunks, the ones after the failure were not run
}

TEST_CASE("run_slices, parallel_for and parallel_chunks cover [0, n) exactly once", "[parallel]") {
  for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{1000}, std::size_t{100003}}) {
    for (unsigned threads : {0u, 1u, 3u, 8u}) {
      std::vector<int> a(n, 0), b(n, 0), c(n, 0);
      const std::size_t slices = vitri::slice_count(threads, n, 64);
      CHECK(slices >= 1);
      // Catch's assertions are not thread-safe: each slice records its bounds, checked here afterwards.
      std::vector<std::size_t> los(slices, n + 1), his(slices, n + 1);
      vitri::run_slices(n, slices, [&](std::size_t s, std::size_t lo, std::size_t hi) {
        los[s] = lo;
        his[s] = hi;
        for (std::size_t i = lo; i < hi; ++i) ++a[i];
      });
      for (std::size_t s = 0; s < slices; ++s) {
        CHECK(los[s] == s * n / slices);
        CHECK(his[s] == (s + 1) * n / slices);
      }
      vitri::parallel_for(n, threads, [&](std::size_t i) { ++b[i]; }, 16);
      vitri::parallel_chunks(n, threads, 100, [&](std::size_t lo, std::size_t hi) {
        for (std::size_t i = lo; i < hi; ++i) ++c[i];
      });
      const auto once = [](const std::vector<int>& v) {
        return std::all_of(v.begin(), v.end(), [](int x) { return x == 1; });
      };
      CHECK(once(a));
      CHECK(once(b));
      CHECK(once(c));
    }
  }
}
