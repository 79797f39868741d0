#pragma once
// Run-time dispatch between the portable and the AVX2 + FMA copies of the dense kernels.

namespace vitri::rbf_detail {

/// The dense kernels of one instruction set (see dense_kernels.inc for the contracts).
struct DenseOps {
  bool (*cholesky_inplace)(double* a, long n, long lda);
  void (*rbf_sums)(const double* cx, const double* cy, const double* cz, const double* w, long n,
                   const double* q, long m, double* f, double* g);
  const char* name;
};

/// The best copy for this CPU (AVX2 + FMA when built with it and supported), chosen once.
/// Setting the environment variable VITRI_RBF_GENERIC=1 forces the portable copy.
const DenseOps& dense_ops();

}  // namespace vitri::rbf_detail
