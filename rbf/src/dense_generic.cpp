// The portable copy of the dense kernels (see dense_kernels.inc).
#define VITRI_DENSE_NS generic
#include "dense_kernels.inc"
