#include "dense.hpp"

#include <cstdlib>

namespace vitri::rbf_detail {

namespace generic {
bool cholesky_inplace(double* a, long n, long lda);
void rbf_sums(const double* cx, const double* cy, const double* cz, const double* w, long n, const double* q,
              long m, double* f, double* g);
}  // namespace generic

#ifdef VITRI_RBF_HAVE_AVX2
namespace avx2 {
bool cholesky_inplace(double* a, long n, long lda);
void rbf_sums(const double* cx, const double* cy, const double* cz, const double* w, long n, const double* q,
              long m, double* f, double* g);
}  // namespace avx2
#endif

const DenseOps& dense_ops() {
  static const DenseOps ops = [] {
#ifdef VITRI_RBF_HAVE_AVX2
    const char* env = std::getenv("VITRI_RBF_GENERIC");
    const bool forced = env && env[0] && env[0] != '0';
    __builtin_cpu_init();
    if (!forced && __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
      return DenseOps{avx2::cholesky_inplace, avx2::rbf_sums, "avx2+fma"};
#endif
    return DenseOps{generic::cholesky_inplace, generic::rbf_sums, "generic"};
  }();
  return ops;
}

}  // namespace vitri::rbf_detail
