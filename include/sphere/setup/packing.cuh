#pragma once
/// \file
/// Preparing samples: particle centres on a regular or jittered cubic lattice or placed at
/// random without overlap, a world box sized to the particles with a margin (sphere's
/// initGridAndWorldsize), and deposition under gravity until the particles are at rest.
/// Host-only set-up code; the random choices use random_stream, so a seed gives the same
/// sample everywhere.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <numeric>
#include <vector>

#include "../boundary/world.cuh"
#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../grid/geometry.cuh"
#include "../particles/distributions.cuh"
#include "../particles/particle.cuh"
#include "../settings.cuh"

namespace sphere {

/// Centres of an nx x ny x nz simple cubic lattice with spacing s (m) per axis: particle
/// i + nx (j + ny k) sits at origin + ((i + 1/2) s.x, (j + 1/2) s.y, (k + 1/2) s.z), so the
/// lattice fills the box [origin, origin + (nx s.x, ny s.y, nz s.z)] and spheres of radius
/// s/2 touch its faces and each other (sphere's initGridPos with s = 2 r_max).
template <class Real>
std::vector<vec3<Real>> cubic_lattice(std::size_t nx, std::size_t ny, std::size_t nz, const vec3<Real>& spacing,
                                      const vec3<Real>& origin = {0, 0, 0})
{
    if (!(spacing.x > 0 && spacing.y > 0 && spacing.z > 0) || !isfinite(spacing))
        detail::fail("cubic_lattice: spacing (", spacing.x, ", ", spacing.y, ", ", spacing.z,
                     ") m must be positive and finite");
    if (!isfinite(origin))
        detail::fail("cubic_lattice: origin (", origin.x, ", ", origin.y, ", ", origin.z, ") m is not finite");
    std::vector<vec3<Real>> c;
    c.reserve(nx * ny * nz);
    for (std::size_t k = 0; k < nz; ++k)
        for (std::size_t j = 0; j < ny; ++j)
            for (std::size_t i = 0; i < nx; ++i)
                c.push_back({origin.x + (Real(i) + Real(0.5)) * spacing.x, origin.y + (Real(j) + Real(0.5)) * spacing.y,
                             origin.z + (Real(k) + Real(0.5)) * spacing.z});
    return c;
}

/// cubic_lattice with the same spacing (m) on every axis.
template <class Real>
std::vector<vec3<Real>> cubic_lattice(std::size_t nx, std::size_t ny, std::size_t nz, Real spacing,
                                      const vec3<Real>& origin = {0, 0, 0})
{
    return cubic_lattice(nx, ny, nz, vec3<Real>{spacing, spacing, spacing}, origin);
}

/// A cubic lattice (spacing in m) whose centres are each moved by an offset uniform in
/// [-jitter, jitter] (m) on every axis (sphere's initRandomGridPos). With spacing >= 2 r_max
/// + 2 jitter no two spheres overlap.
template <class Real>
std::vector<vec3<Real>> jittered_lattice(std::size_t nx, std::size_t ny, std::size_t nz, Real spacing, Real jitter,
                                         std::uint64_t seed, const vec3<Real>& origin = {0, 0, 0})
{
    if (!(jitter >= 0) || !std::isfinite(jitter))
        detail::fail("jittered_lattice: jitter = ", jitter, " m must be non-negative and finite");
    std::vector<vec3<Real>> c = cubic_lattice(nx, ny, nz, spacing, origin);
    random_stream rng(seed);
    for (vec3<Real>& p : c)
        for (int a = 0; a < 3; ++a) p[a] += static_cast<Real>(rng.uniform(-double(jitter), double(jitter)));
    return c;
}

namespace detail {
/// Cells of the random-packing grid to search along one axis around cell c (of n).
inline void search_range(int c, int n, bool periodic, int& first, int& last)
{
    if (periodic && n < 3) {
        first = 0;
        last = n - 1;
    } else if (periodic) {
        first = c - 1;
        last = c + 1;
    } else {
        first = c > 0 ? c - 1 : 0;
        last = c + 1 < n ? c + 1 : n - 1;
    }
}
} // namespace detail

/// Random sequential addition: places spheres of the given radii (m) one after the other at
/// uniformly random centres in `region`, rejecting any candidate that overlaps a sphere
/// already placed (surfaces closer than `gap`, m). On a wall axis of the region every sphere
/// lies inside [lo, hi]; on a periodic axis centres fill [lo, hi) and overlaps are checked
/// against the nearest image. The largest spheres are placed first; the returned centres are
/// in the order of `radii`. Overlaps are checked in double with the centres already rounded
/// to Real, so the returned sample has no overlap. A grid of cells as wide as the largest
/// diameter plus the gap keeps each check local.
///
/// Throws sphere::error when a sphere does not fit the region, or when a particle could not be
/// placed after `max_tries` candidates (the region is too full for random addition: its
/// jamming limit is a solid fraction of about 0.38 for equal spheres).
template <class Real>
std::vector<vec3<Real>> random_packing(const std::vector<Real>& radii, const world<Real>& region, std::uint64_t seed,
                                       Real gap = 0, std::size_t max_tries = 10000)
{
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(region.lo[a]) || !std::isfinite(region.hi[a]) || !(region.hi[a] > region.lo[a]))
            detail::fail("random_packing: region axis ", a, " spans [", region.lo[a], ", ", region.hi[a],
                         "] m; it must be finite with hi > lo");
    if (!(gap >= 0) || !std::isfinite(gap)) detail::fail("random_packing: gap = ", gap, " m must be non-negative and finite");
    if (max_tries == 0) detail::fail("random_packing: max_tries = 0: at least one try is needed");
    const std::size_t n = radii.size();
    double r_max = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (!(radii[i] > 0) || !std::isfinite(radii[i]))
            detail::fail("random_packing: radius ", i, " = ", radii[i], " m must be positive and finite");
        r_max = std::max(r_max, double(radii[i]));
        for (int a = 0; a < 3; ++a)
            if (!region.periodic(a) && !(2 * double(radii[i]) <= double(region.length(a))))
                detail::fail("random_packing: particle ", i, " of radius ", radii[i], " m does not fit between the walls of axis ", a,
                             " (", region.length(a), " m apart)");
    }
    std::vector<vec3<Real>> centre(n);
    if (n == 0) return centre;

    // Cells at least 2 r_max + gap wide: any overlapping pair lies in the same or adjacent cells.
    const double reach = 2 * r_max + double(gap);
    int cells[3];
    double width[3];
    for (int a = 0; a < 3; ++a) {
        const double L = double(region.length(a));
        cells[a] = static_cast<int>(std::max(1.0, std::min(std::floor(L / reach), 1024.0)));
    }
    while (std::size_t(cells[0]) * cells[1] * cells[2] > 8 * n + 64) { // a sparse region: coarser cells
        int& widest = cells[0] >= cells[1] && cells[0] >= cells[2] ? cells[0] : (cells[1] >= cells[2] ? cells[1] : cells[2]);
        widest = (widest + 1) / 2;
    }
    for (int a = 0; a < 3; ++a) width[a] = double(region.length(a)) / cells[a];
    const std::size_t cell_count = std::size_t(cells[0]) * cells[1] * cells[2];
    std::vector<std::size_t> head(cell_count, ~std::size_t(0)), next(n, ~std::size_t(0));
    auto cell_coordinate = [&](double c, int a) {
        const int k = static_cast<int>(std::floor((c - double(region.lo[a])) / width[a]));
        return k < 0 ? 0 : (k >= cells[a] ? cells[a] - 1 : k);
    };

    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return radii[a] > radii[b]; });

    random_stream rng(seed);
    double placed_volume = 0;
    for (std::size_t placed = 0; placed < n; ++placed) {
        const std::size_t i = order[placed];
        const double ri = double(radii[i]);
        bool done = false;
        for (std::size_t attempt = 0; attempt < max_tries && !done; ++attempt) {
            vec3<Real> c;
            for (int a = 0; a < 3; ++a) {
                const double lo = double(region.lo[a]), hi = double(region.hi[a]);
                c[a] = region.periodic(a) ? region.wrap(static_cast<Real>(rng.uniform(lo, hi)), a)
                                          : static_cast<Real>(rng.uniform(lo + ri, hi - ri));
                if (!region.periodic(a)) c[a] = std::min(std::max(c[a], static_cast<Real>(lo + ri)), static_cast<Real>(hi - ri));
            }
            const int ci[3] = {cell_coordinate(c.x, 0), cell_coordinate(c.y, 1), cell_coordinate(c.z, 2)};
            int first[3], last[3];
            for (int a = 0; a < 3; ++a) detail::search_range(ci[a], cells[a], region.periodic(a), first[a], last[a]);
            bool overlaps = false;
            for (int z = first[2]; z <= last[2] && !overlaps; ++z)
                for (int y = first[1]; y <= last[1] && !overlaps; ++y)
                    for (int x = first[0]; x <= last[0] && !overlaps; ++x) {
                        const int wx = (x + cells[0]) % cells[0], wy = (y + cells[1]) % cells[1],
                                  wz = (z + cells[2]) % cells[2];
                        for (std::size_t j = head[(std::size_t(wz) * cells[1] + wy) * cells[0] + wx];
                             j != ~std::size_t(0); j = next[j]) {
                            double d2 = 0;
                            for (int a = 0; a < 3; ++a) {
                                double d = double(c[a]) - double(centre[j][a]);
                                if (region.periodic(a)) {
                                    const double L = double(region.length(a));
                                    d -= L * std::nearbyint(d / L);
                                }
                                d2 += d * d;
                            }
                            const double reach_ij = ri + double(radii[j]) + double(gap);
                            if (d2 < reach_ij * reach_ij) {
                                overlaps = true;
                                break;
                            }
                        }
                    }
            if (overlaps) continue;
            centre[i] = c;
            const std::size_t cell = (std::size_t(ci[2]) * cells[1] + ci[1]) * cells[0] + ci[0];
            next[i] = head[cell];
            head[cell] = i;
            placed_volume += 4.0 / 3.0 * pi<double> * ri * ri * ri;
            done = true;
        }
        if (!done) {
            const double volume = double(region.length(0)) * double(region.length(1)) * double(region.length(2));
            detail::fail("random_packing: could not place particle ", i, " (radius ", ri, " m) after ", max_tries,
                         " tries; ", placed, " of ", n, " particles placed, solid fraction so far ",
                         placed_volume / volume, "; enlarge the region, place fewer particles or raise max_tries");
        }
    }
    return centre;
}

