#pragma once
/// \file
/// The porosity estimator (docs/fluid.md, *Porosity*): for every fluid cell, the solid volume
/// the particles put in it (the share of each particle's volume that falls in the cell, or the
/// seeds' volume shared with a cell-centred sphere) gives the porosity, the volume-weighted
/// mean particle velocity and diameter, and by backward Euler the porosity's rate of change.
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
#include "snapshot.cuh"

namespace sphere {

/// How the porosity estimator measures a cell's solid volume (docs/fluid.md, *Porosity*).
enum class porosity_method {
    /// Each particle's volume is shared among the cells its sphere reaches, cell (i, j, k)
    /// taking V f_x(i) f_y(j) f_z(k), where f_a(i) is the fraction of the sphere's volume
    /// between the cell's two faces normal to axis a (the outermost cells of a wall axis reach
    /// to infinity). The shares of a particle sum to its volume, so the solid volume of the
    /// grid is conserved exactly (a closed box's compatibility condition), and the solid volume
    /// of every layer of cells is exactly that of the particles between its planes. The default.
    cell_volume,
    /// The volume each particle shares with the cell's inscribed sphere (radius half the
    /// smallest cell width), over that sphere's volume: the seeds' estimator (F1, F2). It sees
    /// 52% of a cubic cell, so the grid's solid volume is not conserved.
    cell_sphere
};

/// A method's name as written in C++ ("cell_volume", "cell_sphere").
inline const char* name(porosity_method m)
{
    return m == porosity_method::cell_sphere ? "cell_sphere" : "cell_volume";
}

/// Kernel view of the estimator's fields, each in the fluid grid's field layout
/// (`fluid_grid::field_index`, ghost nodes included; the estimator writes the cells only).
template <class Real>
struct porosity_view {
    fluid_grid<Real> grid;
    Real radius;           ///< radius R of the cell spheres (m; porosity_method::cell_sphere)
    const Real* phi;       ///< porosity (-)
    const Real* dphi_dt;   ///< its rate of change (1/s)
    const vec3<Real>* v_p; ///< volume-weighted mean particle velocity (m/s); 0 where no particle
    const Real* d_p;       ///< volume-weighted mean particle diameter (m); 0 where no particle
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

/// The fraction of a sphere's volume below the plane at t radii from its centre (t in any
/// range): 0 for t <= -1, 1 for t >= 1, the cap (1 + t)^2 (2 - t) / 4 between (docs/fluid.md,
/// *Porosity*).
template <class Real>
SPHERE_HD Real volume_fraction_below(Real t)
{
    if (!(t > Real(-1))) return Real(0);
    if (!(t < Real(1))) return Real(1);
    return (Real(1) + t) * (Real(1) + t) * (Real(2) - t) / Real(4);
}

/// Fluid cell c gathers every particle that can reach it (nearest periodic image) from the bins
/// (the fluid cells themselves, see porosity_estimator) within [lo_offset, hi_offset] of its
/// own along each axis, and writes its own entries of the fields:
///   V_j = the particle's solid volume in the cell (porosity_method; m^3)
///   V_s = sum_j V_j
///   phi = 1 - V_s / V_c   (V_c the cell's volume, or its sphere's for cell_sphere)
///   v_p = sum_j V_j v_j / V_s,  d_p = sum_j V_j 2 r_j / V_s   (0 when V_s = 0)
///   dphi/dt = (phi - phi_previous) / dt   (0 without a previous porosity)
/// phi is read (as the previous value) and written at the same index, by this cell only.
template <class Real>
struct estimate_cell_porosity {
    fluid_grid<Real> fluid;
    grid_view<Real> bins;
    const vec3<Real>* v; ///< particle velocities at the positions' time, user order (m/s)
    porosity_method method;
    Real radius;         ///< the cell spheres' radius R (m; cell_sphere)
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
        cell_place cell;
        cell.centre = fluid.centre(ijk[0], ijk[1], ijk[2]);
        for (int a = 0; a < 3; ++a) {
            const bool wall = !fluid.box.periodic(a);
            cell.open_lo[a] = wall && ijk[a] == 0;
            cell.open_hi[a] = wall && ijk[a] == static_cast<int>(fluid.n[a]) - 1;
        }
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
                    gather(fluid.index(bi, bj, bk), fluid.index(end, bj, bk), cell, s);
                } else {
                    gather(fluid.index(bi, bj, bk), fluid.index(nx - 1, bj, bk), cell, s);
                    gather(fluid.index(0, bj, bk), fluid.index(end - nx, bj, bk), cell, s);
                }
            }
        }
        const std::size_t f = fluid.field_index(ijk[0], ijk[1], ijk[2]);
        const Real sampled = method == porosity_method::cell_sphere ? sphere_volume(radius)
                                                                    : fluid.width.x * fluid.width.y * fluid.width.z;
        const Real porosity = Real(1) - s.solid / sampled;
        dphi_dt[f] = have_previous ? (porosity - phi[f]) / dt : Real(0);
        phi[f] = porosity;
        const bool any = s.solid > Real(0);
        v_p[f] = any ? s.velocity / s.solid : vec3<Real>{0, 0, 0};
        d_p[f] = any ? s.diameter / s.solid : Real(0);
    }

