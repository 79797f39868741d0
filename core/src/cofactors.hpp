#pragma once
/// @file cofactors.hpp (private to vitri::core)
/// The determinants of the predicates as cofactor schemes, generic over the arithmetic: the same
/// expressions, in the same order, as the filters of predicates.hpp. Used with CheckedArithmetic (stage
/// 1 of the exact fallback), DoubleWordArithmetic (stage 2, double_word.hpp) and WideArithmetic (exact
/// integers) in predicates.cpp; the error bounds of the filter and of stage 2 are derived for exactly
/// this order of operations (docs/predicates.md). `Arith` provides sub, add and mul on T.

namespace vitri::detail {

/// orient3d from the differences m (rows b - a, c - a, d - a): det m.
template <class Arith, class T>
T orient3d_from_differences(Arith& f, const T (&m)[3][3]) {
  const T m1 = f.sub(f.mul(m[1][1], m[2][2]), f.mul(m[1][2], m[2][1]));
  const T m2 = f.sub(f.mul(m[1][2], m[2][0]), f.mul(m[1][0], m[2][2]));
  const T m3 = f.sub(f.mul(m[1][0], m[2][1]), f.mul(m[1][1], m[2][0]));
  return f.add(f.add(f.mul(m[0][0], m1), f.mul(m[0][1], m2)), f.mul(m[0][2], m3));
}

/// orient3d from the coordinates v (a, b, c, d: 12 values): rows b - a, c - a, d - a.
template <class Arith, class T>
T orient3d_cofactors(Arith& f, const T* v) {
  T m[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) m[r][k] = f.sub(v[3 * (r + 1) + k], v[k]);
  return orient3d_from_differences(f, m);
}

/// insphere from the differences q[r][k] = coordinate k of (point r - e), r = a, b, c, d.
template <class Arith, class T>
T insphere_cofactors(Arith& f, const T (&q)[4][3]) {
  auto minor2 = [&](int i, int j) { return f.sub(f.mul(q[i][0], q[j][1]), f.mul(q[j][0], q[i][1])); };
  const T ab = minor2(0, 1), bc = minor2(1, 2), cd = minor2(2, 3), da = minor2(3, 0), ac = minor2(0, 2),
          bd = minor2(1, 3);
  const T abc = f.add(f.sub(f.mul(q[0][2], bc), f.mul(q[1][2], ac)), f.mul(q[2][2], ab));
  const T bcd = f.add(f.sub(f.mul(q[1][2], cd), f.mul(q[2][2], bd)), f.mul(q[3][2], bc));
  const T cda = f.add(f.add(f.mul(q[2][2], da), f.mul(q[3][2], ac)), f.mul(q[0][2], cd));
  const T dab = f.add(f.add(f.mul(q[3][2], ab), f.mul(q[0][2], bd)), f.mul(q[1][2], da));
  T lift[4];
  for (int r = 0; r < 4; ++r)
    lift[r] = f.add(f.add(f.mul(q[r][0], q[r][0]), f.mul(q[r][1], q[r][1])), f.mul(q[r][2], q[r][2]));
  return f.add(f.sub(f.mul(lift[0], bcd), f.mul(lift[1], cda)), f.sub(f.mul(lift[2], dab), f.mul(lift[3], abc)));
}

}  // namespace vitri::detail
