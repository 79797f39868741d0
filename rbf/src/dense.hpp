#pragma once
// Run-time dispatch between the portable, the AVX2 + FMA and the AVX-512 copies of the dense kernels.

#include <vector>

namespace vitri::rbf_detail {

/// The dense kernels of one instruction set (see dense_kernels.inc for the contracts).
struct DenseOps {
  bool (*cholesky_inplace)(double* a, long n, long lda);
  void (*rbf_sums)(const double* cx, const double* cy, const double* cz, const double* w, long n,
                   const double* q, long m, double* f, double* g);
  void (*gemm_nt_sub)(const double* a, long m, long lda, const double* b, long k, long ldb, long nb,
                      double* c, long ldc);
  void (*trsm_right_lower_t)(const double* l, long nb, long ldl, double* b, long m, long ldb);
  bool (*patch_weights)(const double* ux, const double* uy, const double* uz, const double* h, long k,
                        double s, const double* qr, long ldqr, const double* tau, long nh, long rank, double* w,
                        double* r, double* work);
  const char* name;
};

/// In-place lower Cholesky of the leading n x n block (leading dimension lda) with up to `threads`
/// threads: right-looking blocked algorithm whose panel solves and trailing updates are split between
/// threads (each piece runs the dense_ops() kernels). threads <= 1 or small n: the single-threaded
/// Eigen LLT. Returns false when the matrix is not numerically positive definite.
bool cholesky_parallel(double* a, long n, long lda, unsigned threads);

/// The best copy for this CPU (AVX-512, else AVX2 + FMA, when built with it and supported), chosen
/// once. Setting the environment variable VITRI_RBF_GENERIC=1 forces the portable copy,
/// VITRI_RBF_NO_AVX512=1 skips the AVX-512 copy.
const DenseOps& dense_ops();

/// Every copy this build has and this CPU runs, best first (the portable one is always last). Tests
/// compare them with each other.
std::vector<DenseOps> dense_ops_supported();

}  // namespace vitri::rbf_detail