private:
    /// The cell's centre, and which of its faces are the open outer side of an outermost cell
    /// on a wall axis (cell_volume: that side reaches to infinity).
    struct cell_place {
        vec3<Real> centre;
        bool open_lo[3], open_hi[3];
    };

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

    /// Adds every particle of bins [first_bin, last_bin] (consecutive along x) that reaches
    /// the cell.
    SPHERE_HD void gather(std::size_t first_bin, std::size_t last_bin, const cell_place& cell, sums& s) const
    {
        const unsigned end = bins.cell_start[last_bin + 1];
        for (unsigned k = bins.cell_start[first_bin]; k < end; ++k) {
            const vec4<Real> xj = bins.sorted_x.x[k];
            const vec3<Real> d = fluid.box.nearest_image(xj.xyz() - cell.centre);
            const Real V = method == porosity_method::cell_sphere ? lens_volume(radius, xj.w, std::sqrt(norm2(d)))
                                                                  : volume_in_cell(d, xj.w, cell);
            if (!(V > Real(0))) continue;
            s.solid += V;
            s.diameter += V * (Real(2) * xj.w);
            s.velocity += V * v[bins.order[k]];
        }
    }

    /// porosity_method::cell_volume: the volume (m^3) of a sphere of radius r whose centre lies
    /// at d from the cell's centre, times the fractions of it between the cell's faces along
    /// each axis; the outermost cells of a wall axis reach to infinity on their outer side.
    SPHERE_HD Real volume_in_cell(const vec3<Real>& d, Real r, const cell_place& cell) const
    {
        Real share = sphere_volume(r);
        for (int a = 0; a < 3; ++a) {
            const Real half = Real(0.5) * fluid.width[a];
            const Real below_hi = cell.open_hi[a] ? Real(1) : volume_fraction_below((half - d[a]) / r);
            const Real below_lo = cell.open_lo[a] ? Real(0) : volume_fraction_below((-half - d[a]) / r);
            share *= below_hi - below_lo;
        }
        return share;
    }
};
} // namespace detail

/// The porosity estimator (docs/fluid.md, *Porosity*). Owns the porosity, porosity-rate,
/// mean-particle-velocity and mean-diameter fields of a fluid grid (field layout with ghost
/// nodes, `fluid_grid::field_index`; ghost entries are never written here, they start at
/// phi = 1 and 0 and are the boundary conditions' to fill) and recomputes them from the
/// particles with `update`, once per fluid step.
///
/// The solid volume of a cell (porosity_method): by default each particle's volume shared
/// among the cells its sphere reaches (the grid's solid volume conserved); with cell_sphere,
/// what it shares with the sphere centred on the cell of radius R = min(width) / 2, which lies
/// inside its cell whatever the cells' aspect (for cubic cells, half the cell width as in the
/// seeds).
///
/// Particle search: the particles are binned into the fluid cells themselves (a
/// `neighbor_grid` over the fluid grid's geometry: hash, stable sort, cell starts), rebuilt
/// from the current positions at every update, and each cell scans the bins within h_a + r_max
/// of its centre along each axis a (h_a = width_a / 2, or R for cell_sphere; r_max the largest
/// radius). The simulation's contact grid is not reused: it is rebuilt only when a particle
/// has moved skin/2, so its bins can be stale, and its cells follow the particle size rather
/// than the fluid resolution; one extra sort per fluid step (usually several DEM steps) is
/// cheap next to the gather.
///
/// Preconditions: coordinates on periodic axes lie in [lo, hi) (the simulation keeps them
/// there; the snapshot overload wraps them), and on every periodic axis h_a + r_max <= L / 2,
/// so that no particle reaches a cell through two periodic images (checked; an error names
/// the axis).
template <class Real, class Policy>
class porosity_estimator {
public:
    explicit porosity_estimator(const fluid_grid<Real>& g = {}, porosity_method method = porosity_method::cell_volume)
        : grid_(g), method_(method), bins_(bin_geometry(g)), phi_(g.field_size(), Real(1)),
          dphi_dt_(g.field_size(), Real(0)), v_p_(g.field_size(), vec3<Real>{0, 0, 0}), d_p_(g.field_size(), Real(0))
    {
    }

