#pragma once
/// \file
/// `execution_context<Policy>`: what a simulation's step needs from its backend beyond kernel
/// launches: temporary storage that is kept between calls (a reduction allocates once, at its
/// first call, not at every step), reductions whose result stays in the policy's memory
/// (`transform_reduce_into`), and the step's one read-back (`read_back`), which on CUDA is also
/// where an asynchronous fault of an earlier kernel surfaces as a sphere::error naming it.
///
/// The host backend goes through the same calls, and both count what the CUDA build does in
/// device_activity() (exec/activity.cuh): a scratch block that grows is an allocation, a
/// read_back is a read-back. On CUDA the context owns a stream: its reductions, sorts and
/// scans run on it, and so do for_each_index's kernels while a `stream_scope` over the context
/// lives (a simulation opens one in each call that launches work).
#include <cstddef>
#include <cstring>
#include <utility>
#include <vector>

#include "../core/config.cuh"
#include "../core/error.cuh"
#include "activity.cuh"
#include "algorithms.cuh"
#include "cuda_error.cuh"
#include "for_each.cuh"
#include "policy.cuh"

#if SPHERE_CUDA_COMPILER
#include <cub/device/device_reduce.cuh>
#endif

namespace sphere {

template <class Policy>
class execution_context;

namespace detail {
/// `bytes` rounded up to a multiple of 256, so that arrays placed one after the other in a
/// scratch block stay aligned for any type.
inline std::size_t aligned_bytes(std::size_t bytes) { return (bytes + 255) / 256 * 256; }
} // namespace detail

/// Routes the kernels launched while it lives to a context's stream (CUDA); nothing on the
/// host. A simulation opens one for each of its calls that launch work.
template <class Policy>
class stream_scope {
public:
    explicit stream_scope(execution_context<Policy>&) {}
};

/// Host: scratch in host memory; a read-back is a copy.
template <>
class execution_context<host> {
public:
    /// At least `bytes` of temporary storage, valid until the next call; grows, never shrinks.
    void* scratch(std::size_t bytes)
    {
        if (bytes > scratch_.size()) {
            ++device_activity().allocations;
            scratch_.resize(bytes);
        }
        return scratch_.data();
    }

    /// Copies `count` values from the policy's memory at `from` to the host at `to`, after
    /// everything launched before; `what` and `step` (of the simulation) name it in errors.
    template <class T>
    void read_back(T* to, const T* from, std::size_t count, const char* /*what*/, std::size_t /*step*/)
    {
        ++device_activity().read_backs;
        std::memcpy(static_cast<void*>(to), static_cast<const void*>(from), count * sizeof(T));
    }

private:
    std::vector<unsigned char> scratch_;
};

/// *out = init op f(0) op ... op f(n-1), written to the policy's memory at `out` (nothing is
/// read back); on the host in the fixed order of detail::host_reduce, so bit-identical for any
/// number of threads. T must be trivially copyable.
template <class T, class Transform, class Op>
void transform_reduce_into(execution_context<host>& ctx, std::size_t n, const Transform& f, T init, Op op, T* out)
{
    T* partial = static_cast<T*>(ctx.scratch(detail::host_reduce_chunks(n) * sizeof(T)));
    *out = detail::host_reduce(n, f, init, op, partial);
}

#if SPHERE_CUDA_COMPILER
/// CUDA: scratch in device memory, the read-back through pinned host memory; both grow only.
template <>
class execution_context<cuda> {
public:
    execution_context() = default;
    execution_context(const execution_context&) = delete;
    execution_context& operator=(const execution_context&) = delete;
    execution_context(execution_context&& other) noexcept { swap(other); }
    execution_context& operator=(execution_context&& other) noexcept
    {
        swap(other);
        return *this;
    }
    ~execution_context()
    {
        if (scratch_) cudaFree(scratch_);
        if (pinned_) cudaFreeHost(pinned_);
        if (stream_) cudaStreamDestroy(stream_);
    }

    /// The context's own stream, made at its first use. A blocking stream: work on the
    /// default stream (buffer allocations and copies, diagnostics outside a stream_scope)
    /// stays ordered with it.
    cudaStream_t stream()
    {
        if (!stream_) detail::check_cuda(cudaStreamCreate(&stream_), "cudaStreamCreate (context stream)");
        return stream_;
    }

