// The CUDA test binary (sphere_cuda_tests, tests/CMakeLists.txt): physics tests written once for
// every backend, compiled here by nvcc with sphere::cuda as the policy of the simulations they
// create (sphere_test::policy, tests/support.hpp), and the comparison of the two backends.
// The host test binary (sphere_tests) compiles the same sources with sphere::host.
//
// One translation unit, so that nvcc compiles the kernels of each simulation type once. The
// sources are chosen to keep its compile time within a few minutes for one architecture (CI):
// binary collisions D1-D6, tangential forces D7-D9, dynamic walls D10 and a settling bed of
// 2304 particles. main() is in main.cpp.
#define SPHERE_TEST_POLICY sphere::cuda

#include "../test_collisions.cpp"
#include "../test_settling.cpp"
#include "../test_tangential.cpp"
#include "../test_walls.cpp"

#include "compare_backends.cu"
