#pragma once
/// \file
/// The collective operations the step needs, one dispatch point each per policy:
/// `sort_by_key` (stable, so equal keys keep their order and results are deterministic) and
/// `transform_reduce` over an index range.
///
/// Host reductions sum fixed chunks of host_chunk indices and then the chunk results in order,
/// so a floating-point sum is bit-identical for any number of OpenMP threads.
///
/// Each of these allocates temporary storage on CUDA, and those that return a value to the
/// host read it back: both count in device_activity() on every backend. The step's own
/// reductions go through an execution_context instead (exec/context.cuh), which does neither.
#include <cstddef>
#include <type_traits>
#include <vector>

#include <thrust/sort.h>
#include <thrust/system/cpp/execution_policy.h>
#include <thrust/system/omp/execution_policy.h>

#include "../core/config.cuh"
#include "activity.cuh"
#include "buffer.cuh"
#include "cuda_error.cuh"
#include "for_each.cuh"
#include "host_team.cuh"
#include "policy.cuh"

#if SPHERE_CUDA_COMPILER
#include <thrust/execution_policy.h>
#include <thrust/functional.h>
#include <thrust/iterator/counting_iterator.h>
#include <thrust/iterator/reverse_iterator.h>
#include <thrust/reduce.h>
#include <thrust/scan.h>
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

/// Sorts `keys[0, n)` ascending and applies the same permutation to `values`; stable. On the
/// calling thread when host_team() is 1 (Thrust's OpenMP sort would start all threads).
template <class Key, class Value>
void sort_by_key(host, Key* keys, Value* values, std::size_t n)
{
    ++device_activity().allocations;
    if (n >= host_parallel_threshold && host_team() > 1)
        thrust::stable_sort_by_key(thrust::omp::par, keys, keys + n, values);
    else thrust::stable_sort_by_key(thrust::cpp::par, keys, keys + n, values);
}

/// Replaces values[0, n) by their exclusive prefix sums (values[0] becomes 0); returns the
/// total of the original values. For the offsets of compressed rows.
inline std::size_t exclusive_scan_in_place(host, unsigned* values, std::size_t n)
{
    ++device_activity().allocations;
    device_activity().read_backs += 2; // the last value before and after the scan
    std::size_t sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const unsigned v = values[i];
        values[i] = static_cast<unsigned>(sum);
        sum += v;
    }
    return sum;
}

/// Replaces each values[i] by the least of values[i, n) (a suffix minimum). One pass on the
/// calling thread: a store per value, cheaper than a parallel scan at the sizes it serves.
inline void suffix_min_in_place(host, unsigned* values, std::size_t n)
{
    ++device_activity().allocations;
    for (std::size_t i = n; i-- > 1;)
        if (values[i] < values[i - 1]) values[i - 1] = values[i];
}

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
/// chunk are computed first, in a loop that may vectorise, and then combined in order.
template <class T, class Transform, class Op>
T host_reduce(std::size_t n, const Transform& f, T init, Op op, T* partial)
{
    const std::size_t chunks = host_reduce_chunks(n);
    const long long count = static_cast<long long>(chunks);
#pragma omp parallel for schedule(static) if (chunks > 1) num_threads(host_team())
    for (long long c = 0; c < count; ++c) {
        Transform local = f; // see detail::run_chunk
        const std::size_t begin = static_cast<std::size_t>(c) * host_chunk;
        const std::size_t end = begin + host_chunk < n ? begin + host_chunk : n;
        T acc = local(begin);
        if constexpr (std::is_arithmetic_v<T>) {
            T values[host_chunk];
            SPHERE_VECTORISE_LOOP
            for (std::size_t i = begin + 1; i < end; ++i) values[i - begin] = local(i);
            for (std::size_t i = begin + 1; i < end; ++i) acc = op(acc, values[i - begin]);
        } else {
            for (std::size_t i = begin + 1; i < end; ++i) acc = op(acc, local(i));
        }
        partial[static_cast<std::size_t>(c)] = acc;
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
template <class Key, class Value>
void sort_by_key(cuda, Key* keys, Value* values, std::size_t n)
{
    ++device_activity().allocations;
    detail::guarded("thrust::stable_sort_by_key", [&] { thrust::stable_sort_by_key(thrust::device, keys, keys + n, values); });
}

inline std::size_t exclusive_scan_in_place(cuda, unsigned* values, std::size_t n)
{
    ++device_activity().allocations;
    device_activity().read_backs += 2;
    if (n == 0) return 0;
    unsigned last = 0;
    detail::check_cuda(cudaMemcpy(&last, values + n - 1, sizeof last, cudaMemcpyDeviceToHost),
                       "cudaMemcpy (the last value before the scan)");
    detail::guarded("thrust::exclusive_scan", [&] { thrust::exclusive_scan(thrust::device, values, values + n, values); });
    unsigned before_last = 0;
    detail::check_cuda(cudaMemcpy(&before_last, values + n - 1, sizeof before_last, cudaMemcpyDeviceToHost),
                       "cudaMemcpy (the last value after the scan)");
    return std::size_t(before_last) + last;
}

inline void suffix_min_in_place(cuda, unsigned* values, std::size_t n)
{
    ++device_activity().allocations;
    if (n == 0) return;
    const thrust::reverse_iterator<unsigned*> last_first(values + n);
    detail::guarded("thrust::inclusive_scan (suffix minimum)", [&] {
        thrust::inclusive_scan(thrust::device, last_first, last_first + n, last_first, thrust::minimum<unsigned>());
    });
}

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
    return detail::guarded("thrust::reduce", [&] { return thrust::reduce(thrust::device, first, first + n, init, op); });
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

/// Position k of sorted keys marks where its value (key >> Shift, at most n) starts when it is
/// the first position with that value: each value present is written once.
template <class Key, int Shift>
struct mark_starts {
    const Key* key;
    std::size_t n;
    unsigned* start;
    SPHERE_HD std::size_t value(std::size_t k) const
    {
        const std::size_t v = static_cast<std::size_t>(key[k] >> Shift);
        return v < n ? v : n;
    }
    SPHERE_HD void operator()(std::size_t k) const
    {
        const std::size_t v = value(k);
        if (k == 0 || value(k - 1) != v) start[v] = static_cast<unsigned>(k);
    }
};
} // namespace detail

/// From `count` keys sorted ascending, read as values key >> Shift (values of n or more count
/// as n), sets start[v] for v = 0 .. n to the first position whose value is at least v (count
/// when there is none). Every start is set to count, the first position of each value present
/// marks it, and a suffix minimum gives each absent value the next present one's start: no
/// thread walks a run of absent values, however many there are.
template <int Shift = 0, class Policy, class Key>
void find_starts(Policy, const Key* key, std::size_t count, std::size_t n, unsigned* start)
{
    for_each_index(Policy{}, n + 1, detail::fill_value<unsigned>{start, static_cast<unsigned>(count)});
    for_each_index(Policy{}, count, detail::mark_starts<Key, Shift>{key, n, start});
    suffix_min_in_place(Policy{}, start, n + 1);
}

} // namespace sphere
