#pragma once
/// \file
/// Porosity (void fraction) and void ratio of the particles in a box, between the walls, and
/// against depth in horizontal slices (sphere's bulkPorosity, voidRatio and porosity). The
/// solid volume is exact: each sphere contributes the volume of its intersection with the box
/// (or slice), in closed form (caps, wedges and corners of a ball cut by the box's planes),
/// never a count of centres. Host-side functions on snapshot copies, computed in double.
#include <cmath>
#include <cstddef>
#include <vector>

#include "../boundary/walls.cuh"
#include "../boundary/world.cuh"
#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../simulation.cuh"

namespace sphere {

namespace detail {
namespace ball {
// Volumes of parts of a ball of radius r centred at the origin. The divergence theorem gives
// the volume of a region bounded by the sphere and planes x_a = c_a as
//   V = (r S - sum_a c_a A_a) / 3,
// S the area of its spherical patch and A_a the area of its face on plane a; by Archimedes
// the patch has S = r * integral over z of the arc angle at height z, and
//   G(p, z) = z acos(p / rho(z)) - p asin(z / q) + r atan(p z / (r sqrt(q^2 - z^2))),
// rho(z) = sqrt(r^2 - z^2), q = sqrt(r^2 - p^2), is an antiderivative of acos(p / rho(z)).

inline double clamp1(double v) { return v > 1 ? 1 : (v < -1 ? -1 : v); }

inline double G(double p, double z, double r)
{
    if (p == 0) return z * pi<double> / 2;
    const double q2 = r * r - p * p, q = std::sqrt(q2 > 0 ? q2 : 0);
    const double rho2 = r * r - z * z, rho = std::sqrt(rho2 > 0 ? rho2 : 0);
    const double t1 = rho > p ? z * std::acos(p / rho) : 0.0;
    const double t2 = q > 0 ? p * std::asin(clamp1(z / q)) : 0.0;
    const double w2 = q2 - z * z;
    const double t3 = r * std::atan2(p * z, r * std::sqrt(w2 > 0 ? w2 : 0));
    return t1 - t2 + t3;
}

/// Area of the disk of radius rho with y > h, h >= 0 (a circular segment).
inline double segment(double h, double rho)
{
    if (!(h < rho)) return 0;
    return rho * rho * std::acos(h / rho) - h * std::sqrt(rho * rho - h * h);
}

/// Area of the disk of radius rho with x > a and y > b, a, b >= 0.
inline double quadrant(double a, double b, double rho)
{
    if (!(a * a + b * b < rho * rho)) return 0;
    const double angle = std::acos(a / rho) + std::acos(b / rho) - pi<double> / 2;
    return (rho * rho * angle - a * (std::sqrt(rho * rho - a * a) - b) - b * (std::sqrt(rho * rho - b * b) - a)) / 2;
}

/// Volume with z > c, c >= 0 (a cap).
inline double cap(double c, double r)
{
    if (!(c < r)) return 0;
    return pi<double> * (r - c) * (r - c) * (2 * r + c) / 3;
}

/// Volume with y > b and z > c, b, c >= 0.
inline double wedge(double b, double c, double r)
{
    if (!(b * b + c * c < r * r)) return 0;
    const double qb = std::sqrt(r * r - b * b);
    const double S = 2 * r * (G(b, qb, r) - G(b, c, r));
    return (r * S - b * segment(c, qb) - c * segment(b, std::sqrt(r * r - c * c))) / 3;
}

/// Volume with x > a, y > b and z > c, a, b, c >= 0.
inline double corner(double a, double b, double c, double r)
{
    if (!(a * a + b * b + c * c < r * r)) return 0;
    const double zm = std::sqrt(r * r - a * a - b * b);
    const double S = r * (G(a, zm, r) - G(a, c, r) + G(b, zm, r) - G(b, c, r) - pi<double> / 2 * (zm - c));
    return (r * S - a * quadrant(b, c, std::sqrt(r * r - a * a)) - b * quadrant(a, c, std::sqrt(r * r - b * b)) -
            c * quadrant(a, b, std::sqrt(r * r - c * c))) /
           3;
}

/// Volume of the ball with x_a > c[a] for each axis a with bound[a] set (any sign).
inline double above(const double (&c)[3], const bool (&bound)[3], double r)
{
    for (int a = 0; a < 3; ++a)
        if (bound[a] && c[a] < 0) { // {x > c} = ball - {x < c}, and {x < c} mirrors to {x > -c}
            bool without[3] = {bound[0], bound[1], bound[2]};
            without[a] = false;
            double mirrored[3] = {c[0], c[1], c[2]};
            mirrored[a] = -c[a];
            return above(c, without, r) - above(mirrored, bound, r);
        }
    double v[3];
    int k = 0;
    for (int a = 0; a < 3; ++a)
        if (bound[a]) v[k++] = c[a];
    if (k == 0) return 4 * pi<double> / 3 * r * r * r;
    if (k == 1) return cap(v[0], r);
    if (k == 2) return wedge(v[0], v[1], r);
    return corner(v[0], v[1], v[2], r);
}
} // namespace ball
} // namespace detail

/// Volume (m^3) of the part of the sphere with centre `centre` and radius r (m) inside the
/// box [lo, hi] (m); a bound may be -inf or +inf. Exact in closed form (the 1 - pi/6 of a
/// cubic lattice comes out to round-off for any box that spans whole lattice periods, wherever
/// the faces cut the spheres). Returns 0 for an empty box.
inline double sphere_box_volume(const vec3<double>& centre, double r, const vec3<double>& lo, const vec3<double>& hi)
{
    // The box's indicator is the product over axes of [x > lo] - [x > hi]; expanded, each of
    // the (up to) 8 terms is the volume of the ball above a corner point. An axis on which the
    // ball lies wholly inside the box drops out; one on which it lies outside gives 0.
    double lower[3], upper[3];
    bool lower_cuts[3], upper_cuts[3];
    for (int a = 0; a < 3; ++a) {
        lower[a] = lo[a] - centre[a];
        upper[a] = hi[a] - centre[a];
        if (!(lower[a] < upper[a]) || !(lower[a] < r) || !(upper[a] > -r)) return 0;
        lower_cuts[a] = lower[a] > -r;
        upper_cuts[a] = upper[a] < r;
    }
    double v = 0;
    for (int mask = 0; mask < 8; ++mask) { // bit a set: the upper plane of axis a
        double c[3] = {0, 0, 0};
        bool bound[3] = {false, false, false};
        double sign = 1;
        bool skip = false;
        for (int a = 0; a < 3; ++a) {
            if (mask & (1 << a)) {
                if (!upper_cuts[a]) skip = true;
                c[a] = upper[a];
                bound[a] = true;
                sign = -sign;
            } else {
                c[a] = lower[a];
                bound[a] = lower_cuts[a];
            }
        }
        if (!skip) v += sign * detail::ball::above(c, bound, r);
    }
    return v;
}

namespace detail {
/// The lower and upper corner of the space between the walls (m): the current wall positions
/// on wall axes, the whole period on periodic ones.
template <class Real>
void between_walls(const wall_set<Real>& walls, const world<Real>& box, vec3<double>& lo, vec3<double>& hi)
{
    for (int a = 0; a < 3; ++a) {
        lo[a] = box.periodic(a) ? double(box.lo[a]) : double(walls.face[2 * a].position);
        hi[a] = box.periodic(a) ? double(box.hi[a]) : double(walls.face[2 * a + 1].position);
    }
}

template <class Real>
void check_region(const world<Real>& box, const vec3<double>& lo, const vec3<double>& hi, const char* where)
{
    for (int a = 0; a < 3; ++a) {
        if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || !(hi[a] > lo[a]))
            fail(where, ": region axis ", a, " spans [", lo[a], ", ", hi[a], "] m; it must be finite with hi > lo");
        if (box.periodic(a) && (lo[a] < double(box.lo[a]) || hi[a] > double(box.hi[a])))
            fail(where, ": region axis ", a, " spans [", lo[a], ", ", hi[a], "] m, beyond the period [", box.lo[a],
                 ", ", box.hi[a], "] m of that periodic axis");
    }
}
} // namespace detail

