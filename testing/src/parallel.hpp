#pragma once
// parallel_for: the library's contiguous-block loop (vitri/core/parallel.hpp): body(i) must only write slot
// i of its outputs, so that the result does not depend on the thread count.
#include "vitri/core/parallel.hpp"

namespace vitri::testing::detail {

using ::vitri::parallel_for;

}  // namespace vitri::testing::detail
