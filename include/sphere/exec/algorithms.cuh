#pragma once
/// \file
/// Reductions over an index range, one dispatch point each per policy: the operators
/// (`plus_op`, `max_op`, `min_op`) and `transform_reduce`, which returns its result to the host
/// (diagnostics and set-up; the step's own reductions and the rebuild's sorts and scans go
/// through an execution context: exec/context.cuh, exec/collectives.cuh).
///
/// Host reductions sum fixed chunks of host_chunk indices and then the chunk results in order,
/// so a floating-point sum is bit-identical for any number of OpenMP threads.
///
/// transform_reduce allocates temporary storage on CUDA and reads its result back: both count
/// in device_activity() on every backend.
#include <cstddef>
#include <type_traits>
#include <vector>

#include "../core/config.cuh"
#include "activity.cuh"
#include "buffer.cuh"
#include "cuda_error.cuh"
#include "for_each.cuh"
#include "host_team.cuh"
#include "policy.cuh"

#if SPHERE_CUDA_COMPILER
#include <thrust/execution_policy.h>
#include <thrust/reduce.h>
#endif

namespace sphere {

/// a + b
struct plus_op {
    template <class T> SPHERE_HD T operator()(const T& a, const T& b) const { return a + b; }
};
/// max(a, b)
struct max_op {
    template <class T> SPHERE_HD T operator()(const T& a, const T& b) const { return a < b ? b : a; }
};
/// min(a, b)
struct min_op {
    template <class T> SPHERE_HD T operator()(const T& a, const T& b) const { return b < a ? b : a; }
};

/// Whether op's result over a set of numbers is the same in any order (the largest, the
/// smallest; NaN and the sign of zero aside): host_reduce then combines a chunk's values in interleaved lanes, which
/// the CPU overlaps, rather than in one chain of dependent operations.
template <class Op>
inline constexpr bool order_free = std::is_same_v<Op, max_op> || std::is_same_v<Op, min_op>;

namespace detail {
/// values[i] = f(i): a reduction's transform as a kernel of its own (CUDA).
template <class T, class Transform>
struct store_values {
    Transform f;
    T* values;
    SPHERE_HD void operator()(std::size_t i) const { values[i] = f(i); }
};

/// Number of partial results of a host reduction over n indices.
inline std::size_t host_reduce_chunks(std::size_t n) { return (n + host_chunk - 1) / host_chunk; }

/// init op f(0) op f(1) ... op f(n-1), in a fixed association order: in order within chunks of
/// host_chunk indices (small enough to share n = 1e4 evenly between threads), then the chunks
/// in order; `partial` holds host_reduce_chunks(n) values. For a number type T the values of a
/// chunk are computed first, in a loop that may vectorise, and then combined in order, or for an
/// order_free op in eight lanes, each of every eighth value, and then the lanes.
template <class T, class Transform, class Op>
T host_reduce(std::size_t n, const Transform& f, T init, Op op, T* partial)
{
    const std::size_t chunks = host_reduce_chunks(n);
    const long long count = static_cast<long long>(chunks);
    const auto chunk = [&](long long c) {
        Transform local = f; // see detail::run_chunk
        const std::size_t begin = static_cast<std::size_t>(c) * host_chunk;
        const std::size_t end = begin + host_chunk < n ? begin + host_chunk : n;
        T acc = local(begin);
        if constexpr (std::is_arithmetic_v<T>) {
            T values[host_chunk];
            SPHERE_VECTORISE_LOOP
            for (std::size_t i = begin + 1; i < end; ++i) values[i - begin] = local(i);
            if constexpr (order_free<Op>) {
                constexpr int ways = 8;
                T lane[ways];
                for (int k = 0; k < ways; ++k) lane[k] = acc;
                std::size_t i = begin + 1;
                for (; i + ways <= end; i += ways)
                    for (int k = 0; k < ways; ++k) lane[k] = op(lane[k], values[i - begin + k]);
                for (; i < end; ++i) lane[0] = op(lane[0], values[i - begin]);
                for (int k = 1; k < ways; ++k) lane[0] = op(lane[0], lane[k]);
                acc = lane[0];
            } else {
                for (std::size_t i = begin + 1; i < end; ++i) acc = op(acc, values[i - begin]);
            }
        } else {
            for (std::size_t i = begin + 1; i < end; ++i) acc = op(acc, local(i));
        }
        partial[static_cast<std::size_t>(c)] = acc;
    };
    if (chunks > 1 && host_team() > 1) { // else no OpenMP region at all (see for_each_index)
#pragma omp parallel for schedule(static) num_threads(host_team())
        for (long long c = 0; c < count; ++c) chunk(c);
    } else {
        for (long long c = 0; c < count; ++c) chunk(c);
    }
    T result = init;
    for (std::size_t c = 0; c < chunks; ++c) result = op(result, partial[c]);
    return result;
}
} // namespace detail

/// Returns init op f(0) op f(1) ... op f(n-1) to the host, in the fixed association order of
/// detail::host_reduce (bit-identical for any number of threads).
template <class T, class Transform, class Op>
T transform_reduce(host, std::size_t n, const Transform& f, T init, Op op)
{
    device_activity().allocations += 2; // on CUDA: the array of values and the reduction's storage
    ++device_activity().read_backs;
    std::vector<T> partial(detail::host_reduce_chunks(n), init);
    return detail::host_reduce(n, f, init, op, partial.data());
}

#if SPHERE_CUDA_COMPILER
template <class T, class Transform, class Op>
T transform_reduce(cuda, std::size_t n, const Transform& f, T init, Op op)
{
    // The transform runs in a kernel of its own, one index per thread, into an array that a
    // plain reduction then combines: inlined into the reduction, which unrolls several indices
    // per thread, a heavy transform spills registers (tests/check_ptxas.py).
    ++device_activity().allocations; // the reduction's storage (the array counts itself)
    ++device_activity().read_backs;
    if (n == 0) return init;
    buffer<T, cuda> values(n);
    for_each_index(cuda{}, n, detail::store_values<T, Transform>{f, values.data()});
    T* first = values.data();
    return detail::guarded("thrust::reduce", [&] { return thrust::reduce(thrust::cuda::par.on(detail::current_stream()), first, first + n, init, op); });
}
#endif

namespace detail {
/// to[i] = value (kernel over the indices of `to`).
template <class T>
struct fill_value {
    T* to;
    T value;
    SPHERE_HD void operator()(std::size_t i) const { to[i] = value; }
};
} // namespace detail

} // namespace sphere
