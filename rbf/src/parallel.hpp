#pragma once
// parallel_chunks: the library's dynamic-chunk loop (vitri/core/parallel.hpp), under the rbf module's name.
#include "vitri/core/parallel.hpp"

namespace vitri {
namespace rbf_detail {

using ::vitri::parallel_chunks;

}  // namespace rbf_detail
}  // namespace vitri
