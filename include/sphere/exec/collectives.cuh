#pragma once
/// \file
/// The collective operations of a rebuild, through an execution context (exec/context.cuh):
/// `sort_by_key` (a stable radix sort over the keys' low bits), `exclusive_scan` and
/// `suffix_min` in place, and `find_starts` (where each value of sorted keys starts). Their
/// temporary storage is the context's scratch, which grows only, and their results stay in
/// the policy's memory: after warm-up none of them allocates or reads back (a scan's total is
/// its array's last element, for the kernels that follow to read).
#include <cstddef>
#include <cstring>

#include "../core/config.cuh"
#include "context.cuh"
#include "cuda_error.cuh"
#include "for_each.cuh"
#include "policy.cuh"

#if SPHERE_CUDA_COMPILER
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <thrust/iterator/reverse_iterator.h>
#endif

namespace sphere {

/// Sorts keys[0, n) ascending by their bits [0, bits) and applies the same permutation to
/// `values`; stable, so equal keys keep their order and results are deterministic. On the
/// host a least-significant-digit radix sort on the calling thread, eight bits a pass.
template <class Key, class Value>
void sort_by_key(execution_context<host>& ctx, Key* keys, Value* values, std::size_t n, int bits)
{
    if (n < 2) return;
    unsigned char* base = static_cast<unsigned char*>(
        ctx.scratch(detail::aligned_bytes(n * sizeof(Key)) + detail::aligned_bytes(n * sizeof(Value))));
    Key* other_keys = reinterpret_cast<Key*>(base);
    Value* other_values = reinterpret_cast<Value*>(base + detail::aligned_bytes(n * sizeof(Key)));
    Key* from_k = keys;
    Value* from_v = values;
    for (int shift = 0; shift < bits; shift += 8) {
        std::size_t start[257] = {};
        for (std::size_t i = 0; i < n; ++i) ++start[((from_k[i] >> shift) & 255u) + 1];
        if (start[((from_k[0] >> shift) & 255u) + 1] == n) continue; // one digit: nothing to move
        for (int d = 0; d < 256; ++d) start[d + 1] += start[d];
        Key* to_k = from_k == keys ? other_keys : keys;
        Value* to_v = from_v == values ? other_values : values;
        for (std::size_t i = 0; i < n; ++i) {
            const std::size_t at = start[(from_k[i] >> shift) & 255u]++;
            to_k[at] = from_k[i];
            to_v[at] = from_v[i];
        }
        from_k = to_k;
        from_v = to_v;
    }
    if (from_k != keys) {
        std::memcpy(static_cast<void*>(keys), from_k, n * sizeof(Key));
        std::memcpy(static_cast<void*>(values), from_v, n * sizeof(Value));
    }
}

/// Replaces values[0, n) by their exclusive prefix sums (values[0] becomes 0). With a last
/// value of 0, the total of the others ends up in values[n - 1].
inline void exclusive_scan(execution_context<host>&, unsigned* values, std::size_t n)
{
    unsigned sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const unsigned v = values[i];
        values[i] = sum;
        sum += v;
    }
}

/// Replaces each values[i] by the least of values[i, n) (a suffix minimum).
inline void suffix_min(execution_context<host>&, unsigned* values, std::size_t n)
{
    for (std::size_t i = n; i-- > 1;)
        if (values[i] < values[i - 1]) values[i - 1] = values[i];
}

