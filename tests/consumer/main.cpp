// Built against an installed vitri: checks that the headers, the exported targets and the libraries work
// together outside the source tree.
#include <vitri/core/predicates.hpp>

#include <cstdio>

int main() {
  const vitri::Point3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0}, d{0, 0, 1};
  if (vitri::orient3d(a, b, c, d) != vitri::Sign::Positive) {
    std::puts("orient3d convention broken");
    return 1;
  }
  std::puts("consumer ok");
  return 0;
}
