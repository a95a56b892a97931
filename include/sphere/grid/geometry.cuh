#pragma once
/// \file
/// Geometry of the uniform neighbour grid over the world box.
#include <cmath>
#include <cstddef>

#include "../boundary/world.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"

namespace sphere {

/// A uniform grid of n[0] x n[1] x n[2] cells covering the world box. Cells are at least as
/// wide as the contact search reach (largest diameter plus skin), so every candidate pair lies
/// in the same or an adjacent cell.
///
/// Cells are numbered with axis `fast` varying fastest and axis `slow` slowest (by default x
/// fastest, z slowest). The contact grid (`make`) makes the axis with the most cells the slow
/// one: its layers of cells are the slabs of the host interaction (contact/interact.cuh), and
/// particles stored in cell order then lie slab after slab in memory.
template <class Real>
struct grid_geometry {
    world<Real> box;
    vec3<Real> width{0, 0, 0}; ///< cell widths (m)
    unsigned n[3] = {1, 1, 1};
    int fast = 0, mid = 1, slow = 2; ///< axes in the order of the cell numbering

    SPHERE_HD std::size_t cell_count() const { return std::size_t(n[0]) * n[1] * n[2]; }
    /// Cells along axis a. Kernels read n and the axes' properties through selects like
    /// this one, never by a run-time index (see component() in core/vec.cuh).
    SPHERE_HDI unsigned cells(int a) const { return a == 0 ? n[0] : (a == 1 ? n[1] : n[2]); }
    /// Cells in one layer across the slow axis.
    SPHERE_HD unsigned cells_per_layer() const { return cells(fast) * cells(mid); }
    /// Layers along the slow axis.
    SPHERE_HD unsigned layers() const { return cells(slow); }

    /// Cell coordinate of c along axis a, clamped into the grid.
    SPHERE_HDI int coordinate(Real c, int a) const
    {
        const unsigned na = cells(a);
        const Real f = std::floor((c - component(box.lo, a)) / component(width, a));
        if (!(f > Real(0))) return 0;
        if (f >= Real(na - 1)) return static_cast<int>(na - 1);
        return static_cast<int>(f);
    }

    /// The number of the cell with coordinates s, m, f along the slow, mid and fast axes.
    SPHERE_HD unsigned index_in_order(int s, int m, int f) const
    {
        return (static_cast<unsigned>(s) * cells(mid) + static_cast<unsigned>(m)) * cells(fast) + static_cast<unsigned>(f);
    }
    /// The number of the cell with coordinates ix, iy, iz along x, y, z.
    SPHERE_HD unsigned index(int ix, int iy, int iz) const
    {
        const auto pick = [&](int a) { return a == 0 ? ix : (a == 1 ? iy : iz); };
        return index_in_order(pick(slow), pick(mid), pick(fast));
    }

    SPHERE_HD unsigned cell_of(const vec3<Real>& p) const
    {
        return index(coordinate(p.x, 0), coordinate(p.y, 1), coordinate(p.z, 2));
    }

    /// Lays a grid over `box` with cells at least `reach` (m) wide, or exactly `requested` wide
    /// per axis when it is positive (rounded down to fit the box). The axis with the most cells
    /// (the first of equals) is numbered slowest, and without a requested width its count is
    /// rounded down to a multiple of 4 from 16 cells on (even shares of the slab schedule); of
    /// the other two, a wall axis is numbered fastest when the other is periodic (a run of
    /// cells along it never wraps), else the lower one. Throws when a requested cell is narrower than `reach`, when a periodic axis
    /// has fewer than 3 cells, or when the grid would exceed 2^28 cells.
    static grid_geometry make(const world<Real>& box, Real reach, Real requested)
    {
        if (requested > 0 && requested < reach)
            detail::fail("settings.cell_size = ", requested,
                         " m is smaller than the largest particle diameter plus skin and the contact law's range, ",
                         reach, " m: contacts would be missed");
        const Real target = requested > 0 ? requested : reach;
        grid_geometry g;
        g.box = box;
        for (int a = 0; a < 3; ++a) {
            const Real cells = std::floor(box.length(a) / target);
            g.n[a] = cells < 1 ? 1u : static_cast<unsigned>(cells < Real(1 << 20) ? cells : Real(1 << 20));
            g.width[a] = box.length(a) / Real(g.n[a]);
            if (box.periodic(a) && g.n[a] < 3)
                detail::fail("periodic axis ", a, " of length ", box.length(a), " m holds ", g.n[a],
                             " grid cells of at least ", target,
                             " m: a periodic axis needs at least 3 (make the world wider or the particles smaller)");
        }
        g.slow = 0;
        for (int a = 1; a < 3; ++a)
            if (g.n[a] > g.n[g.slow]) g.slow = a;
        if (requested <= 0 && g.n[g.slow] >= 16) {
            // Layers in a multiple of 4: each of the slab schedule's two phases then holds an
            // even number of equal tasks, which two threads (or four, with a multiple of 8)
            // share evenly (contact/interact.cuh); the cells grow by at most 1/5.
            g.n[g.slow] -= g.n[g.slow] % 4;
            g.width[g.slow] = box.length(g.slow) / Real(g.n[g.slow]);
        }
        const int other[2] = {g.slow == 0 ? 1 : 0, g.slow == 2 ? 1 : 2};
        const bool swap = box.periodic(other[0]) && !box.periodic(other[1]);
        g.fast = swap ? other[1] : other[0];
        g.mid = swap ? other[0] : other[1];
        if (g.cell_count() > (std::size_t(1) << 28))
            detail::fail("the neighbour grid would need ", g.cell_count(), " cells (", g.n[0], " x ", g.n[1], " x ",
                         g.n[2], "); set settings.cell_size larger or shrink the world");
        return g;
    }
};

} // namespace sphere
