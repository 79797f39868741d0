// The AVX-512 copy of the dense kernels (see dense_kernels.inc), compiled with -mavx512f -mavx512dq
// -mavx512vl -mfma and called only when the CPU reports them (dense.cpp). Eigen's matrix product then
// runs on 8-lane FMAs, about twice the AVX2 throughput in the Cholesky's trailing updates. Eigen is
// renamed so that none of its instantiations here can replace the other copies at link time.
#define Eigen vitri_avx512_Eigen
#define VITRI_DENSE_NS avx512
#include "dense_kernels.inc"
