#pragma once
/// \file
/// The one portability header: every compiler check of the library lives here.
///
/// SPHERE_HD marks a function callable from host and device code. It expands to
/// `__host__ __device__` only when nvcc compiles the translation unit, so every header
/// also compiles with a plain C++17 compiler (g++), where kernels run on the host backend.

#if defined(__CUDACC__)
#define SPHERE_HD __host__ __device__
#define SPHERE_CUDA_COMPILER 1
#else
#define SPHERE_HD
#define SPHERE_CUDA_COMPILER 0
#endif

/// SPHERE_HDI: SPHERE_HD and always inlined, for the small vector operations and contact-law
/// pieces of the inner loops (g++ -O2 otherwise leaves calls like cross() out of line: a
/// third of the interaction kernel's time, docs/performance.md).
#if defined(__CUDACC__)
#define SPHERE_HDI __host__ __device__ __forceinline__
#elif defined(__GNUC__)
#define SPHERE_HDI __attribute__((always_inline)) inline
#else
#define SPHERE_HDI inline
#endif

/// SPHERE_VECTORISE_LOOP before a loop whose iterations are independent: vectorise it. g++ is
/// told `ivdep` (its `omp simd` privatises a loop's local structs into arrays, which it then
/// cannot vectorise), clang `vectorize(assume_safety)` (which it also takes as an order, and
/// warns where it cannot: the CMake target turns that warning off), other compilers `omp simd`.
#if defined(__GNUC__) && !defined(__clang__)
#define SPHERE_VECTORISE_LOOP _Pragma("GCC ivdep")
#elif defined(__clang__) && !defined(__CUDACC__)
#define SPHERE_VECTORISE_LOOP _Pragma("clang loop vectorize(assume_safety)")
#else
#define SPHERE_VECTORISE_LOOP _Pragma("omp simd")
#endif

/// SPHERE_UNROLL before a loop with a constant trip count whose index selects struct members
/// (the six wall faces): unrolled, every index is a constant and the members stay in
/// registers on CUDA instead of local memory. g++ gets its own pragma; nvcc's host pass none
/// (its front end warns about g++'s, and g++ about nvcc's).
#if defined(__CUDA_ARCH__)
#define SPHERE_UNROLL _Pragma("unroll")
#elif defined(__CUDACC__)
#define SPHERE_UNROLL
#elif defined(__GNUC__) && !defined(__clang__)
#define SPHERE_UNROLL _Pragma("GCC unroll 8")
#else
#define SPHERE_UNROLL
#endif

/// SPHERE_DEVICE_CODE: 1 in nvcc's device pass, else 0, for the few places where a GPU thread
/// and a host SIMD lane want different forms of the same arithmetic.
#if defined(__CUDA_ARCH__)
#define SPHERE_DEVICE_CODE 1
#else
#define SPHERE_DEVICE_CODE 0
#endif

#if __cplusplus < 201703L && !defined(_MSVC_LANG)
#error "sphere needs C++17"
#endif