    porosity_method method() const { return method_; }
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
    /// periodic axis is too short for the cells' reach (see the class comment).
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
        const bool sphere = method_ == porosity_method::cell_sphere;
        const char* axis_name[3] = {"x", "y", "z"};
        for (int a = 0; a < 3; ++a) {
            const Real h = sphere ? R : grid_.width[a] / Real(2);
            if (grid_.box.periodic(a) && h + r_max > grid_.box.length(a) / Real(2))
                detail::fail("porosity_estimator: periodic axis ", axis_name[a], " of length ", grid_.box.length(a),
                             " m is shorter than twice ", sphere ? "the cell sphere radius " : "half the cell width ", h,
                             " m plus the largest particle radius ", r_max,
                             " m, so a particle could reach a cell through two periodic images; use more fluid "
                             "cells along ", axis_name[a]);
        }
        const stream_scope<Policy> on_stream(context_);
        bins_.build(context_, p);
        detail::estimate_cell_porosity<Real> kernel{grid_, bins_.view(), p.v_sync, method_, R, {0, 0, 0}, {0, 0, 0},
                                                    have_previous_, dt, phi_.data(), dphi_dt_.data(), v_p_.data(),
                                                    d_p_.data()};
        // Bins along a (of width w) that can hold a centre within h + r_max of the centre of
        // cell i, at (i + 1/2) w: i + floor(1/2 -+ s) with s = (h + r_max) / w, widened by
        // 1e-4 of a bin against round-off in the hash, and bounded by the grid's size.
        for (int a = 0; a < 3; ++a) {
            const Real h = sphere ? R : grid_.width[a] / Real(2);
            const double s = double(h + r_max) / double(grid_.width[a]) + 1e-4;
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

    /// The estimator's name in a fluid_snapshot.
    static const char* model_name() { return "porosity"; }

    /// A host copy of the estimator's state (fluid/snapshot.cuh; docs/fluid.md, *Restarting a
    /// coupled run*), for a checkpoint: the porosity phi, which the next update reads as the
    /// previous one (dphi/dt = (phi - previous) / dt), and have_previous (0: the next update
    /// sets dphi/dt = 0); dphi_dt, d_p and v_p (3 per node) too, which the next update
    /// overwrites, so that fields() reads the same after a restore. The porosity method, to
    /// be checked. Field layout, ghost nodes included.
    fluid_snapshot<Real> snapshot() const
    {
        fluid_snapshot<Real> s = fluid_snapshot<Real>::of(model_name(), grid_);
        s.add("phi", phi_.to_host());
        s.add("dphi_dt", dphi_dt_.to_host());
        s.add("d_p", d_p_.to_host());
        s.add("v_p", v_p_.to_host());
        s.add_count("have_previous", have_previous_ ? 1 : 0);
        s.add_count("method", method_ == porosity_method::cell_volume ? 0 : 1);
        return s;
    }

    /// Throws what restore() would throw for snapshot s, changing nothing.
    void check_snapshot(const fluid_snapshot<Real>& s) const
    {
        const char* who = "porosity_estimator::restore";
        s.check_model_and_grid(who, model_name(), grid_);
        s.check_only(who, {"phi", "dphi_dt", "d_p", "v_p"}, {}, {"have_previous", "method"});
        const std::size_t size = grid_.field_size();
        const char* what = "the grid's field size, ghost nodes included";
        for (const char* name : {"phi", "dphi_dt", "d_p"}) s.array_named(who, name, size, what);
        s.array_named(who, "v_p", 3 * size, "3 per node of the grid's fields");
        s.count_named(who, "have_previous", 1);
        const auto stored = static_cast<porosity_method>(s.count_named(who, "method", 1));
        if (stored != method_)
            detail::fail(who, ": the snapshot's porosity method is ", name(stored), ", this estimator's ", name(method_));
    }

    /// Continues from a snapshot() of an estimator of the same grid and method: the next update
    /// gives the bits the snapshotted estimator's next update gave. Throws sphere::error, with
    /// nothing changed, when the snapshot is of another grid or method, lacks an entry or holds
    /// one the estimator does not have, or an array has another length than the grid's fields.
    void restore(const fluid_snapshot<Real>& s)
    {
        check_snapshot(s);
        const char* who = "porosity_estimator::restore";
        const std::size_t size = grid_.field_size();
        const char* what = "the grid's field size";
        phi_.assign(s.array_named(who, "phi", size, what));
        dphi_dt_.assign(s.array_named(who, "dphi_dt", size, what));
        d_p_.assign(s.array_named(who, "d_p", size, what));
        v_p_.assign(s.vectors_named(who, "v_p", size, what));
        have_previous_ = s.count_named(who, "have_previous", 1) == 1;
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
    porosity_method method_;
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
porosity_fields<Real> estimate_porosity(const particle_snapshot<Real>& s, const fluid_grid<Real>& g,
                                        porosity_method method = porosity_method::cell_volume)
{
    porosity_estimator<Real, host> estimator(g, method);
    estimator.update(s, Real(1));
    return estimator.fields();
}

} // namespace sphere
