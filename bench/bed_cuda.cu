// bed_cuda: the dense-bed benchmark (bed.cpp) on the CUDA backend; bench/CMakeLists.txt builds it.
#define SPHERE_BED_POLICY sphere::cuda
#include "bed.cpp"
