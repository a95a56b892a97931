#pragma once
/// \file
/// The uniform neighbour grid: order the particles by cell (ties by the particle's user index,
/// so the order depends on positions and user indices alone, not on where the particles are
/// stored), find where each cell starts in that order, and gather the particles in it (or
/// read them where the caller has put them in it). On CUDA a radix sort of keys (cell, user
/// index) orders them; on the host a counting sort by cell, which needs neither keys nor the
/// sort's second copy of them (20 B per particle). Also each particle's reference position in
/// its own cell (reference_in_cell).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "../boundary/position_lattice.cuh"
#include "../core/vec.cuh"
#include "../exec/buffer.cuh"
#include "../exec/collectives.cuh"
#include "../exec/context.cuh"
#include "../exec/for_each.cuh"
#include "../exec/policy.cuh"
#include "../particles/state.cuh"
#include "geometry.cuh"

namespace sphere {

/// Where a grid reads the particles: their positions and radii (`x`, position in xyz, radius in
/// w) and, optionally, their reference positions on a lattice (boundary/position_lattice.cuh;
/// each in its particle's cell: reference_in_cell), which decide the near partners.
template <class Real>
struct position_source {
    const vec4<Real>* x = nullptr;
    const typename position_lattice<Real>::stored* reference = nullptr; ///< may be null
    position_lattice<Real> lattice{};
};

/// The reference position of a particle at x (boundary/position_lattice.cuh): the nearest
/// lattice point, or, along an axis where that lies across a face of x's grid cell, the point
/// a step back, on x's side: one in x's cell (cells are far wider than a step). So the
/// reference positions place every particle in the cell its position does, and a position lies
/// at most a step from its reference position along each axis.
template <class Real>
SPHERE_HDI typename position_lattice<Real>::stored reference_in_cell(const grid_geometry<Real>& g,
                                                                     const position_lattice<Real>& l,
                                                                     const vec3<Real>& x)
{
    typename position_lattice<Real>::stored q = l.encode(x);
    if constexpr (position_lattice<Real>::fixed_point) {
        const vec3<Real> p = l.decode(q);
        const auto inside = [&](std::uint32_t& n, Real pa, Real xa, int a) {
            if (g.coordinate(pa, a) == g.coordinate(xa, a)) return;
            if (pa > xa && n > 0u) --n;
            else if (pa < xa && n < 4294967295u) ++n;
        };
        inside(q.x, p.x, x.x, 0);
        inside(q.y, p.y, x.y, 1);
        inside(q.z, p.z, x.z, 2);
    }
    return q;
}

/// Kernel view of a built grid. The particles of cells [a, b] (consecutive along x) sit at
/// sorted positions [cell_start[a], cell_start[b + 1]).
template <class Real>
struct grid_view {
    grid_geometry<Real> geometry;
    std::size_t n;                    ///< number of particles
    const unsigned* order;            ///< particle index at each sorted position
    position_source<Real> sorted_x;   ///< the particles at each sorted position
    const unsigned* cell_start;       ///< first sorted position of each cell; cell_count() + 1 entries
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

/// to[k] = the reference position of x[k] (reference_in_cell).
template <class Real>
struct place_references {
    grid_geometry<Real> geometry;
    position_lattice<Real> lattice;
    const vec4<Real>* x;
    typename position_lattice<Real>::stored* to;
    SPHERE_HD void operator()(std::size_t k) const { to[k] = reference_in_cell(geometry, lattice, x[k].xyz()); }
};

/// The particles of `source` in sorted order: x[k] = source.x[order[k]], and so the reference
/// positions when there are some.
template <class Real>
struct gather_positions {
    position_source<Real> source;
    const unsigned* order;
    vec4<Real>* x;
    typename position_lattice<Real>::stored* reference;
    SPHERE_HD void operator()(std::size_t k) const
    {
        x[k] = source.x[order[k]];
        if (source.reference) reference[k] = source.reference[order[k]];
    }
};

} // namespace detail

template <class Real, class Policy>
class neighbor_grid {
public:
    explicit neighbor_grid(const grid_geometry<Real>& g = {}) : geometry_(g) {}

    const grid_geometry<Real>& geometry() const { return geometry_; }

    /// Rebuilds the cell lists for the particles 0 .. n - 1 of `source`, by their positions (in
    /// Real: a grid is laid in the type of the positions), with user indices `user` (ties in a
    /// cell go by them; may be null: by index) and gathers the particles in sorted order into
    /// the grid's own arrays. No allocation once the particle count stays.
    void build(execution_context<Policy>& ctx, std::size_t n, const position_source<Real>& source, const unsigned* user)
    {
        order(ctx, n, source, user);
        if (own_sorted_x_.size() != n) own_sorted_x_.resize(n);
        if (own_reference_.size() != (source.reference ? n : 0)) own_reference_.resize(source.reference ? n : 0);
        for_each_index(Policy{}, n,
                       detail::gather_positions<Real>{source, order_.data(), own_sorted_x_.data(), own_reference_.data()});
        sorted_x_ = position_source<Real>{own_sorted_x_.data(), source.reference ? own_reference_.data() : nullptr,
                                          source.lattice};
    }

    /// build() from the particles' current positions.
    template <class P>
    void build(execution_context<Policy>& ctx, const particle_view<P>& p)
    {
        static_assert(std::is_same_v<coord_t<P>, Real>, "the grid is laid in the type of the positions");
        build(ctx, p.n, position_source<Real>{p.x}, p.user);
    }

    /// Rebuilds the cell lists like build() but gathers nothing: the caller moves the
    /// particles into the grid's order (e.g. particle_state::permute) and hands their positions
    /// to sorted() before it reads the view's. No allocation once the particle count stays
    /// (CUDA sorts and scans through `ctx`'s scratch; the host needs none).
    void order(execution_context<Policy>& ctx, std::size_t n, const position_source<Real>& source, const unsigned* user)
    {
        const std::size_t cells = geometry_.cell_count();
        n_ = n;
        sorted_x_ = position_source<Real>{};
        if (order_.size() != n) order_.resize(n);
        if (cell_start_.size() != cells + 1) cell_start_.resize(cells + 1);
        if constexpr (runs_in_blocks<Policy>) { // host memory, read and written in place
            detail::order_by_cell(geometry_, source.x, user, n, order_.data(), cell_start_.data());
        } else {
            if (key_.size() != n) key_.resize(n);
            const int tie_bits = bits_for(n - 1);
            for_each_index(Policy{}, n,
                           detail::hash_particles<Real>{geometry_, source.x, user, tie_bits, key_.data(), order_.data()});
            sort_by_key(ctx, key_.data(), order_.data(), n, tie_bits + bits_for(cells - 1));
            // where each cell starts, for any number of empty cells (a tall box)
            find_starts(ctx, key_.data(), tie_bits, n, cells, cell_start_.data());
        }
    }

    /// The particles in the order of the last order() (policy memory that the caller keeps
    /// unchanged while it uses the view); frees the grid's own arrays.
    void sorted(const position_source<Real>& sorted_x)
    {
        if (own_sorted_x_.size()) own_sorted_x_ = buffer<vec4<Real>, Policy>();
        if (own_reference_.size()) own_reference_ = buffer<typename position_lattice<Real>::stored, Policy>();
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
    buffer<vec4<Real>, Policy> own_sorted_x_; ///< empty when the caller holds the sorted particles
    buffer<typename position_lattice<Real>::stored, Policy> own_reference_; ///< with own_sorted_x_, if any
    position_source<Real> sorted_x_;
};

} // namespace sphere