    void* scratch(std::size_t bytes)
    {
        if (bytes > scratch_bytes_) {
            ++device_activity().allocations;
            if (scratch_) detail::check_cuda(cudaFree(scratch_), "cudaFree (context scratch)");
            scratch_ = nullptr;
            scratch_bytes_ = 0;
            detail::check_cuda(cudaMalloc(&scratch_, bytes), "cudaMalloc (context scratch)");
            scratch_bytes_ = bytes;
        }
        return scratch_;
    }

    template <class T>
    void read_back(T* to, const T* from, std::size_t count, const char* what, std::size_t step)
    {
        ++device_activity().read_backs;
        const std::size_t bytes = count * sizeof(T);
        if (bytes > pinned_bytes_) {
            if (pinned_) detail::check_cuda(cudaFreeHost(pinned_), "cudaFreeHost (context read-back)");
            pinned_ = nullptr;
            pinned_bytes_ = 0;
            detail::check_cuda(cudaMallocHost(&pinned_, bytes), "cudaMallocHost (context read-back)");
            pinned_bytes_ = bytes;
        }
        detail::check_cuda(cudaMemcpyAsync(pinned_, from, bytes, cudaMemcpyDeviceToHost, stream()), what);
        const cudaError_t status = cudaStreamSynchronize(stream());
        if (status != cudaSuccess)
            detail::fail("step ", step, ": CUDA error at ", what,
                         " (a kernel launched since the last read-back faulted, or the copy did): ",
                         cudaGetErrorString(status));
        std::memcpy(static_cast<void*>(to), pinned_, bytes);
    }

private:
    void swap(execution_context& other) noexcept
    {
        std::swap(scratch_, other.scratch_);
        std::swap(scratch_bytes_, other.scratch_bytes_);
        std::swap(pinned_, other.pinned_);
        std::swap(pinned_bytes_, other.pinned_bytes_);
        std::swap(stream_, other.stream_);
    }

    void* scratch_ = nullptr;
    std::size_t scratch_bytes_ = 0;
    void* pinned_ = nullptr;
    std::size_t pinned_bytes_ = 0;
    cudaStream_t stream_ = nullptr;
};

/// While it lives, the calling thread's kernels and CUB calls go to the context's stream
/// (detail::current_stream); the stream before is restored after.
template <>
class stream_scope<cuda> {
public:
    explicit stream_scope(execution_context<cuda>& ctx) : before_(detail::current_stream())
    {
        detail::current_stream() = ctx.stream();
    }
    ~stream_scope() { detail::current_stream() = before_; }
    stream_scope(const stream_scope&) = delete;
    stream_scope& operator=(const stream_scope&) = delete;

private:
    cudaStream_t before_;
};

template <class T, class Transform, class Op>
void transform_reduce_into(execution_context<cuda>& ctx, std::size_t n, const Transform& f, T init, Op op, T* out)
{
    if (n == 0) {
        const stream_scope<cuda> on_stream(ctx);
        for_each_index(cuda{}, 1, detail::fill_value<T>{out, init});
        return;
    }
    // The transform runs in a kernel of its own, one index per thread, into the scratch; CUB
    // then reduces the plain array (see transform_reduce in exec/algorithms.cuh).
    const std::size_t value_bytes = detail::aligned_bytes(n * sizeof(T));
    std::size_t bytes = 0;
    detail::check_cuda(cub::DeviceReduce::Reduce(nullptr, bytes, static_cast<const T*>(nullptr), out, n, op, init,
                                                 ctx.stream()),
                       "cub::DeviceReduce::Reduce (size query)");
    unsigned char* base = static_cast<unsigned char*>(ctx.scratch(value_bytes + bytes));
    T* values = reinterpret_cast<T*>(base);
    const stream_scope<cuda> on_stream(ctx);
    for_each_index(cuda{}, n, detail::store_values<T, Transform>{f, values});
    detail::check_cuda(cub::DeviceReduce::Reduce(base + value_bytes, bytes, static_cast<const T*>(values), out, n, op,
                                                 init, ctx.stream()),
                       "cub::DeviceReduce::Reduce");
}
#endif

} // namespace sphere