/// Particles of the given density (kg/m^3) at the given centres (m) with the given radii (m),
/// at rest and free; centres and radii must have the same length.
template <class Real>
std::vector<particle<Real>> make_particles(const std::vector<vec3<Real>>& centres, const std::vector<Real>& radii,
                                           Real density)
{
    if (centres.size() != radii.size())
        detail::fail("make_particles: ", centres.size(), " centres but ", radii.size(), " radii");
    std::vector<particle<Real>> ps(centres.size());
    for (std::size_t i = 0; i < ps.size(); ++i) {
        ps[i].position = centres[i];
        ps[i].radius = radii[i];
        ps[i].density = density;
    }
    return ps;
}

/// make_particles with one radius (m) for all.
template <class Real>
std::vector<particle<Real>> make_particles(const std::vector<vec3<Real>>& centres, Real radius, Real density)
{
    return make_particles(centres, std::vector<Real>(centres.size(), radius), density);
}

/// Sizes the world box to the particles (sphere's initGridAndWorldsize): on every wall axis a
/// of s.box the box becomes [min(x - r) - margin r_max, max(x + r) + margin r_max], with
/// `headroom` (m) more above on z (room for an upper wall to move; sphere's z_adjust), and is
/// then extended upwards to a whole number of grid cells of the automatic width
/// 2 r_max + s.skin. Periodic axes keep the extent the caller chose (the period belongs to the
/// sample, e.g. a lattice's n spacing). The walls start on the box faces, so an upper wall
/// starts at the top of the world, as in sphere. `margin` is in units of the largest radius.
/// Sets s.cell_size = 0 (automatic) and returns the grid the simulation will lay over the box.
/// Throws for no particles, a negative or non-finite margin or headroom, or a grid that does
/// not fit (grid_geometry::make).
template <class Real, class Params>
grid_geometry<Real> fit_world(settings<Real, Params>& s, const std::vector<particle<Real>>& particles, Real margin = 2,
                              Real headroom = 0)
{
    if (particles.empty()) detail::fail("fit_world: no particles to fit the world to");
    if (!(margin >= 0) || !std::isfinite(margin))
        detail::fail("fit_world: margin = ", margin, " (in largest radii) must be non-negative and finite");
    if (!(headroom >= 0) || !std::isfinite(headroom))
        detail::fail("fit_world: headroom = ", headroom, " m must be non-negative and finite");
    double r_max = 0, lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
        lo[a] = HUGE_VAL;
        hi[a] = -HUGE_VAL;
    }
    for (std::size_t i = 0; i < particles.size(); ++i) {
        const particle<Real>& p = particles[i];
        if (!(p.radius > 0) || !std::isfinite(p.radius) || !isfinite(p.position))
            detail::fail("fit_world: particle ", i, " has radius ", p.radius, " m and position (", p.position.x, ", ",
                         p.position.y, ", ", p.position.z, ") m; both must be finite, the radius positive");
        r_max = std::max(r_max, double(p.radius));
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], double(p.position[a]) - double(p.radius));
            hi[a] = std::max(hi[a], double(p.position[a]) + double(p.radius));
        }
    }
    // The cell width as the simulation computes it (in Real), so that the box holds exactly
    // the whole number of cells chosen here.
    const Real reach = Real(2) * static_cast<Real>(r_max) + s.skin;
    const double cell = double(reach);
    std::size_t cells[3] = {0, 0, 0};
    for (int a = 0; a < 3; ++a) {
        if (s.box.periodic(a)) continue;
        const double from = lo[a] - double(margin) * r_max;
        const double to = hi[a] + double(margin) * r_max + (a == 2 ? double(headroom) : 0.0);
        cells[a] = static_cast<std::size_t>(std::ceil((to - from) / cell * (1 - 1e-12)));
        s.box.lo[a] = static_cast<Real>(from);
        s.box.hi[a] = static_cast<Real>(from + double(cells[a]) * cell);
    }
    s.cell_size = 0;
    grid_geometry<Real> g = grid_geometry<Real>::make(s.box, reach, Real(0));
    for (int tries = 0; tries < 64; ++tries) { // round-off may leave a hair less than the last cell
        bool short_of = false;
        for (int a = 0; a < 3; ++a)
            if (!s.box.periodic(a) && g.n[a] < cells[a]) {
                s.box.hi[a] = std::nextafter(s.box.hi[a], Real(HUGE_VAL));
                short_of = true;
            }
        if (!short_of) break;
        g = grid_geometry<Real>::make(s.box, reach, Real(0));
    }
    return g;
}