#if SPHERE_CUDA_COMPILER
template <class Key, class Value>
void sort_by_key(execution_context<cuda>& ctx, Key* keys, Value* values, std::size_t n, int bits)
{
    if (n < 2) return;
    cub::DoubleBuffer<Key> k(keys, nullptr);
    cub::DoubleBuffer<Value> v(values, nullptr);
    std::size_t temp = 0;
    detail::check_cuda(cub::DeviceRadixSort::SortPairs(nullptr, temp, k, v, n, 0, bits, ctx.stream()),
                       "cub::DeviceRadixSort::SortPairs (size query)");
    const std::size_t key_bytes = detail::aligned_bytes(n * sizeof(Key)), value_bytes = detail::aligned_bytes(n * sizeof(Value));
    unsigned char* base = static_cast<unsigned char*>(ctx.scratch(key_bytes + value_bytes + temp));
    k = cub::DoubleBuffer<Key>(keys, reinterpret_cast<Key*>(base));
    v = cub::DoubleBuffer<Value>(values, reinterpret_cast<Value*>(base + key_bytes));
    detail::check_cuda(cub::DeviceRadixSort::SortPairs(base + key_bytes + value_bytes, temp, k, v, n, 0, bits, ctx.stream()),
                       "cub::DeviceRadixSort::SortPairs");
    if (k.Current() != keys) {
        detail::check_cuda(cudaMemcpyAsync(keys, k.Current(), n * sizeof(Key), cudaMemcpyDeviceToDevice, ctx.stream()),
                           "cudaMemcpyAsync (sorted keys)");
        detail::check_cuda(cudaMemcpyAsync(values, v.Current(), n * sizeof(Value), cudaMemcpyDeviceToDevice, ctx.stream()),
                           "cudaMemcpyAsync (sorted values)");
    }
}

inline void exclusive_scan(execution_context<cuda>& ctx, unsigned* values, std::size_t n)
{
    if (n == 0) return;
    std::size_t temp = 0;
    detail::check_cuda(cub::DeviceScan::ExclusiveSum(nullptr, temp, values, n, ctx.stream()),
                       "cub::DeviceScan::ExclusiveSum (size query)");
    detail::check_cuda(cub::DeviceScan::ExclusiveSum(ctx.scratch(temp), temp, values, n, ctx.stream()),
                       "cub::DeviceScan::ExclusiveSum");
}

inline void suffix_min(execution_context<cuda>& ctx, unsigned* values, std::size_t n)
{
    if (n == 0) return;
    const thrust::reverse_iterator<unsigned*> last_first(values + n);
    const min_op op{};
    std::size_t temp = 0;
    detail::check_cuda(cub::DeviceScan::InclusiveScan(nullptr, temp, last_first, last_first, op, n, ctx.stream()),
                       "cub::DeviceScan::InclusiveScan (suffix minimum, size query)");
    detail::check_cuda(cub::DeviceScan::InclusiveScan(ctx.scratch(temp), temp, last_first, last_first, op, n, ctx.stream()),
                       "cub::DeviceScan::InclusiveScan (suffix minimum)");
}
#endif

namespace detail {
/// Position k of sorted keys marks where its value (key >> shift, at most n) starts when it
/// is the first position with that value: each value present is written once.
template <class Key>
struct mark_starts {
    const Key* key;
    int shift;
    std::size_t n;
    unsigned* start;
    SPHERE_HD std::size_t value(std::size_t k) const
    {
        const std::size_t v = static_cast<std::size_t>(key[k] >> shift);
        return v < n ? v : n;
    }
    SPHERE_HD void operator()(std::size_t k) const
    {
        const std::size_t v = value(k);
        if (k == 0 || value(k - 1) != v) start[v] = static_cast<unsigned>(k);
    }
};
} // namespace detail

/// From `count` keys sorted ascending, read as values key >> shift (values of n or more count
/// as n), sets start[v] for v = 0 .. n to the first position whose value is at least v (count
/// when there is none). Every start is set to count, the first position of each value present
/// marks it, and a suffix minimum gives each absent value the next present one's start: no
/// thread walks a run of absent values, however many there are.
template <class Policy, class Key>
void find_starts(execution_context<Policy>& ctx, const Key* key, int shift, std::size_t count, std::size_t n,
                 unsigned* start)
{
    for_each_index(Policy{}, n + 1, detail::fill_value<unsigned>{start, static_cast<unsigned>(count)});
    for_each_index(Policy{}, count, detail::mark_starts<Key>{key, shift, n, start});
    suffix_min(ctx, start, n + 1);
}

/// The number of bits that hold the values 0 .. largest.
inline int bits_for(std::size_t largest)
{
    int bits = 0;
    while (bits < 64 && (largest >> bits) != 0) ++bits;
    return bits;
}

} // namespace sphere
