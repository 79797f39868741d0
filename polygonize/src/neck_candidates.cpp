// The Polygonizer's neck candidates (neck_candidates.hpp).
#include "neck_candidates.hpp"

namespace vitri::polygonizer_detail {

std::vector<VertexId> NeckCandidates::take() {
  std::vector<VertexId> out;
  out.swap(list_);
  for (const VertexId v : out) mark_[v] = 0;
  return out;
}

}  // namespace vitri::polygonizer_detail
