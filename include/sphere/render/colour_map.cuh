#pragma once
/// \file
/// The colour map of rendered values: dark blue at the bottom of the range, through blue,
/// cyan, green, yellow and red, to dark red at the top (the "jet" map, as piecewise-linear
/// channels), and a channel rounded to a byte. Host and device code.
#include <cstdint>

#include "../core/config.cuh"
#include "../core/vec.cuh"

namespace sphere {

namespace detail {
/// One channel of the map at t: 1 within 1/8 of its centre, falling linearly to 0 at 3/8.
template <class Real>
SPHERE_HDI Real map_channel(Real t, Real centre)
{
    const Real d = Real(4) * (t - centre);
    const Real c = Real(1.5) - (d < Real(0) ? -d : d);
    return c < Real(0) ? Real(0) : (c > Real(1) ? Real(1) : c);
}
} // namespace detail

/// The colour (red, green, blue in [0, 1]) at t in [0, 1] (clamped; NaN counts as 0): each
/// channel rises and falls linearly around its own centre, blue at t = 1/4, green at 1/2, red
/// at 3/4, so the ends are dark blue (0, 0, 0.5) and dark red (0.5, 0, 0).
template <class Real>
SPHERE_HDI vec3<Real> colour_map(Real t)
{
    t = t > Real(0) ? (t < Real(1) ? t : Real(1)) : Real(0);
    return {detail::map_channel(t, Real(0.75)), detail::map_channel(t, Real(0.5)), detail::map_channel(t, Real(0.25))};
}

/// A colour channel in [0, 1] as a byte, rounded.
template <class Real>
SPHERE_HDI std::uint8_t to_byte(Real c)
{
    const Real v = c * Real(255) + Real(0.5);
    return v >= Real(255) ? std::uint8_t(255) : (v > Real(0) ? std::uint8_t(v) : std::uint8_t(0));
}

/// Where `value` lies in [lo, hi] as a fraction (clamped to [0, 1] by colour_map).
template <class Real>
SPHERE_HDI Real colour_fraction(Real value, Real lo, Real hi)
{
    return (value - lo) / (hi - lo);
}

} // namespace sphere
