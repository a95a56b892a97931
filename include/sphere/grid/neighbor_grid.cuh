#pragma once
/// \file
/// The uniform neighbour grid: hash each particle to its cell, sort by cell (stable),
/// gather positions in cell order and find each cell's [start, end) in the sorted order.
#include <cstddef>

#include "../core/vec.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/for_each.cuh"
#include "../particles/state.cuh"
#include "geometry.cuh"

namespace sphere {

/// Kernel view of a built grid.
template <class Real>
struct grid_view {
    grid_geometry<Real> geometry;
    const unsigned* order;       ///< particle index at each sorted position
    const vec4<Real>* sorted_x;  ///< position and radius at each sorted position
    const unsigned* cell_start;  ///< first sorted position of each cell (empty_cell if none)
    const unsigned* cell_end;    ///< one past the last sorted position of each cell
    static constexpr unsigned empty_cell = 0xffffffffu;
};

namespace detail {
template <class Real>
struct hash_particles {
    grid_geometry<Real> g;
    const vec4<Real>* x;
    unsigned* key;
    unsigned* order;
    SPHERE_HD void operator()(std::size_t i) const
    {
        key[i] = g.cell_of(x[i].xyz());
        order[i] = static_cast<unsigned>(i);
    }
};

struct fill_empty {
    unsigned* cell_start;
    SPHERE_HD void operator()(std::size_t c) const { cell_start[c] = 0xffffffffu; }
};

template <class Real>
struct find_cell_bounds {
    std::size_t n;
    const unsigned* key;
    const unsigned* order;
    const vec4<Real>* x;
    vec4<Real>* sorted_x;
    unsigned* cell_start;
    unsigned* cell_end;
    SPHERE_HD void operator()(std::size_t k) const
    {
        const unsigned c = key[k];
        if (k == 0 || key[k - 1] != c) cell_start[c] = static_cast<unsigned>(k);
        if (k + 1 == n || key[k + 1] != c) cell_end[c] = static_cast<unsigned>(k + 1);
        sorted_x[k] = x[order[k]];
    }
};
} // namespace detail

template <class Real, class Policy>
class neighbor_grid {
public:
    explicit neighbor_grid(const grid_geometry<Real>& g = {}) : geometry_(g) {}

    const grid_geometry<Real>& geometry() const { return geometry_; }

    /// Rebuilds the cell lists from the particles' current positions.
    void build(const particle_view<Real>& p)
    {
        const std::size_t cells = geometry_.cell_count();
        if (key_.size() != p.n) {
            key_.resize(p.n);
            order_.resize(p.n);
            sorted_x_.resize(p.n);
        }
        if (cell_start_.size() != cells) {
            cell_start_.resize(cells);
            cell_end_.resize(cells);
        }
        for_each_index(Policy{}, p.n, detail::hash_particles<Real>{geometry_, p.x, key_.data(), order_.data()});
        sort_by_key(Policy{}, key_.data(), order_.data(), p.n);
        for_each_index(Policy{}, cells, detail::fill_empty{cell_start_.data()});
        for_each_index(Policy{}, p.n,
                       detail::find_cell_bounds<Real>{p.n, key_.data(), order_.data(), p.x, sorted_x_.data(),
                                                      cell_start_.data(), cell_end_.data()});
    }

    grid_view<Real> view() const
    {
        return {geometry_, order_.data(), sorted_x_.data(), cell_start_.data(), cell_end_.data()};
    }

private:
    grid_geometry<Real> geometry_;
    buffer<unsigned, Policy> key_, order_, cell_start_, cell_end_;
    buffer<vec4<Real>, Policy> sorted_x_;
};

} // namespace sphere
