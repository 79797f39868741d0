#pragma once
// A cube [c - h, c + h]^3 as 12 triangles, counter-clockwise seen from outside.
#include <Eigen/Core>

namespace vitri::testing::test {

inline void cube(Eigen::MatrixXd& V, Eigen::MatrixXi& F, const Eigen::Vector3d& c = Eigen::Vector3d::Zero(),
                 double h = 0.5) {
  V.resize(8, 3);
  for (int i = 0; i < 8; ++i)
    V.row(i) = (c + h * Eigen::Vector3d(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1)).transpose();
  F.resize(12, 3);
  F << 0, 2, 3, 0, 3, 1,  // z = -h, normal -z
      4, 5, 7, 4, 7, 6,   // z = +h, normal +z
      0, 1, 5, 0, 5, 4,   // y = -h, normal -y
      2, 6, 7, 2, 7, 3,   // y = +h, normal +y
      0, 4, 6, 0, 6, 2,   // x = -h, normal -x
      1, 3, 7, 1, 7, 5;   // x = +h, normal +x
}

}  // namespace vitri::testing::test
