#pragma once
/// \file
/// How the forces of the pair contacts reach the particles (docs/architecture.md,
/// "Interaction"). Both ways evaluate each listed pair once and give results that do not
/// depend on the thread count or on where particles are stored; they differ in the order in
/// which a particle's contributions are summed, so they agree to round-off, not bit for bit.
#include <cstdint>

namespace sphere {

enum class pair_summation : std::uint8_t {
    automatic = 0, ///< slabs on the host backend, gather on CUDA
    /// Each pair is added to both of its particles as it is evaluated, the layers of the
    /// neighbour grid in two phases (even, then odd) so that no two threads ever write the same
    /// particle; the evaluations run in SIMD tiles. Host backend only.
    slabs = 1,
    /// Each pair's result is stored per pair, then each particle sums its own and its
    /// partners' results (a reverse index): no write conflicts, one thread per particle.
    gather = 2,
};

} // namespace sphere
