#pragma once
/// \file
/// The porosity estimator (docs/fluid.md, *Porosity*): for every fluid cell, the volume its
/// cell-centred sphere shares with the particles gives the porosity, the lens-weighted mean
/// particle velocity and diameter, and by backward Euler the porosity's rate of change.
#include <cmath>
#include <cstddef>
#include <vector>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/context.cuh"
#include "../exec/for_each.cuh"
#include "../grid/neighbor_grid.cuh"
#include "../particles/state.cuh"
#include "grid.cuh"
#include "lens.cuh"

namespace sphere {

/// Kernel view of the estimator's fields, each in the fluid grid's field layout
/// (`fluid_grid::field_index`, ghost nodes included; the estimator writes the cells only).
template <class Real>
struct porosity_view {
    fluid_grid<Real> grid;
    Real radius;           ///< radius R of the cell spheres (m)
    const Real* phi;       ///< porosity (-)
    const Real* dphi_dt;   ///< its rate of change (1/s)
    const vec3<Real>* v_p; ///< lens-weighted mean particle velocity (m/s); 0 where no particle
    const Real* d_p;       ///< lens-weighted mean particle diameter (m); 0 where no particle
};

/// Host copies of the estimator's fields, in the fluid grid's field layout: the value of cell
/// (i, j, k) is at `grid.field_index(i, j, k)`.
template <class Real>
struct porosity_fields {
    fluid_grid<Real> grid;
    std::vector<Real> phi, dphi_dt, d_p;
    std::vector<vec3<Real>> v_p;
};

namespace detail {
/// Largest particle radius (m).
template <class Real>
struct particle_radius {
    const vec4<Real>* x;
    SPHERE_HD Real operator()(std::size_t i) const { return x[i].w; }
};

/// Fluid cell c gathers every particle whose sphere meets its cell sphere (centre at the cell
/// centre, radius R; nearest periodic image) from the bins (the fluid cells themselves, see
/// porosity_estimator) within [lo_offset, hi_offset] of its own along each axis, and writes
/// its own entries of the fields:
///   V_s = sum_j lens_volume(R, r_j, d_j)
///   phi = 1 - V_s / (4/3 pi R^3)
///   v_p = sum_j V_j v_j / V_s,  d_p = sum_j V_j 2 r_j / V_s   (0 when V_s = 0)
///   dphi/dt = (phi - phi_previous) / dt   (0 without a previous porosity)
/// phi is read (as the previous value) and written at the same index, by this cell only.
template <class Real>
struct estimate_cell_porosity {
    fluid_grid<Real> fluid;
    grid_view<Real> bins;
    const vec3<Real>* v; ///< particle velocities at the positions' time, user order (m/s)
    Real radius;
    int lo_offset[3];
    int hi_offset[3];
    bool have_previous;
    Real dt;
    Real* phi;
    Real* dphi_dt;
    vec3<Real>* v_p;
    Real* d_p;

    SPHERE_HD void operator()(std::size_t c) const
    {
        int ijk[3];
        fluid.coordinates(c, ijk[0], ijk[1], ijk[2]);
        const vec3<Real> centre = fluid.centre(ijk[0], ijk[1], ijk[2]);
        int first[3], count[3];
        for (int a = 0; a < 3; ++a) bin_range(ijk[a], a, first[a], count[a]);
        const int nx = static_cast<int>(fluid.n[0]);
        sums s{Real(0), Real(0), vec3<Real>{0, 0, 0}};
        for (int dk = 0; dk < count[2]; ++dk) {
            const int bk = wrap(first[2] + dk, 2);
            for (int dj = 0; dj < count[1]; ++dj) {
                const int bj = wrap(first[1] + dj, 1);
                // The bins first[0] .. first[0] + count[0] - 1 along x: one run of sorted
                // positions, or two when a periodic x wraps around.
                const int bi = wrap(first[0], 0);
                const int end = bi + count[0] - 1;
                if (end < nx) {
                    gather(fluid.index(bi, bj, bk), fluid.index(end, bj, bk), centre, s);
                } else {
                    gather(fluid.index(bi, bj, bk), fluid.index(nx - 1, bj, bk), centre, s);
                    gather(fluid.index(0, bj, bk), fluid.index(end - nx, bj, bk), centre, s);
                }
            }
        }
        const std::size_t f = fluid.field_index(ijk[0], ijk[1], ijk[2]);
        const Real porosity = Real(1) - s.solid / sphere_volume(radius);
        dphi_dt[f] = have_previous ? (porosity - phi[f]) / dt : Real(0);
        phi[f] = porosity;
        const bool any = s.solid > Real(0);
        v_p[f] = any ? s.velocity / s.solid : vec3<Real>{0, 0, 0};
        d_p[f] = any ? s.diameter / s.solid : Real(0);
    }

private:
    struct sums {
        Real solid;        ///< sum of V_j (m^3)
        Real diameter;     ///< sum of V_j 2 r_j (m^4)
        vec3<Real> velocity; ///< sum of V_j v_j (m^4/s)
    };

