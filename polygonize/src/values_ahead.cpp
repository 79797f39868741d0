// f at a round's new vertices on a helper thread (see values_ahead.hpp).
#include "values_ahead.hpp"

#include <algorithm>
#include <chrono>

namespace vitri::polygonizer_detail {

namespace {

// Points evaluated per call of f by the helper (small: the helper keeps up with the insertions, and the
// batch kernels need no more to be efficient).
constexpr std::size_t kHelperBatch = 32;

}  // namespace

ValuesAhead::ValuesAhead(const ImplicitFunction& f, bool gradients, std::size_t capacity)
    : f_(f), gradients_(gradients), vertices_(capacity), points_(capacity), values_(capacity),
      grads_(gradients ? capacity : 0) {
  helper_ = std::thread([this] { run(); });
}

ValuesAhead::~ValuesAhead() { stop(); }

bool ValuesAhead::offer(VertexId v, const Point3& p) {
  const std::size_t i = count_.load(std::memory_order_relaxed);
  if (i == points_.size() || closed_.load(std::memory_order_relaxed)) return false;
  vertices_[i] = v;
  points_[i] = p;
  count_.store(i + 1, std::memory_order_release);
  return true;
}

void ValuesAhead::stop() {
  closed_.store(true, std::memory_order_release);
  if (helper_.joinable()) helper_.join();
}

void ValuesAhead::finish() {
  stop();
  if (error_) std::rethrow_exception(error_);
}

void ValuesAhead::run() {
  try {
    std::size_t done = 0;
    for (;;) {
      // closed_ is read before count_: a count read after seeing it closed is the final one.
      const bool closed = closed_.load(std::memory_order_acquire);
      const std::size_t n = count_.load(std::memory_order_acquire);
      if (done == n) {
        if (closed) return;
        // The insertions have not made the next point yet (one takes about 10 us at 10^6 points): sleep
        // rather than spin, which would take the core from the insertions where two share one.
        std::this_thread::sleep_for(std::chrono::microseconds(20));
        continue;
      }
      const std::size_t k = std::min(n - done, kHelperBatch);
      if (gradients_)
        f_.values_gradients(points_.data() + done, k, values_.data() + done, grads_.data() + done);
      else
        f_.values(points_.data() + done, k, values_.data() + done);
      done += k;
    }
  } catch (...) {
    error_ = std::current_exception();  // read by finish() after the join
  }
}

}  // namespace vitri::polygonizer_detail
