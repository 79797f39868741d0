// The Polygonizer's lone zeros (lone_zeros.hpp).
#include "lone_zeros.hpp"

namespace vitri::polygonizer_detail {

bool LoneZeros::set(VertexId v, bool on) {
  if (on == contains(v)) return false;
  if (on)
    list_insert(list_, pos_, v);
  else
    list_erase(list_, pos_, v);
  return true;
}

}  // namespace vitri::polygonizer_detail
