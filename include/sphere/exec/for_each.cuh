#pragma once
/// \file
/// `for_each_index(policy, n, body)`: runs `body(i)` for every i in [0, n).
///
/// The body is a trivially copyable functor with a SPHERE_HD `operator()(std::size_t) const`
/// (a kernel written once over views). Each index must write only its own outputs, so the
/// result does not depend on the order or the number of threads.
#include <cstddef>
#include <string>

#include "../core/config.cuh"
#include "../core/error.cuh"
#include "policy.cuh"

namespace sphere {

/// Below this many indices a host loop runs on the calling thread: starting a team of
/// threads costs more than the work (and much more when the cores are busy).
inline constexpr std::size_t host_parallel_threshold = 256;

/// Static schedule: each thread takes the same share of every loop, so a particle's data stay
/// in one core's cache from loop to loop (a dynamic schedule measured 17% slower on the bed
/// with 2 threads, docs/performance.md).
template <class Body>
void for_each_index(host, std::size_t n, const Body& body)
{
    const long long count = static_cast<long long>(n);
#pragma omp parallel for schedule(static) if (n >= host_parallel_threshold)
    for (long long i = 0; i < count; ++i) body(static_cast<std::size_t>(i));
}

#if SPHERE_CUDA_COMPILER
namespace detail {
template <class Body>
__global__ void for_each_index_kernel(std::size_t n, Body body)
{
    const std::size_t stride = static_cast<std::size_t>(blockDim.x) * gridDim.x;
    for (std::size_t i = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x; i < n; i += stride)
        body(i);
}

inline void check_cuda(cudaError_t status, const char* what)
{
    if (status != cudaSuccess) fail("CUDA error in ", what, ": ", cudaGetErrorString(status));
}
} // namespace detail

template <class Body>
void for_each_index(cuda, std::size_t n, const Body& body)
{
    if (n == 0) return;
    constexpr unsigned threads = 256;
    const std::size_t wanted = (n + threads - 1) / threads;
    const unsigned blocks = static_cast<unsigned>(wanted < 65535u * 32u ? wanted : 65535u * 32u);
    detail::for_each_index_kernel<<<blocks, threads>>>(n, body);
    detail::check_cuda(cudaGetLastError(), "kernel launch");
}
#endif

} // namespace sphere
