#include "dense.hpp"

#include "vitri/core/parallel.hpp"

#include <algorithm>
#include <cstdlib>
#include <string_view>
#include <vector>

namespace vitri::rbf_detail {

// The entry points of one instruction-set copy of dense_kernels.inc (compiled in its own file).
#define VITRI_DECLARE_DENSE_COPY(ns)                                                                         \
  namespace ns {                                                                                             \
  bool cholesky_inplace(double* a, long n, long lda);                                                        \
  void gemm_nt_sub(const double* a, long m, long lda, const double* b, long k, long ldb, long nb, double* c, \
                   long ldc);                                                                                \
  void trsm_right_lower_t(const double* l, long nb, long ldl, double* b, long m, long ldb);                  \
  void rbf_sums(const double* cx, const double* cy, const double* cz, const double* w, long n,               \
                const double* q, long m, double* f, double* g);                                              \
  bool patch_weights(const double* ux, const double* uy, const double* uz, const double* h, long k, double s, \
                     const double* qr, long ldqr, const double* tau, long nh, long rank, double* w, double* r, \
                     double* work);                                                                          \
  }

VITRI_DECLARE_DENSE_COPY(generic)
#ifdef VITRI_RBF_HAVE_AVX2
VITRI_DECLARE_DENSE_COPY(avx2)
#endif
#ifdef VITRI_RBF_HAVE_AVX512
VITRI_DECLARE_DENSE_COPY(avx512)
#endif
#undef VITRI_DECLARE_DENSE_COPY

std::vector<DenseOps> dense_ops_supported() {
  std::vector<DenseOps> out;
#ifdef VITRI_RBF_HAVE_AVX2
  __builtin_cpu_init();
#ifdef VITRI_RBF_HAVE_AVX512
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512vl"))
    out.push_back(DenseOps{avx512::cholesky_inplace, avx512::rbf_sums, avx512::gemm_nt_sub,
                           avx512::trsm_right_lower_t, avx512::patch_weights, "avx512"});
#endif
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
    out.push_back(DenseOps{avx2::cholesky_inplace, avx2::rbf_sums, avx2::gemm_nt_sub,
                           avx2::trsm_right_lower_t, avx2::patch_weights, "avx2+fma"});
#endif
  out.push_back(DenseOps{generic::cholesky_inplace, generic::rbf_sums, generic::gemm_nt_sub,
                         generic::trsm_right_lower_t, generic::patch_weights, "generic"});
  return out;
}

namespace {
bool env_flag(const char* name) {
  const char* v = std::getenv(name);
  return v && v[0] && v[0] != '0';
}
}  // namespace

const DenseOps& dense_ops() {
  static const DenseOps ops = [] {
    const std::vector<DenseOps> all = dense_ops_supported();  // best first, generic last
    if (env_flag("VITRI_RBF_GENERIC")) return all.back();
    for (const DenseOps& o : all)
      if (!(env_flag("VITRI_RBF_NO_AVX512") && std::string_view(o.name) == "avx512")) return o;
    return all.back();
  }();
  return ops;
}

// Right-looking blocked Cholesky:
//
//   for each block column k:   [A11  .  ]    A11 = L11 L11^T           (one thread, Eigen LLT)
//                              [A21 A22 ]    L21 = A21 L11^{-T}        (rows split between threads)
//                                            A22 -= L21 L21^T, lower   (column blocks split by work)
//
// Each piece is an ordinary single-threaded kernel call on disjoint memory, so the result does not
// depend on the number of threads.
bool cholesky_parallel(double* a, long n, long lda, unsigned threads) {
  const DenseOps& ops = dense_ops();
  constexpr long kBlock = 192;
  if (n < 3 * kBlock) return ops.cholesky_inplace(a, n, lda);
  const long t = static_cast<long>(std::clamp(threads, 1u, 8u));
  auto at = [&](long i, long j) { return a + i + j * lda; };
  auto run = [&](auto&& task) {  // task(thread index) on t threads (the caller is thread 0)
    run_tasks(static_cast<std::size_t>(t), [&](std::size_t p) { task(static_cast<long>(p)); });
  };
  for (long k = 0; k < n; k += kBlock) {
    const long kb = std::min(kBlock, n - k);
    if (!ops.cholesky_inplace(at(k, k), kb, lda)) return false;
    const long r0 = k + kb, m = n - r0;
    if (m == 0) break;
    // Fixed row chunks (not one chunk per thread): the same kernel calls whatever the thread count,
    // hence bit-identical factors.
    const long chunks = (m + kBlock - 1) / kBlock;
    run([&](long p) {
      for (long q = p; q < chunks; q += t) {
        const long b = r0 + q * kBlock, e = std::min(n, b + kBlock);
        ops.trsm_right_lower_t(at(k, k), kb, lda, at(b, k), e - b, lda);
      }
    });
    // Column blocks of the trailing matrix; block [j, j + jb) updates rows j..n-1. Split by work.
    std::vector<long> starts;
    for (long j = r0; j < n; j += kBlock) starts.push_back(j);
    std::vector<double> work(starts.size() + 1, 0.0);
    for (std::size_t q = 0; q < starts.size(); ++q)
      work[q + 1] =
          work[q] + static_cast<double>(n - starts[q]) * static_cast<double>(std::min(kBlock, n - starts[q]));
    run([&](long p) {
      const double lo = work.back() * static_cast<double>(p) / static_cast<double>(t);
      const double hi = work.back() * static_cast<double>(p + 1) / static_cast<double>(t);
      for (std::size_t q = 0; q < starts.size(); ++q) {
        const double mid = 0.5 * (work[q] + work[q + 1]);
        if (mid < lo || mid >= hi) continue;
        const long j = starts[q], jb = std::min(kBlock, n - j);
        ops.gemm_nt_sub(at(j, k), n - j, lda, at(j, k), jb, lda, kb, at(j, j), lda);
      }
    });
  }
  return true;
}

}  // namespace vitri::rbf_detail
