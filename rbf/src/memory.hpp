#pragma once
// The memory budget of the dense RBF system (RbfOptions::max_memory_bytes), checked before allocating.

#include "vitri/rbf/rbf.hpp"

#include <cstddef>

namespace vitri::rbf_detail {

/// A byte count computed in floating point, saturated at SIZE_MAX.
std::size_t saturated_bytes(double bytes);

/// The budget in force: options.max_memory_bytes, or the physical memory when it is 0 (0 = no limit when
/// neither is known).
std::size_t memory_budget(const RbfOptions& options);

/// Throws LimitError when `bytes` exceed the budget. `what` says what needs them ("the fit of N
/// constraints", ...); the message names the bytes, the limit and the way out (the local function).
void require_memory(std::size_t bytes, const std::string& what, const RbfOptions& options);

}  // namespace vitri::rbf_detail