    /// The bins to scan along axis a for cell coordinate i: `count` bins from `first`
    /// (wrapped later on periodic axes, each bin at most once; clamped to the grid on others).
    SPHERE_HD void bin_range(int i, int a, int& first, int& count) const
    {
        const int n = static_cast<int>(fluid.n[a]);
        int lo = i + lo_offset[a], hi = i + hi_offset[a];
        if (fluid.box.periodic(a)) {
            if (hi - lo + 1 >= n) {
                lo = 0;
                hi = n - 1;
            }
        } else {
            lo = lo < 0 ? 0 : lo;
            hi = hi > n - 1 ? n - 1 : hi;
        }
        first = lo;
        count = hi - lo + 1;
    }

    SPHERE_HD int wrap(int b, int a) const
    {
        const int n = static_cast<int>(fluid.n[a]);
        return fluid.box.periodic(a) ? ((b % n) + n) % n : b;
    }

    /// Adds every particle of bins [first_bin, last_bin] (consecutive along x) that meets the
    /// cell sphere.
    SPHERE_HD void gather(std::size_t first_bin, std::size_t last_bin, const vec3<Real>& centre, sums& s) const
    {
        const unsigned end = bins.cell_start[last_bin + 1];
        for (unsigned k = bins.cell_start[first_bin]; k < end; ++k) {
            const vec4<Real> xj = bins.sorted_x[k];
            const Real reach = radius + xj.w;
            const Real d2 = norm2(fluid.box.nearest_image(xj.xyz() - centre));
            if (!(d2 < reach * reach)) continue;
            const Real V = lens_volume(radius, xj.w, std::sqrt(d2));
            s.solid += V;
            s.diameter += V * (Real(2) * xj.w);
            s.velocity += V * v[bins.order[k]];
        }
    }
};
} // namespace detail

/// The porosity estimator (docs/fluid.md, *Porosity*). Owns the porosity, porosity-rate,
/// mean-particle-velocity and mean-diameter fields of a fluid grid (field layout with ghost
/// nodes, `fluid_grid::field_index`; ghost entries are never written here, they start at
/// phi = 1 and 0 and are the boundary conditions' to fill) and recomputes them from the
/// particles with `update`, once per fluid step.
///
/// Cell sphere: centred on the cell, radius R = min(width) / 2, so that it lies inside its
/// cell whatever the cells' aspect (for cubic cells, half the cell width as in the seeds).
///
/// Particle search: the particles are binned into the fluid cells themselves (a
/// `neighbor_grid` over the fluid grid's geometry: hash, stable sort, cell starts), rebuilt
/// from the current positions at every update, and each cell scans the bins within
/// R + r_max of its centre (r_max the largest radius). The simulation's contact grid is not
/// reused: it is rebuilt only when a particle has moved skin/2, so its bins can be stale, and
/// its cells follow the particle size rather than the fluid resolution; one extra sort per
/// fluid step (usually several DEM steps) is cheap next to the gather.
///
/// Preconditions: coordinates on periodic axes lie in [lo, hi) (the simulation keeps them
/// there; the snapshot overload wraps them), and on every periodic axis R + r_max <= L / 2, so
/// that no particle meets a cell sphere through two periodic images (checked; an error names
/// the axis).
template <class Real, class Policy>
class porosity_estimator {
public:
    explicit porosity_estimator(const fluid_grid<Real>& g = {})
        : grid_(g), bins_(bin_geometry(g)), phi_(g.field_size(), Real(1)), dphi_dt_(g.field_size(), Real(0)),
          v_p_(g.field_size(), vec3<Real>{0, 0, 0}), d_p_(g.field_size(), Real(0))
    {
    }

    const fluid_grid<Real>& grid() const { return grid_; }

    /// The particles binned by fluid cell at the last update (bin index = fluid_grid::index of
    /// the cell holding the particle's centre; sorted by particle index within a bin).
    grid_view<Real> bins() const { return bins_.view(); }

    /// Radius R (m) of the cell spheres: half the smallest cell width.
    Real cell_sphere_radius() const { return grid_.min_width() / Real(2); }

    /// Recomputes every cell's fields from the particles' positions, radii (p.x) and
    /// velocities at the positions' time (p.v_sync). dt (s) is the time since the previous
    /// update, for dphi/dt = (phi - phi_previous) / dt; the first update after construction or
    /// `reset()` sets dphi/dt = 0. Throws when dt is not positive and finite, or when a
    /// periodic axis is too short for the cell spheres (see the class comment).
    void update(const particle_view<Real>& p, Real dt)
    {
        update(p, dt,
               p.n == 0 ? Real(0)
                        : transform_reduce(Policy{}, p.n, detail::particle_radius<Real>{p.x}, Real(0), max_op{}));
    }

