#pragma once
/// \file
/// CUDA and Thrust failures as sphere::error (CUDA builds only; empty otherwise):
/// `check_cuda(status, what)` after a CUDA runtime call, `guarded(what, f)` around a Thrust
/// call (Thrust throws its own types: bad_alloc, system_error), each naming the call.
#include "../core/config.cuh"
#include "../core/error.cuh"

#if SPHERE_CUDA_COMPILER
#include <exception>

namespace sphere {
namespace detail {

inline void check_cuda(cudaError_t status, const char* what)
{
    if (status != cudaSuccess) fail("CUDA error in ", what, ": ", cudaGetErrorString(status));
}

template <class F>
auto guarded(const char* what, F&& f) -> decltype(f())
{
    try {
        return f();
    } catch (const error&) {
        throw;
    } catch (const std::exception& e) {
        fail("CUDA error in ", what, ": ", e.what());
    }
}

/// A name for kernel launches of a body type in errors (the host compiler's signature of this
/// function, which spells out Body).
template <class Body>
const char* kernel_name()
{
    return __PRETTY_FUNCTION__;
}

} // namespace detail
} // namespace sphere
#endif
