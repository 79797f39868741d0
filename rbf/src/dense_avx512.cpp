// The AVX-512 copy of the dense kernels (see dense_kernels.inc), compiled with -mavx512f -mavx512dq
// -mavx512vl -mfma and called only when the CPU reports them (dense.cpp). Eigen's matrix product then
// runs on 8-lane FMAs. Measured on a Sapphire Rapids VM: about 1.25x the AVX2 copy's speed on the fit
// and 1.1x on evaluation (not the 2x the lane count suggests: memory and the scalar parts). Eigen is
// renamed so that none of its instantiations here can replace the other copies at link time.
#define Eigen vitri_avx512_Eigen
#define VITRI_DENSE_NS avx512
#include "dense_kernels.inc"
