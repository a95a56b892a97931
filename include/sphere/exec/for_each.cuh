#pragma once
/// \file
/// `for_each_index(policy, n, body)`: runs `body(i)` for every i in [0, n) (on CUDA,
/// asynchronously, on the calling thread's current stream).
///
/// The body is a trivially copyable functor with a SPHERE_HD `operator()(std::size_t) const`
/// (a kernel written once over views). Each index must write only its own outputs, so the
/// result does not depend on the order or the number of threads.
#include <cstddef>
#include <string>

#include "../core/config.cuh"
#include "../core/error.cuh"
#include "cuda_error.cuh"
#include "host_team.cuh"
#include "policy.cuh"

namespace sphere {

/// Below this many indices a host loop runs on the calling thread: starting a team of
/// threads costs more than the work (and much more when the cores are busy).
inline constexpr std::size_t host_parallel_threshold = 256;

/// Host loops run in chunks of this many indices: the unit of the threads' shares, and of
/// reductions (exec/algorithms.cuh).
inline constexpr std::size_t host_chunk = 512;

namespace detail {
/// body(i) for i in [begin, end): a loop the compiler may vectorise (the iterations are
/// independent by the contract of for_each_index), over a local copy of the body, whose
/// pointers the compiler then knows no store in the loop can change.
template <class Body>
void run_chunk(const Body& body, std::size_t begin, std::size_t end)
{
    Body local = body; // not const: g++ 12 does not scalarise a const copy
    SPHERE_VECTORISE_LOOP
    for (std::size_t i = begin; i < end; ++i) local(i);
}
} // namespace detail

/// Static schedule: each thread takes the same share of every loop, so a particle's data stay
/// in one core's cache from loop to loop (a dynamic schedule measured 17% slower on the bed
/// with 2 threads, docs/performance.md).
///
/// A loop too short for threads, or a team of one, runs without entering an OpenMP region: a
/// region of one thread still costs libgomp's team start and end (system calls that took 40%
/// of a 6-particle step).
template <class Body>
void for_each_index(host, std::size_t n, const Body& body)
{
    const long long chunks = static_cast<long long>((n + host_chunk - 1) / host_chunk);
    if (n < host_parallel_threshold || host_team() == 1) {
        for (long long c = 0; c < chunks; ++c) {
            const std::size_t begin = static_cast<std::size_t>(c) * host_chunk;
            detail::run_chunk(body, begin, begin + host_chunk < n ? begin + host_chunk : n);
        }
        return;
    }
#pragma omp parallel for schedule(static) num_threads(host_team())
    for (long long c = 0; c < chunks; ++c) {
        const std::size_t begin = static_cast<std::size_t>(c) * host_chunk;
        detail::run_chunk(body, begin, begin + host_chunk < n ? begin + host_chunk : n);
    }
}

/// body(i) for every i in [0, n) if `*go` is not 0 when the loop's turn comes: `go` lies in the
/// policy's memory and may be set by a kernel launched before (a decision taken on the device,
/// which the host does not wait for). The host reads the flag once before the loop; each CUDA
/// thread reads it first.
template <class Body>
void for_each_index_if(host, const int* go, std::size_t n, const Body& body)
{
    if (*go) for_each_index(host{}, n, body);
}

#if SPHERE_CUDA_COMPILER
namespace detail {
/// The stream the calling thread's CUDA work goes to: the simulation's own while one of its
/// calls runs (stream_scope, exec/context.cuh), else the default stream.
inline cudaStream_t& current_stream()
{
    static thread_local cudaStream_t stream = 0;
    return stream;
}

template <class Body>
__global__ void for_each_index_kernel(std::size_t n, Body body)
{
    const std::size_t stride = static_cast<std::size_t>(blockDim.x) * gridDim.x;
    for (std::size_t i = blockIdx.x * static_cast<std::size_t>(blockDim.x) + threadIdx.x; i < n; i += stride)
        body(i);
}
} // namespace detail

template <class Body>
void for_each_index(cuda, std::size_t n, const Body& body)
{
    if (n == 0) return;
    constexpr unsigned threads = 256;
    const std::size_t wanted = (n + threads - 1) / threads;
    const unsigned blocks = static_cast<unsigned>(wanted < 65535u * 32u ? wanted : 65535u * 32u);
    detail::for_each_index_kernel<<<blocks, threads, 0, detail::current_stream()>>>(n, body);
    detail::check_cuda(cudaGetLastError(), detail::kernel_name<Body>());
}

namespace detail {
/// body(i) where *go is not 0 (for_each_index_if on CUDA).
template <class Body>
struct only_if {
    const int* go;
    Body body;
    SPHERE_HD void operator()(std::size_t i) const
    {
        if (*go) body(i);
    }
};
} // namespace detail

template <class Body>
void for_each_index_if(cuda, const int* go, std::size_t n, const Body& body)
{
    for_each_index(cuda{}, n, detail::only_if<Body>{go, body});
}
#endif

} // namespace sphere
