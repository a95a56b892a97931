#pragma once
/// \file
/// The uniform neighbour grid: order the particles by cell (ties by the particle's user index,
/// so the order depends on positions and user indices alone, not on where the particles are
/// stored), gather positions in cell order and find where each cell starts in that order. On
/// CUDA a radix sort of keys (cell, user index) orders them; on the host a counting sort by
/// cell, which needs neither keys nor the sort's second copy of them (20 B per particle).
#include <algorithm>
#include <cstddef>
#include <type_traits>

#include "../core/vec.cuh"
#include "../exec/buffer.cuh"
#include "../exec/collectives.cuh"
#include "../exec/context.cuh"
#include "../exec/for_each.cuh"
#include "../exec/policy.cuh"
#include "../particles/state.cuh"
#include "geometry.cuh"

namespace sphere {

/// Kernel view of a built grid. The particles of cells [a, b] (consecutive along x) sit at
/// sorted positions [cell_start[a], cell_start[b + 1]).
template <class Real>
struct grid_view {
    grid_geometry<Real> geometry;
    std::size_t n;               ///< number of particles
    const unsigned* order;       ///< particle index at each sorted position
    const vec4<Real>* sorted_x;  ///< position and radius at each sorted position
    const unsigned* cell_start;  ///< first sorted position of each cell; cell_count() + 1 entries
};

namespace detail {
/// Sort key of slot i: its cell above bit `tie_bits`, its user index (or its slot when the
/// view has no user indices) in the bits below, so that the sort needs only as many bits as
/// the cells and particles take.
template <class Real>
struct hash_particles {
    grid_geometry<Real> g;
    const vec4<Real>* x;
    const unsigned* user; ///< may be null
    int tie_bits;
    unsigned long long* key;
    unsigned* order;
    SPHERE_HD void operator()(std::size_t i) const
    {
        const unsigned tie = user ? user[i] : static_cast<unsigned>(i);
        key[i] = (static_cast<unsigned long long>(g.cell_of(x[i].xyz())) << tie_bits) | tie;
        order[i] = static_cast<unsigned>(i);
    }
};

/// The host's ordering: a counting sort of slots 0 .. n - 1 by cell into `order`, then each
/// cell's slots by user index (by slot without user indices, which the counting sort gives
/// already); start[c] is the first position of cell c, start[cells] = n. On the calling thread.
template <class Real>
void order_by_cell(const grid_geometry<Real>& g, const vec4<Real>* x, const unsigned* user, std::size_t n,
                   unsigned* order, unsigned* start)
{
    const std::size_t cells = g.cell_count();
    std::fill(start, start + cells + 1, 0u);
    for (std::size_t i = 0; i < n; ++i) ++start[g.cell_of(x[i].xyz()) + 1];
    for (std::size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
    // start[c] advances past each slot placed in cell c, ending where cell c + 1 starts
    for (std::size_t i = 0; i < n; ++i) order[start[g.cell_of(x[i].xyz())]++] = static_cast<unsigned>(i);
    for (std::size_t c = cells; c > 0; --c) start[c] = start[c - 1];
    start[0] = 0;
    if (!user) return;
    for (std::size_t c = 0; c < cells; ++c)
        if (start[c + 1] - start[c] > 1)
            std::sort(order + start[c], order + start[c + 1], [user](unsigned a, unsigned b) { return user[a] < user[b]; });
}

} // namespace detail

template <class Real, class Policy>
class neighbor_grid {
public:
    explicit neighbor_grid(const grid_geometry<Real>& g = {}) : geometry_(g) {}

    const grid_geometry<Real>& geometry() const { return geometry_; }

    /// Rebuilds the cell lists from the particles' current positions (held in Real: a grid
    /// is laid in the type of the positions, coord_t of the particles' precision P) and
    /// gathers the positions in sorted order into the grid's own array. No allocation once the
    /// particle count stays.
    template <class P>
    void build(execution_context<Policy>& ctx, const particle_view<P>& p)
    {
        order(ctx, p);
        if (own_sorted_x_.size() != p.n) own_sorted_x_.resize(p.n);
        for_each_index(Policy{}, p.n, detail::gather<vec4<Real>>{p.x, order_.data(), own_sorted_x_.data()});
        sorted_x_ = own_sorted_x_.data();
    }

    /// Rebuilds the cell lists like build() but leaves the positions where they are: the
    /// caller moves them into the grid's order (e.g. particle_state::permute) and hands them
    /// to sorted() before it reads the view's positions; the grid's own array is freed. No
    /// allocation once the particle count stays (CUDA sorts and scans through `ctx`'s scratch;
    /// the host needs none).
    template <class P>
    void order(execution_context<Policy>& ctx, const particle_view<P>& p)
    {
        static_assert(std::is_same_v<coord_t<P>, Real>, "the grid is laid in the type of the positions");
        const std::size_t cells = geometry_.cell_count();
        n_ = p.n;
        sorted_x_ = nullptr;
        if (order_.size() != p.n) order_.resize(p.n);
        if (cell_start_.size() != cells + 1) cell_start_.resize(cells + 1);
        if constexpr (runs_in_blocks<Policy>) { // host memory, read and written in place
            detail::order_by_cell(geometry_, p.x, p.user, p.n, order_.data(), cell_start_.data());
        } else {
            if (key_.size() != p.n) key_.resize(p.n);
            const int tie_bits = bits_for(p.n - 1);
            for_each_index(Policy{}, p.n,
                           detail::hash_particles<Real>{geometry_, p.x, p.user, tie_bits, key_.data(), order_.data()});
            sort_by_key(ctx, key_.data(), order_.data(), p.n, tie_bits + bits_for(cells - 1));
            // where each cell starts, for any number of empty cells (a tall box)
            find_starts(ctx, key_.data(), tie_bits, p.n, cells, cell_start_.data());
        }
    }

    /// The positions and radii in the order of the last order() (p.n elements of policy
    /// memory that the caller keeps unchanged while it uses the view); frees the grid's own.
    void sorted(const vec4<Real>* sorted_x)
    {
        if (own_sorted_x_.size()) own_sorted_x_ = buffer<vec4<Real>, Policy>();
        sorted_x_ = sorted_x;
    }

    grid_view<Real> view() const
    {
        return {geometry_, n_, order_.data(), sorted_x_, cell_start_.data()};
    }

private:
    grid_geometry<Real> geometry_;
    std::size_t n_ = 0;                      ///< particles of the last build
    buffer<unsigned long long, Policy> key_; ///< sort keys (CUDA only)
    buffer<unsigned, Policy> order_, cell_start_;
    buffer<vec4<Real>, Policy> own_sorted_x_; ///< empty when the caller holds the sorted positions
    const vec4<Real>* sorted_x_ = nullptr;
};

} // namespace sphere
