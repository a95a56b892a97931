#pragma once
/// \file
/// How the simulation keeps each particle's position at the last rebuild of the contact lists
/// (its reference position): in double, as a point of a fixed-point lattice over the world
/// (three 32-bit steps, 12 B instead of 24); in float, as the position itself (12 B already).
/// The grid and the lists place and list the particles by their own positions; the reference
/// positions decide the near rows and measure the displacements since the rebuild, with
/// margins of their rounding (docs/architecture.md, *Reference positions*).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "world.cuh"

namespace sphere {

/// Steps along x, y and z from a lattice's origin.
struct lattice_point {
    std::uint32_t x, y, z;
};

/// The lattice of reference positions over a world of positions in Coord. In double its step
/// along each axis is a power of two, at least the box's length / (2^32 - 2), and its origin a
/// multiple of the step at most one step below the box: every point origin + q step is a
/// double exactly, encoding it gives q back, and 2^32 - 1 steps cover the box. encode() rounds
/// a position to the nearest point (at most half a step, 2.3e-10 of the box's length, away
/// along each axis), clamped into the lattice; a particle's reference position is that point
/// or its neighbour in the particle's grid cell (grid/neighbor_grid.cuh, reference_in_cell).
/// Other types store positions as they are.
template <class Coord>
struct position_lattice {
    static constexpr bool fixed_point = std::is_same_v<Coord, double>;
    using stored = std::conditional_t<fixed_point, lattice_point, vec3<Coord>>;

    vec3<Coord> origin{0, 0, 0};
    vec3<Coord> step{1, 1, 1};      ///< (m)
    vec3<Coord> per_step{1, 1, 1}; ///< 1 / step (1/m), exact (a power of two)

    /// The lattice over `box`; throws sphere::error for a box that it cannot cover exactly
    /// (an axis of non-finite or no length, or one whose lower end lies more than 2^52 steps,
    /// about 2^20 of its lengths, from the coordinates' origin).
    static position_lattice over(const world<Coord>& box)
    {
        position_lattice l;
        if constexpr (fixed_point) {
            for (int a = 0; a < 3; ++a) {
                const double length = double(box.hi[a]) - double(box.lo[a]);
                if (!(length > 0) || !std::isfinite(length) || !std::isfinite(double(box.lo[a])))
                    detail::fail("the world's axis ", a, " from ", box.lo[a], " to ", box.hi[a],
                                 " m has no finite length for the reference positions' lattice");
                int e = 0;
                const double m = std::frexp(length / 4294967294.0, &e); // length / (2^32 - 2) = m 2^e
                const double step = m == 0.5 ? std::ldexp(0.5, e) : std::ldexp(1.0, e);
                const double first = std::floor(double(box.lo[a]) / step); // the origin in steps
                if (std::fabs(first) > 4503599627370496.0) // 2^52: origin + (2^32 - 1) steps stays exact
                    detail::fail("the world's axis ", a, " from ", box.lo[a], " to ", box.hi[a],
                                 " m lies too far from the origin for the reference positions' lattice (steps of ",
                                 step, " m)");
                l.origin[a] = first * step;
                l.step[a] = step;
                l.per_step[a] = 1 / step;
            }
        }
        return l;
    }

    /// The reference position of x: the nearest lattice point (in double).
    SPHERE_HDI stored encode(const vec3<Coord>& x) const
    {
        if constexpr (fixed_point) {
            return {steps(x.x, origin.x, per_step.x), steps(x.y, origin.y, per_step.y),
                    steps(x.z, origin.z, per_step.z)};
        } else {
            return x;
        }
    }

    /// How far (m) a position in the box may lie from its reference position, at most: a
    /// step along each axis, summed (more than the diagonal of a step, the farthest a neighbour
    /// point of its own can lie: grid/neighbor_grid.cuh, reference_in_cell), in double; 0 in
    /// other types.
    Coord rounding() const
    {
        if constexpr (fixed_point) return step.x + step.y + step.z;
        else return 0;
    }

    /// The position a reference position stands for (exact).
    SPHERE_HDI vec3<Coord> decode(const stored& q) const
    {
        if constexpr (fixed_point) {
            return {origin.x + Coord(q.x) * step.x, origin.y + Coord(q.y) * step.y, origin.z + Coord(q.z) * step.z};
        } else {
            return q;
        }
    }

    /// decode(a) - decode(b), exactly: from the points' difference in steps in double (both
    /// positions and their difference are multiples of the step that a double holds, so this
    /// is the difference of the decoded positions, bit for bit, in fewer operations).
    SPHERE_HDI vec3<Coord> between(const stored& a, const stored& b) const
    {
        if constexpr (fixed_point) {
            using wide = long long;
            return {Coord(wide(a.x) - wide(b.x)) * step.x, Coord(wide(a.y) - wide(b.y)) * step.y,
                    Coord(wide(a.z) - wide(b.z)) * step.z};
        } else {
            return a - b;
        }
    }

private:
    /// The nearest whole number of steps from the origin to c, clamped into [0, 2^32 - 1]
    /// (a NaN to 0: the particle check reports it).
    SPHERE_HDI static std::uint32_t steps(Coord c, Coord origin, Coord per_step)
    {
        const Coord t = std::floor((c - origin) * per_step + Coord(0.5));
        if (!(t > 0)) return 0u;
        return t < Coord(4294967295.0) ? static_cast<std::uint32_t>(t) : 4294967295u;
    }
};

} // namespace sphere