/// Outcome of deposit().
struct deposition_result {
    std::size_t steps = 0; ///< steps taken by deposit()
    double time = 0;       ///< simulated time they took (s)
    double kinetic = 0;    ///< kinetic plus rotational energy at the end (J)
};

/// Runs `sim` (a sphere::simulation with gravity) until the particles are at rest: the
/// kinetic plus rotational energy, checked every `check_every` steps, is below
/// `kinetic_threshold` (J), and at least `min_time` (s) has passed. A negative min_time selects
/// the time a particle needs to fall freely across the world along gravity,
/// sqrt(2 L_g / |g|) with L_g the extent of the box along g, so that particles released at
/// rest are not taken for settled before they have fallen. A useful threshold is a small
/// fraction (1e-6 to 1e-4) of N m g d, the energy of every particle lifted by one diameter.
///
/// `progress`, when given, is called after every check with the deposition so far (a program
/// prints a progress line from it).
///
/// Throws sphere::error when gravity is zero, on a non-positive or non-finite threshold, and
/// when the energy is still above the threshold after `max_steps` steps, naming both.
template <class Sim>
deposition_result deposit(Sim& sim, double kinetic_threshold, std::size_t max_steps, std::size_t check_every = 100,
                          double min_time = -1,
                          const std::function<void(const deposition_result&)>& progress = nullptr)
{
    const auto& s = sim.config();
    const double g = std::sqrt(double(norm2(s.gravity)));
    if (!(g > 0)) detail::fail("deposit: settings.gravity is zero; deposition needs gravity");
    if (!(kinetic_threshold > 0) || !std::isfinite(kinetic_threshold))
        detail::fail("deposit: kinetic energy threshold = ", kinetic_threshold, " J must be positive and finite");
    if (check_every == 0) detail::fail("deposit: check_every = 0: must be at least 1 step");
    if (min_time < 0) {
        double along = 0;
        for (int a = 0; a < 3; ++a) along += double(s.box.length(a)) * std::abs(double(s.gravity[a])) / g;
        min_time = std::sqrt(2 * along / g);
    }
    const double start = sim.time();
    deposition_result out;
    while (true) {
        const std::size_t chunk = std::min(check_every, max_steps - out.steps);
        sim.run(chunk);
        out.steps += chunk;
        out.time = sim.time() - start;
        const auto e = sim.energy();
        out.kinetic = double(e.kinetic) + double(e.rotational);
        if (progress) progress(out);
        if (out.kinetic < kinetic_threshold && out.time >= min_time) return out;
        if (out.steps >= max_steps && out.time < min_time)
            detail::fail("deposit: max_steps = ", max_steps, " steps (", out.time,
                         " s) end before the minimum deposition time ", min_time, " s; raise max_steps");
        if (out.steps >= max_steps)
            detail::fail("deposit: after ", out.steps, " steps (", out.time, " s) the kinetic energy ", out.kinetic,
                         " J is still above the threshold ", kinetic_threshold,
                         " J; raise max_steps or the damping, or the threshold");
    }
}

} // namespace sphere
