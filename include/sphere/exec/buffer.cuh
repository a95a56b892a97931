#pragma once
/// \file
/// `buffer<T, Policy>`: an owning array in the memory space of a policy.
#include <cstddef>
#include <utility>
#include <vector>

#include "../core/config.cuh"
#include "policy.cuh"

#if SPHERE_CUDA_COMPILER
#include <thrust/copy.h>
#include <thrust/device_vector.h>
#endif

namespace sphere {

template <class T, class Policy>
class buffer;

/// Host memory (a std::vector underneath).
template <class T>
class buffer<T, host> {
public:
    using value_type = T;
    buffer() = default;
    explicit buffer(std::size_t n, const T& value = T{}) : data_(n, value) {}

    std::size_t size() const { return data_.size(); }
    T* data() { return data_.data(); }
    const T* data() const { return data_.data(); }
    void resize(std::size_t n, const T& value = T{}) { data_.resize(n, value); }
    void assign(const std::vector<T>& values) { data_ = values; }
    void assign(std::vector<T>&& values) { data_ = std::move(values); }
    std::vector<T> to_host() const { return data_; }
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
    explicit buffer(std::size_t n, const T& value = T{}) : data_(n, value) {}

    std::size_t size() const { return data_.size(); }
    T* data() { return thrust::raw_pointer_cast(data_.data()); }
    const T* data() const { return thrust::raw_pointer_cast(data_.data()); }
    void resize(std::size_t n, const T& value = T{}) { data_.resize(n, value); }
    void assign(const std::vector<T>& values) { data_.assign(values.begin(), values.end()); }
    std::vector<T> to_host() const
    {
        std::vector<T> out(data_.size());
        thrust::copy(data_.begin(), data_.end(), out.begin());
        return out;
    }
    void swap(buffer& other) noexcept { data_.swap(other.data_); }

private:
    thrust::device_vector<T> data_;
};
#endif

} // namespace sphere
