#pragma once
/// \file
/// Pictures of particles: `frame_particles` (an orthographic camera that looks at a
/// snapshot's particles from the side), `render_options` (a render_style, the camera and the
/// colour bar) and `render_particles`, a snapshot's spheres coloured by one of the methods of
/// render/fields.cuh or by any per-particle values, as an image with a colour bar.
#include <algorithm>
#include <cstddef>
#include <optional>
#include <vector>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../particles/state.cuh"
#include "camera.cuh"
#include "colour_bar.cuh"
#include "fields.cuh"
#include "image.cuh"
#include "scene.cuh"
#include "trace.cuh"

namespace sphere {

/// An orthographic camera of width x height pixels looking along +y at the middle of the
/// particles' bounding box (x to the right, z up), which fills the image but the share
/// `keep_right` (in [0, 1)) of its width at the right, with a margin of 5%. Throws
/// sphere::error for an empty snapshot or a bad `keep_right`.
template <class Real>
camera frame_particles(const particle_snapshot<Real>& s, std::size_t width, std::size_t height, double keep_right = 0)
{
    if (s.size() == 0) detail::fail("render: the snapshot has no particles");
    if (!(keep_right >= 0 && keep_right < 1))
        detail::fail("render: frame_particles keeps ", keep_right, " of the width free: must lie in [0, 1)");
    vec3<double> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (std::size_t i = 0; i < s.size(); ++i) {
        const double r = double(s.radius(i));
        const vec3<double> c{double(s.x[i].x), double(s.x[i].y), double(s.x[i].z)};
        lo = {std::min(lo.x, c.x - r), std::min(lo.y, c.y - r), std::min(lo.z, c.z - r)};
        hi = {std::max(hi.x, c.x + r), std::max(hi.y, c.y + r), std::max(hi.z, c.z + r)};
    }
    const vec3<double> size = hi - lo, middle = 0.5 * (lo + hi);
    const double aspect = double(width) / double(height);
    const double fill = std::max(size.x, size.z * aspect * (1 - keep_right)) * 1.05;
    camera c;
    c.width = width;
    c.height = height;
    c.view_width = fill / (1 - keep_right);
    // Shift the view so that the particles sit in the middle of the part left to them.
    c.look_at = middle + vec3<double>{0.5 * keep_right * c.view_width, 0, 0};
    c.eye = c.look_at - vec3<double>{0, size.y + c.view_width, 0};
    c.up = {0, 0, 1};
    return c;
}

struct render_options : render_style {
    std::optional<camera> view; ///< empty: frame_particles at 800 x 800 pixels, keeping room for the bar
    bool colour_bar = true;     ///< drawn for coloured values (not for method normal)
};

/// The snapshot's particles coloured by `values` (one per particle; empty: all in
/// options.colour), with the colour bar from options.lower_cutoff to options.max_val, rendered
/// by Policy's kernels. Throws sphere::error for bad options, an empty snapshot, or values
/// that do not match the particles.
template <class Policy, class Real>
rgb_image render_particles(const particle_snapshot<Real>& s, const std::vector<Real>& values, const render_options& options)
{
    if (s.size() == 0) detail::fail("render: the snapshot has no particles");
    if (!values.empty() && values.size() != s.size())
        detail::fail("render: ", values.size(), " values for ", s.size(), " particles");
    const bool bar = options.colour_bar && !values.empty();
    const camera view = options.view ? *options.view : frame_particles(s, 800, 800, bar ? colour_bar_share : 0.0);
    rgb_image image = render_scene<Policy>(sphere_scene<Real>{s.x, values}, view, options);
    if (bar) draw_colour_bar(image, options.lower_cutoff, options.max_val, options.background);
    return image;
}

/// The snapshot's particles as method m shows them (render/fields.cuh).
template <class Policy, class Real>
rgb_image render_particles(const particle_snapshot<Real>& s, render_method m, const render_options& options)
{
    return render_particles<Policy>(s, particle_values(s, m), options);
}

} // namespace sphere
