#pragma once
/// \file
/// `device_activity()`: what the calling thread's sphere calls have cost a GPU in
/// synchronisations: allocations of the policy's memory and read-backs (copies from it to the
/// host that the host waits for). Counted on every backend, the host's included, at the places
/// where the CUDA build makes them (a buffer that grows, a sort's or a scan's temporary
/// storage, a result handed to the host), so that a test on the host counts what a GPU run
/// would do (docs/architecture.md, *Execution context*).
#include <cstddef>

namespace sphere {

struct device_activity_counts {
    std::size_t allocations = 0; ///< allocations of the policy's memory
    std::size_t read_backs = 0;  ///< copies to the host that the host waits for
};

/// The calling thread's counts since it started (reset them freely).
inline device_activity_counts& device_activity()
{
    static thread_local device_activity_counts counts;
    return counts;
}

} // namespace sphere
