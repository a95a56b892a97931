#pragma once
/// \file
/// The ray tracer: `trace_pixels`, the kernel body that colours one pixel (the nearest sphere
/// its ray enters, among its tile's, shaded; else the background), and `render_scene`, which
/// bins the spheres (render/tiles.cuh), runs the kernel over every pixel through the policy's
/// for_each_index and returns the image in host memory.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "../core/config.cuh"
#include "../core/vec.cuh"
#include "../exec/buffer.cuh"
#include "../exec/for_each.cuh"
#include "camera.cuh"
#include "colour_map.cuh"
#include "image.cuh"
#include "scene.cuh"
#include "tiles.cuh"

namespace sphere {

/// How far along ray r it enters sphere s (centre and radius), or `miss` when it does not, or
/// enters it behind its origin. Computed from the ray's closest approach to the centre, which
/// keeps its precision for spheres far from the eye.
template <class Real>
SPHERE_HDI Real entry_distance(const ray<Real>& r, const vec4<Real>& s, Real miss)
{
    const vec3<Real> to_centre = s.xyz() - r.origin;
    const Real along = dot(to_centre, r.direction);
    const Real off2 = norm2(to_centre - along * r.direction);
    const Real inside2 = s.w * s.w - off2;
    if (!(inside2 >= Real(0))) return miss;
    const Real t = along - std::sqrt(inside2);
    return t > Real(0) ? t : miss;
}

/// Kernel body over pixels i = y width + x: writes pixel i's three bytes.
template <class Real>
struct trace_pixels {
    camera_frame<Real> camera;
    const vec4<Real>* spheres;
    const Real* values;     ///< null: every sphere in `colour`
    const std::size_t* start; ///< the tile lists (render/tiles.cuh)
    const unsigned* listed;
    unsigned tiles_x;
    Real lo, hi;            ///< the colour map's range
    Real miss;              ///< +infinity
    vec3<Real> light;       ///< towards the light, world frame, unit length
    Real ambient;
    rgb background, colour;
    std::uint8_t* out;

    SPHERE_HD void operator()(std::size_t i) const
    {
        const unsigned x = static_cast<unsigned>(i % camera.width), y = static_cast<unsigned>(i / camera.width);
        const ray<Real> r = camera.through(x, y);
        const std::size_t tile = std::size_t(y / tile_side) * tiles_x + x / tile_side;
        Real nearest = miss;
        unsigned hit = 0;
        for (std::size_t k = start[tile]; k < start[tile + 1]; ++k) {
            const Real t = entry_distance(r, spheres[listed[k]], miss);
            if (t < nearest) nearest = t, hit = listed[k];
        }
        std::uint8_t* pixel = out + 3 * i;
        if (!(nearest < miss)) {
            pixel[0] = background.r, pixel[1] = background.g, pixel[2] = background.b;
            return;
        }
        const vec4<Real> s = spheres[hit];
        const vec3<Real> normal = (r.origin + nearest * r.direction - s.xyz()) / s.w;
        const Real lambert = dot(normal, light);
        const Real shade = ambient + (Real(1) - ambient) * (lambert > Real(0) ? lambert : Real(0));
        const vec3<Real> base = values ? colour_map(colour_fraction(values[hit], lo, hi))
                                       : vec3<Real>{Real(colour.r), Real(colour.g), Real(colour.b)} / Real(255);
        pixel[0] = to_byte(base.x * shade), pixel[1] = to_byte(base.y * shade), pixel[2] = to_byte(base.z * shade);
    }
};

/// The direction towards the light of `style` (camera frame: right, up, towards the viewer)
/// in the world frame, of unit length.
inline vec3<double> world_light(const camera_frame<double>& f, const render_style& style)
{
    const vec3<double> l = style.light.x * f.right + style.light.y * f.up - style.light.z * f.forward;
    return l / norm(l);
}

/// The scene seen through camera `view`, rendered by Policy's kernels (host: OpenMP threads;
/// cuda: the GPU) in the scene's precision. Throws sphere::error for a bad camera, style or scene.
template <class Policy, class Real>
rgb_image render_scene(const sphere_scene<Real>& scene, const camera& view, const render_style& style)
{
    validate_style(style);
    validate_scene(scene);
    const camera_frame<double> frame = camera_frame<double>::of(view);
    const tile_lists tiles = bin_spheres(scene, frame, style);

    buffer<vec4<Real>, Policy> spheres;
    spheres.assign(scene.spheres);
    buffer<Real, Policy> values;
    values.assign(scene.values);
    buffer<std::size_t, Policy> start;
    start.assign(tiles.start);
    buffer<unsigned, Policy> listed;
    listed.assign(tiles.spheres);
    rgb_image image;
    image.width = view.width;
    image.height = view.height;
    buffer<std::uint8_t, Policy> out(image.width * image.height * 3);

    const vec3<double> light = world_light(frame, style);
    const trace_pixels<Real> body{camera_frame<Real>::of(view),
                                  spheres.data(),
                                  scene.values.empty() ? nullptr : values.data(),
                                  start.data(),
                                  listed.data(),
                                  tiles.tiles_x,
                                  Real(style.lower_cutoff),
                                  Real(style.max_val),
                                  std::numeric_limits<Real>::infinity(),
                                  {Real(light.x), Real(light.y), Real(light.z)},
                                  Real(style.ambient),
                                  style.background,
                                  style.colour,
                                  out.data()};
    for_each_index(Policy{}, image.width * image.height, body);
    image.bytes = out.to_host();
    return image;
}

} // namespace sphere