    /// `update` with the largest particle radius r_max (m) given (a simulation knows it on the
    /// host), so that nothing is read back from the device.
    void update(const particle_view<Real>& p, Real dt, Real r_max)
    {
        if (!(dt > Real(0)) || !std::isfinite(dt))
            detail::fail("porosity_estimator::update: dt = ", dt, " s must be positive and finite");
        const Real R = cell_sphere_radius();
        const char* axis_name[3] = {"x", "y", "z"};
        for (int a = 0; a < 3; ++a)
            if (grid_.box.periodic(a) && R + r_max > grid_.box.length(a) / Real(2))
                detail::fail("porosity_estimator: periodic axis ", axis_name[a], " of length ", grid_.box.length(a),
                             " m is shorter than twice the cell sphere radius ", R,
                             " m plus the largest particle radius ", r_max,
                             " m, so a particle could meet a cell sphere through two periodic images; use more fluid "
                             "cells along ", axis_name[a]);
        const stream_scope<Policy> on_stream(context_);
        bins_.build(context_, p);
        detail::estimate_cell_porosity<Real> kernel{grid_, bins_.view(), p.v_sync, R, {0, 0, 0}, {0, 0, 0},
                                                    have_previous_, dt, phi_.data(), dphi_dt_.data(), v_p_.data(),
                                                    d_p_.data()};
        // Bins along a (of width w) that can hold a centre within R + r_max of the centre of
        // cell i, at (i + 1/2) w: i + floor(1/2 -+ s) with s = (R + r_max) / w, widened by
        // 1e-4 of a bin against round-off in the hash, and bounded by the grid's size.
        for (int a = 0; a < 3; ++a) {
            const double s = double(R + r_max) / double(grid_.width[a]) + 1e-4;
            const double n = double(grid_.n[a]);
            const double lo = std::floor(0.5 - s), hi = std::floor(0.5 + s);
            kernel.lo_offset[a] = static_cast<int>(lo < -n ? -n : lo);
            kernel.hi_offset[a] = static_cast<int>(hi > n ? n : hi);
        }
        for_each_index(Policy{}, grid_.cell_count(), kernel);
        have_previous_ = true;
    }

    /// `update` from a host snapshot (its x and v_sync; coordinates on periodic axes are
    /// wrapped into the box first), for tests and host-side analysis.
    void update(const particle_snapshot<Real>& s, Real dt)
    {
        if (s.v_sync.size() != s.x.size())
            detail::fail("porosity_estimator::update: the snapshot has ", s.x.size(), " positions but ",
                         s.v_sync.size(), " velocities (v_sync)");
        std::vector<vec4<Real>> x = s.x;
        for (vec4<Real>& xi : x) {
            xi.x = grid_.box.wrap(xi.x, 0);
            xi.y = grid_.box.wrap(xi.y, 1);
            xi.z = grid_.box.wrap(xi.z, 2);
        }
        x_.assign(x);
        v_.assign(s.v_sync);
        particle_view<Real> p{};
        p.n = x.size();
        p.x = x_.data();
        p.v_sync = v_.data();
        update(p, dt);
    }

    /// Forgets the previous porosity: the next update sets dphi/dt = 0.
    void reset() { have_previous_ = false; }

    porosity_view<Real> view() const
    {
        return {grid_, cell_sphere_radius(), phi_.data(), dphi_dt_.data(), v_p_.data(), d_p_.data()};
    }

    /// Host copies of the fields.
    porosity_fields<Real> fields() const
    {
        return {grid_, phi_.to_host(), dphi_dt_.to_host(), d_p_.to_host(), v_p_.to_host()};
    }

private:
    /// The fluid cells as bins of a neighbour grid.
    static grid_geometry<Real> bin_geometry(const fluid_grid<Real>& g)
    {
        grid_geometry<Real> b;
        b.box = g.box;
        b.width = g.width;
        for (int a = 0; a < 3; ++a) b.n[a] = g.n[a];
        return b;
    }

    fluid_grid<Real> grid_;
    execution_context<Policy> context_; ///< the bins' sort and scans
    neighbor_grid<Real, Policy> bins_;
    buffer<Real, Policy> phi_, dphi_dt_;
    buffer<vec3<Real>, Policy> v_p_;
    buffer<Real, Policy> d_p_;
    buffer<vec4<Real>, Policy> x_; ///< wrapped positions of the snapshot overload
    buffer<vec3<Real>, Policy> v_;
    bool have_previous_ = false;
};

/// The porosity, mean particle velocity and mean diameter of every cell of `g` for the
/// particles of a host snapshot (x and v_sync), on the host backend; dphi_dt is 0.
template <class Real>
porosity_fields<Real> estimate_porosity(const particle_snapshot<Real>& s, const fluid_grid<Real>& g)
{
    porosity_estimator<Real, host> estimator(g);
    estimator.update(s, Real(1));
    return estimator.fields();
}

} // namespace sphere