/// Solid volume (m^3) of the particles (x: centre in xyz, radius in w, as
/// particle_snapshot::x) inside the box [lo, hi] (m) of the world `box`. On a periodic axis
/// the region must lie within one period; each particle then also counts with its periodic
/// images, so a region spanning the whole period holds every particle's full volume.
template <class Real>
double solid_volume(const std::vector<vec4<Real>>& x, const world<Real>& box, const vec3<double>& lo,
                    const vec3<double>& hi)
{
    detail::check_region(box, lo, hi, "solid_volume");
    bool whole[3];
    for (int a = 0; a < 3; ++a)
        whole[a] = box.periodic(a) && lo[a] == double(box.lo[a]) && hi[a] == double(box.hi[a]);
    vec3<double> from = lo, to = hi;
    for (int a = 0; a < 3; ++a)
        if (whole[a]) { // on this axis the particle and its images fill exactly one sphere's volume
            from[a] = -HUGE_VAL;
            to[a] = HUGE_VAL;
        }
    double v = 0;
    for (const vec4<Real>& p : x) {
        const double r = double(p.w);
        // Images one period either way on periodic axes that the region does not span.
        for (int iz = -1; iz <= 1; ++iz)
            for (int iy = -1; iy <= 1; ++iy)
                for (int ix = -1; ix <= 1; ++ix) {
                    const int shift[3] = {ix, iy, iz};
                    bool use = true;
                    vec3<double> c{double(p.x), double(p.y), double(p.z)};
                    for (int a = 0; a < 3; ++a) {
                        if (shift[a] != 0 && (!box.periodic(a) || whole[a])) use = false;
                        c[a] += shift[a] * double(box.length(a));
                    }
                    if (use) v += sphere_box_volume(c, r, from, to);
                }
    }
    return v;
}

