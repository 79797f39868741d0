// Tests of vitri/core/threads.hpp: what `threads = 0` means everywhere in the library.

#include "vitri/core/threads.hpp"

#include <catch2/catch.hpp>

#include <thread>

TEST_CASE("available_cpus follows the affinity mask", "[threads]") {
  const unsigned all = vitri::available_cpus();
  REQUIRE(all >= 1);
  const unsigned hardware = std::thread::hardware_concurrency();
  if (hardware > 0) CHECK(all <= hardware);
  CHECK(vitri::resolve_thread_count(0) == all);
  CHECK(vitri::resolve_thread_count(3) == 3);
#if defined(__linux__) && defined(CPU_COUNT)
  // A thread pinned to one CPU (as under `taskset -c K`) sees exactly one.
  unsigned pinned = 0;
  bool set_ok = false;
  std::thread t([&] {
    cpu_set_t mine;
    CPU_ZERO(&mine);
    if (sched_getaffinity(0, sizeof(mine), &mine) != 0) return;
    int first = -1;
    for (int c = 0; c < CPU_SETSIZE && first < 0; ++c)
      if (CPU_ISSET(c, &mine)) first = c;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(first, &one);
    set_ok = sched_setaffinity(0, sizeof(one), &one) == 0;
    pinned = vitri::available_cpus();
  });
  t.join();
  if (set_ok) CHECK(pinned == 1);
  CHECK(vitri::available_cpus() == all);  // the pin was the other thread's alone
#endif
}
