#pragma once
/// \file
/// Bonded pairs for a sample, as the seeds' createBondPair and randomBondPairs make them:
/// particle j moved next to particle i in a random direction, at a spacing relative to the sum
/// of their radii, and the bond to hand to the simulation (docs/physics.md, "Bonds").
/// Host-only set-up code; a seed gives the same pairs.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "../bonds/bond_table.cuh"
#include "../boundary/world.cuh"
#include "../core/error.cuh"
#include "../particles/distributions.cuh"
#include "../particles/particle.cuh"

namespace sphere {

namespace detail {
/// A direction uniform on the unit sphere.
inline vec3<double> random_direction(random_stream& rng)
{
    const double z = rng.uniform(-1, 1), phi = rng.uniform(0, 2 * pi<double>), s = std::sqrt(1 - z * z);
    return {s * std::cos(phi), s * std::sin(phi), z};
}

/// Whether particle k, were it at `at`, would overlap a particle other than itself and
/// `partner`, or stick out of the world on an axis closed by walls.
template <class Real>
bool blocked(const std::vector<particle<Real>>& particles, std::size_t k, std::size_t partner, const vec3<Real>& at,
             const world<Real>& box)
{
    const Real r = particles[k].radius;
    for (int a = 0; a < 3; ++a)
        if (!box.periodic(a) && (at[a] - r < box.lo[a] || at[a] + r > box.hi[a])) return true;
    for (std::size_t q = 0; q < particles.size(); ++q) {
        if (q == k || q == partner) continue;
        const Real reach = r + particles[q].radius;
        if (norm2(box.nearest_image_inside(at - particles[q].position)) < reach * reach) return true;
    }
    return false;
}

template <class Real>
void check_spacing(Real spacing, const char* who)
{
    if (!(spacing > -1) || !std::isfinite(spacing))
        fail(who, ": spacing = ", spacing, ": must be finite and above -1 (a fraction of the sum of the radii; "
             "negative overlaps the pair)");
}
} // namespace detail

/// Moves particle j next to particle i, its centre (r_i + r_j)(1 + spacing) from i's in a
/// direction drawn from `rng`, and returns the bond of the two (the seeds' createBondPair:
/// spacing < 0 overlaps them). Nothing checks j's new place against the other particles
/// (random_bond_pairs does).
template <class Real>
bond create_bond_pair(std::vector<particle<Real>>& particles, std::size_t i, std::size_t j, random_stream& rng,
                      Real spacing = Real(-0.1))
{
    if (i >= particles.size() || j >= particles.size() || i == j)
        detail::fail("create_bond_pair: particles ", i, " and ", j, " (", particles.size(), " particles): two distinct ones");
    detail::check_spacing(spacing, "create_bond_pair");
    const vec3<double> d = detail::random_direction(rng);
    const double distance = double(particles[i].radius + particles[j].radius) * (1 + double(spacing));
    particles[j].position = particles[i].position + vec_cast<Real>(d * distance);
    return {i, j};
}

/// Bonds about `ratio` of the particles in pairs (the seeds' randomBondPairs): the particles in
/// an order drawn from `seed` are taken two by two while fewer than ratio N are bonded, and
/// the second of each pair is moved next to the first (create_bond_pair) in up to `tries`
/// random directions until its new place overlaps no other particle and lies inside the
/// world's walls; a pair that finds none stays unbonded, so the count may fall short.
template <class Real>
std::vector<bond> random_bond_pairs(std::vector<particle<Real>>& particles, const world<Real>& box, double ratio,
                                    std::uint64_t seed, Real spacing = Real(-0.1), unsigned tries = 100)
{
    if (!(ratio > 0 && ratio <= 1))
        detail::fail("random_bond_pairs: ratio = ", ratio, ": must be in (0, 1] (the fraction of particles to bond)");
    detail::check_spacing(spacing, "random_bond_pairs");
    random_stream rng(seed);
    std::vector<std::size_t> order(particles.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    for (std::size_t k = order.size(); k > 1; --k) std::swap(order[k - 1], order[rng.below(k)]);
    std::vector<bond> out;
    const double wanted = ratio * double(particles.size());
    for (std::size_t k = 0; k + 1 < order.size() && double(2 * (out.size() + 1)) <= wanted; k += 2) {
        const std::size_t i = order[k], j = order[k + 1];
        const vec3<Real> before = particles[j].position;
        for (unsigned t = 0; t < tries; ++t) {
            create_bond_pair(particles, i, j, rng, spacing);
            particles[j].position = box.wrap(particles[j].position);
            if (!detail::blocked(particles, j, i, particles[j].position, box)) {
                out.push_back({i, j});
                break;
            }
            particles[j].position = before;
        }
    }
    return out;
}

} // namespace sphere