/// Porosity and void ratio of a region.
struct porosity_result {
    double porosity = 0;     ///< void volume over region volume, phi = 1 - V_solid / V
    double void_ratio = 0;   ///< void volume over solid volume, phi / (1 - phi)
    double solid_volume = 0; ///< V_solid (m^3)
    double volume = 0;       ///< V (m^3)
};

/// Void ratio e = phi / (1 - phi) of a porosity phi in [0, 1) (sphere's voidRatio);
/// infinite for phi = 1.
inline double void_ratio(double porosity)
{
    if (!(porosity >= 0 && porosity <= 1))
        detail::fail("void_ratio: porosity = ", porosity, " must lie in [0, 1]");
    return porosity < 1 ? porosity / (1 - porosity) : HUGE_VAL;
}

/// Porosity of the particles (as particle_snapshot::x) in the box [lo, hi] (m) of the world;
/// see solid_volume for periodic axes. Throws for an empty, infinite or out-of-period region.
template <class Real>
porosity_result porosity_in_box(const std::vector<vec4<Real>>& x, const world<Real>& box, const vec3<double>& lo,
                                const vec3<double>& hi)
{
    porosity_result out;
    out.solid_volume = solid_volume(x, box, lo, hi);
    out.volume = (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
    out.porosity = 1 - out.solid_volume / out.volume;
    out.void_ratio = out.porosity / (1 - out.porosity);
    return out;
}

/// Bulk porosity of the particles between the walls (sphere's bulkPorosity): the region
/// spans the current wall positions on wall axes and the whole period on periodic axes.
template <class Real>
porosity_result bulk_porosity(const std::vector<vec4<Real>>& x, const world<Real>& box, const wall_set<Real>& walls)
{
    vec3<double> lo, hi;
    detail::between_walls(walls, box, lo, hi);
    return porosity_in_box(x, box, lo, hi);
}

/// Bulk porosity of a simulation's particles between its walls.
template <class P, class Policy, class Law, class Integrator, class Real = coord_t<P>>
porosity_result bulk_porosity(const simulation<P, Policy, Law, Integrator>& sim)
{
    return bulk_porosity(sim.positions(), sim.config().box, sim.walls());
}

/// Porosity of a simulation's particles in the box [lo, hi] (m).
template <class P, class Policy, class Law, class Integrator, class Real = coord_t<P>>
porosity_result bulk_porosity(const simulation<P, Policy, Law, Integrator>& sim, const vec3<double>& lo,
                              const vec3<double>& hi)
{
    return porosity_in_box(sim.positions(), sim.config().box, lo, hi);
}

/// One horizontal slice of a porosity profile.
struct porosity_slice {
    double z_lo = 0, z_hi = 0; ///< bottom and top of the slice (m)
    double porosity = 0;       ///< porosity within it
};

/// Porosity against depth (sphere's porosity(slices)): the box [lo, hi] (m) cut into
/// `slices` horizontal slices of equal height, bottom first, each with the exact solid volume
/// of every sphere within it.
template <class Real>
std::vector<porosity_slice> porosity_profile(const std::vector<vec4<Real>>& x, const world<Real>& box,
                                             const vec3<double>& lo, const vec3<double>& hi, std::size_t slices)
{
    detail::check_region(box, lo, hi, "porosity_profile");
    if (slices == 0) detail::fail("porosity_profile: slices = 0: at least one is needed");
    std::vector<porosity_slice> out(slices);
    const double h = (hi.z - lo.z) / double(slices);
    for (std::size_t k = 0; k < slices; ++k) {
        vec3<double> a = lo, b = hi;
        a.z = lo.z + h * double(k);
        b.z = k + 1 == slices ? hi.z : lo.z + h * double(k + 1);
        out[k].z_lo = a.z;
        out[k].z_hi = b.z;
        out[k].porosity = 1 - solid_volume(x, box, a, b) / ((b.x - a.x) * (b.y - a.y) * (b.z - a.z));
    }
    return out;
}

/// Porosity profile of a simulation's particles in `slices` horizontal slices between its
/// walls (the whole period on periodic axes).
template <class P, class Policy, class Law, class Integrator, class Real = coord_t<P>>
std::vector<porosity_slice> porosity_profile(const simulation<P, Policy, Law, Integrator>& sim, std::size_t slices)
{
    vec3<double> lo, hi;
    detail::between_walls(sim.walls(), sim.config().box, lo, hi);
    return porosity_profile(sim.positions(), sim.config().box, lo, hi, slices);
}

} // namespace sphere
