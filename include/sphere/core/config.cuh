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

#if defined(__CUDA_ARCH__)
#define SPHERE_DEVICE_CODE 1
#else
#define SPHERE_DEVICE_CODE 0
#endif

#if __cplusplus < 201703L && !defined(_MSVC_LANG)
#error "sphere needs C++17"
#endif
