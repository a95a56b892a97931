#pragma once
/// \file
/// What the ray tracer draws: `sphere_scene` (spheres and one value each, host memory) and
/// `render_style` (the colour range of the values, the lower cutoff, the colours and the
/// light), with their validation.
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "image.cuh"

namespace sphere {

template <class Real>
struct sphere_scene {
    std::vector<vec4<Real>> spheres; ///< centre (x, y, z) and radius (w)
    std::vector<Real> values;        ///< one per sphere, coloured by the map; empty: every sphere in render_style::colour
};

/// How the scene is coloured and lit. The values map onto the colour map (render/colour_map.cuh)
/// from `lower_cutoff` (its bottom) to `max_val` (its top; larger values take the top colour);
/// spheres whose value is below `lower_cutoff` (or NaN) are not drawn, as if absent. A point of
/// a sphere is its colour times ambient + (1 - ambient) max(0, n . l), with n the surface's
/// normal and l the direction towards the light, given in the camera's frame: x to the
/// image's right, y up, z towards the viewer (the default light is above, left of and behind
/// the viewer).
struct render_style {
    double max_val = 1000;
    double lower_cutoff = 0;
    rgb background{255, 255, 255};
    rgb colour{200, 200, 210}; ///< the spheres of a scene without values
    double ambient = 0.3;
    vec3<double> light{-0.4, 0.5, 1};
};

/// Throws sphere::error naming the first bad field of a style.
inline void validate_style(const render_style& s)
{
    if (!std::isfinite(s.max_val) || !std::isfinite(s.lower_cutoff) || !(s.max_val > s.lower_cutoff))
        detail::fail("render: max_val = ", s.max_val, " must be finite and above lower_cutoff = ", s.lower_cutoff);
    if (!(s.ambient >= 0 && s.ambient <= 1))
        detail::fail("render: ambient = ", s.ambient, " must lie in [0, 1]");
    if (!isfinite(s.light) || !(norm(s.light) > 0))
        detail::fail("render: light (", s.light.x, ", ", s.light.y, ", ", s.light.z, ") must be finite and not zero");
}

/// Throws sphere::error naming the first bad sphere, or an empty scene, or a number of values
/// that is neither zero nor the number of spheres.
template <class Real>
void validate_scene(const sphere_scene<Real>& scene)
{
    const std::size_t n = scene.spheres.size();
    if (n == 0) detail::fail("render: the scene has no spheres");
    if (n >= std::numeric_limits<unsigned>::max()) detail::fail("render: too many spheres: ", n, " (at most 2^32 - 2)");
    if (!scene.values.empty() && scene.values.size() != n)
        detail::fail("render: ", scene.values.size(), " values for ", n, " spheres (one per sphere, or none)");
    for (std::size_t i = 0; i < n; ++i) {
        const vec4<Real>& s = scene.spheres[i];
        if (!isfinite(s.xyz())) detail::fail("render: sphere ", i, ": centre (", s.x, ", ", s.y, ", ", s.z, ") is not finite");
        if (!(s.w > 0) || !std::isfinite(s.w)) detail::fail("render: sphere ", i, ": radius = ", s.w, " must be positive and finite");
    }
}

/// Whether sphere i is drawn: it has no value, or its value is at least lower_cutoff.
template <class Real>
bool drawn(const sphere_scene<Real>& scene, std::size_t i, const render_style& s)
{
    return scene.values.empty() || double(scene.values[i]) >= s.lower_cutoff;
}

} // namespace sphere
