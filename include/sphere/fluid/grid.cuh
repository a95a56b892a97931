#pragma once
/// \file
/// Geometry of the fluid grid (docs/fluid.md, *Fluid grid*): nx x ny x nz cells over the world
/// box, at a resolution the user chooses independently of the contact-search grid, and the
/// layout of the cell fields, which carry one layer of ghost nodes on every side.
#include <cmath>
#include <cstddef>

#include "../boundary/world.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"

namespace sphere {

/// n[0] x n[1] x n[2] cells of equal size covering the world box; cell (i, j, k), 0 <= i < n[0]
/// etc., spans [lo + (i, j, k) width, lo + (i + 1, j + 1, k + 1) width).
///
/// Two index spaces:
///   - `index(i, j, k)`: the cells alone, cell_count() entries, x fastest;
///   - `field_index(i, j, k)`: a cell field with ghost nodes, field_size() =
///     (n[0] + 2)(n[1] + 2)(n[2] + 2) entries, x fastest, where each coordinate runs from -1 to
///     n (inclusive): -1 and n are the ghost layers, whose centres lie half a cell outside the
///     box. Every fluid field (porosity, pressure, velocities) uses this layout; a kernel
///     writes the cells, and the boundary conditions fill the ghosts (a copy of the opposite
///     cell on periodic axes: ghost -1 holds cell n - 1 and ghost n holds cell 0).
template <class Real>
struct fluid_grid {
    world<Real> box;
    unsigned n[3] = {1, 1, 1};  ///< cells along x, y, z
    vec3<Real> width{1, 1, 1};  ///< cell widths (m): box length / n per axis

    SPHERE_HD std::size_t cell_count() const { return std::size_t(n[0]) * n[1] * n[2]; }
    SPHERE_HD std::size_t field_size() const { return std::size_t(n[0] + 2) * (n[1] + 2) * (n[2] + 2); }

    /// Linear index of cell (i, j, k), each in [0, n).
    SPHERE_HD std::size_t index(int i, int j, int k) const
    {
        return (std::size_t(k) * n[1] + std::size_t(j)) * n[0] + std::size_t(i);
    }

    /// The cell of linear index c (the inverse of `index`).
    SPHERE_HD void coordinates(std::size_t c, int& i, int& j, int& k) const
    {
        i = static_cast<int>(c % n[0]);
        c /= n[0];
        j = static_cast<int>(c % n[1]);
        k = static_cast<int>(c / n[1]);
    }

    /// Index of cell or ghost node (i, j, k), each in [-1, n], in a field with ghost nodes.
    SPHERE_HD std::size_t field_index(int i, int j, int k) const
    {
        return (std::size_t(k + 1) * (n[1] + 2) + std::size_t(j + 1)) * (n[0] + 2) + std::size_t(i + 1);
    }

    /// Coordinates (each in [-1, n]) of field index f (the inverse of `field_index`).
    SPHERE_HD void field_coordinates(std::size_t f, int& i, int& j, int& k) const
    {
        i = static_cast<int>(f % (n[0] + 2)) - 1;
        f /= (n[0] + 2);
        j = static_cast<int>(f % (n[1] + 2)) - 1;
        k = static_cast<int>(f / (n[1] + 2)) - 1;
    }

    /// Whether (i, j, k) is a cell (not a ghost node).
    SPHERE_HD bool is_cell(int i, int j, int k) const
    {
        return i >= 0 && j >= 0 && k >= 0 && i < static_cast<int>(n[0]) && j < static_cast<int>(n[1]) &&
               k < static_cast<int>(n[2]);
    }

    /// Centre (m) of cell (i, j, k); also of ghost nodes (-1 or n).
    SPHERE_HD vec3<Real> centre(int i, int j, int k) const
    {
        return {box.lo.x + (Real(i) + Real(0.5)) * width.x, box.lo.y + (Real(j) + Real(0.5)) * width.y,
                box.lo.z + (Real(k) + Real(0.5)) * width.z};
    }

    /// Coordinates c[0..2] of the cell holding the point x (m), clamped to the grid (a point
    /// on or beyond a face belongs to the outermost cell).
    SPHERE_HD void cell_of(const vec3<Real>& x, int c[3]) const
    {
        for (int a = 0; a < 3; ++a) {
            const Real s = (x[a] - box.lo[a]) / width[a];
            const int k = s > Real(0) ? static_cast<int>(s) : 0;
            c[a] = k >= static_cast<int>(n[a]) ? static_cast<int>(n[a]) - 1 : k;
        }
    }

    /// The smallest of the three cell widths (m).
    SPHERE_HD Real min_width() const
    {
        const Real w = width.x < width.y ? width.x : width.y;
        return w < width.z ? w : width.z;
    }

    /// nx x ny x nz cells over `box`. Throws when a count is below 1, when the grid would exceed
    /// 2^28 cells, or when the box is not finite with lo < hi on every axis.
    static fluid_grid make(const world<Real>& box, long long nx, long long ny, long long nz)
    {
        const char* axis_name[3] = {"x", "y", "z"};
        const long long counts[3] = {nx, ny, nz};
        fluid_grid g;
        g.box = box;
        double cells = 1;
        for (int a = 0; a < 3; ++a) {
            if (!(std::isfinite(box.lo[a]) && std::isfinite(box.hi[a]) && box.lo[a] < box.hi[a]))
                detail::fail("fluid grid: the world box along ", axis_name[a], " is [", box.lo[a], ", ", box.hi[a],
                             "] m: it needs finite bounds with lo < hi");
            if (counts[a] < 1)
                detail::fail("fluid grid: n", axis_name[a], " = ", counts[a], " cells: every axis needs at least 1");
            cells *= double(counts[a]);
        }
        if (cells > double(std::size_t(1) << 28))
            detail::fail("fluid grid: ", nx, " x ", ny, " x ", nz, " = ", cells,
                         " cells is more than the 2^28 allowed; choose a coarser resolution");
        for (int a = 0; a < 3; ++a) {
            g.n[a] = static_cast<unsigned>(counts[a]);
            g.width[a] = box.length(a) / Real(g.n[a]);
        }
        return g;
    }
};

} // namespace sphere
