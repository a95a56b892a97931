#pragma once
/// \file
/// `buffer<T, Policy>`: an owning array in the memory space of a policy. Every allocation (a
/// buffer made or grown beyond its capacity) and every copy to the host counts in
/// device_activity() on both backends.
#include <cstddef>
#include <new>
#include <stdexcept>
#include <utility>
#include <vector>

#include "../core/config.cuh"
#include "../core/error.cuh"
#include "activity.cuh"
#include "cuda_error.cuh"
#include "policy.cuh"

#if SPHERE_CUDA_COMPILER
#include <thrust/copy.h>
#include <thrust/device_vector.h>
#endif

namespace sphere {

template <class T, class Policy>
class buffer;

namespace detail {
/// Counts an allocation when `size` values do not fit `capacity`.
inline void count_growth(std::size_t size, std::size_t capacity)
{
    if (size > capacity) ++device_activity().allocations;
}

/// Runs f, an allocation of n values of `bytes` bytes in host memory, and turns its failure
/// (std::bad_alloc, std::length_error) into a sphere::error that says how much was asked.
template <class F>
void host_allocation(std::size_t n, std::size_t bytes, F&& f)
{
    try {
        f();
    } catch (const std::bad_alloc&) {
        fail("host memory: allocating ", n, " values of ", bytes, " B (", double(n) * double(bytes) / 1073741824.0,
             " GiB) failed");
    } catch (const std::length_error&) {
        fail("host memory: ", n, " values of ", bytes, " B are more than one array can hold");
    }
}
} // namespace detail

/// Host memory (a std::vector underneath).
template <class T>
class buffer<T, host> {
public:
    using value_type = T;
    buffer() = default;
    explicit buffer(std::size_t n, const T& value = T{}) { resize(n, value); }
    buffer(const buffer& other) : data_((detail::count_growth(other.size(), 0), other.data_)) {}
    buffer(buffer&&) noexcept = default;
    buffer& operator=(const buffer& other)
    {
        detail::count_growth(other.size(), data_.capacity());
        data_ = other.data_;
        return *this;
    }
    buffer& operator=(buffer&&) noexcept = default;

    std::size_t size() const { return data_.size(); }
    T* data() { return data_.data(); }
    const T* data() const { return data_.data(); }
    void resize(std::size_t n, const T& value = T{})
    {
        detail::count_growth(n, data_.capacity());
        detail::host_allocation(n, sizeof(T), [&] { data_.resize(n, value); });
    }
    void assign(const std::vector<T>& values)
    {
        detail::count_growth(values.size(), data_.capacity());
        data_ = values;
    }
    void assign(std::vector<T>&& values)
    {
        detail::count_growth(values.size(), data_.capacity());
        data_ = std::move(values);
    }
    std::vector<T> to_host() const
    {
        ++device_activity().read_backs;
        return data_;
    }
    void swap(buffer& other) noexcept { data_.swap(other.data_); }

private:
    std::vector<T> data_;
};

#if SPHERE_CUDA_COMPILER
/// GPU global memory (a thrust::device_vector underneath).
template <class T>
class buffer<T, cuda> {
public:
    using value_type = T;
    buffer() = default;
    explicit buffer(std::size_t n, const T& value = T{}) { resize(n, value); }
    buffer(const buffer& other) { *this = other; }
    buffer(buffer&&) noexcept = default;
    buffer& operator=(const buffer& other)
    {
        detail::count_growth(other.size(), data_.capacity());
        detail::guarded("a device allocation (buffer copy)", [&] { data_ = other.data_; });
        return *this;
    }
    buffer& operator=(buffer&&) noexcept = default;

    std::size_t size() const { return data_.size(); }
    T* data() { return thrust::raw_pointer_cast(data_.data()); }
    const T* data() const { return thrust::raw_pointer_cast(data_.data()); }
    void resize(std::size_t n, const T& value = T{})
    {
        detail::count_growth(n, data_.capacity());
        detail::guarded("a device allocation (buffer resize)", [&] { data_.resize(n, value); });
    }
    void assign(const std::vector<T>& values)
    {
        detail::count_growth(values.size(), data_.capacity());
        detail::guarded("a copy to the device (buffer assign)", [&] { data_.assign(values.begin(), values.end()); });
    }
    std::vector<T> to_host() const
    {
        ++device_activity().read_backs;
        std::vector<T> out(data_.size());
        detail::guarded("a copy to the host (buffer to_host)", [&] { thrust::copy(data_.begin(), data_.end(), out.begin()); });
        return out;
    }
    void swap(buffer& other) noexcept { data_.swap(other.data_); }

private:
    thrust::device_vector<T> data_;
};
#endif

} // namespace sphere
