// The AVX2 + FMA copy of the dense kernels (see dense_kernels.inc), compiled with -mavx2 -mfma and
// called only when the CPU reports both (dense.cpp). Eigen is renamed so that none of its instantiations
// here can replace the portable ones at link time.
#define Eigen vitri_avx2_Eigen
#define VITRI_DENSE_NS avx2
#include "dense_kernels.inc"
