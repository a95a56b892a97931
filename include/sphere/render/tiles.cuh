#pragma once
/// \file
/// The ray tracer's acceleration: the image is cut into square tiles of `tile_side` pixels,
/// and each tile lists the drawn spheres whose projection's bounding box, widened by a pixel,
/// covers the centre of one of its pixels (in increasing sphere order). A pixel then tests only
/// its tile's spheres. Built on the host (a count, a prefix sum and a fill, in sphere order).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "../core/vec.cuh"
#include "camera.cuh"
#include "scene.cuh"

namespace sphere {

inline constexpr unsigned tile_side = 16;

struct tile_lists {
    unsigned tiles_x = 0, tiles_y = 0;  ///< tiles per row and per column
    std::vector<std::size_t> start;     ///< tile t's spheres are spheres[start[t], start[t + 1]); tiles by rows
    std::vector<unsigned> spheres;
};

/// A rectangle of pixels, [x0, x1] x [y0, y1] (inclusive).
struct pixel_box {
    long x0, x1, y0, y1;
};

/// The pixels whose rays may hit the sphere of centre c and radius r; false when none may
/// (off the image, or behind the eye).
inline bool sphere_pixels(const camera_frame<double>& f, const vec3<double>& c, double r, pixel_box& box)
{
    const vec3<double> p = f.project(c);
    if (p.z + r <= 0) return false;
    double lo_x = 1e300, hi_x = -1e300, lo_y = 1e300, hi_y = -1e300;
    if (!f.perspective) {
        lo_x = p.x - r / f.pixel, hi_x = p.x + r / f.pixel;
        lo_y = p.y - r / f.pixel, hi_y = p.y + r / f.pixel;
    } else {
        // The projection of the sphere lies in that of its bounding cube (a convex hull),
        // if the whole cube is in front of the eye; else the sphere may cover any pixel.
        for (int k = 0; k < 8; ++k) {
            const vec3<double> corner{c.x + ((k & 1) ? r : -r), c.y + ((k & 2) ? r : -r), c.z + ((k & 4) ? r : -r)};
            const vec3<double> q = f.project(corner);
            if (!(q.z > 1e-9 * f.distance)) {
                lo_x = lo_y = -1e300, hi_x = hi_y = 1e300;
                break;
            }
            lo_x = std::min(lo_x, q.x), hi_x = std::max(hi_x, q.x);
            lo_y = std::min(lo_y, q.y), hi_y = std::max(hi_y, q.y);
        }
    }
    // Pixel x's centre is x + 1/2; one pixel more on each side covers rounding in the kernel.
    auto first = [](double lo, unsigned n) { return long(std::ceil(std::clamp(lo - 1.5, -1.0, double(n)))); };
    auto last = [](double hi, unsigned n) { return long(std::floor(std::clamp(hi + 0.5, -1.0, double(n)))); };
    box = {std::max(first(lo_x, f.width), 0L), std::min(last(hi_x, f.width), long(f.width) - 1),
           std::max(first(lo_y, f.height), 0L), std::min(last(hi_y, f.height), long(f.height) - 1)};
    return box.x0 <= box.x1 && box.y0 <= box.y1;
}

/// The tiles of a validated scene seen through frame f.
template <class Real>
tile_lists bin_spheres(const sphere_scene<Real>& scene, const camera_frame<double>& f, const render_style& style)
{
    tile_lists t;
    t.tiles_x = (f.width + tile_side - 1) / tile_side;
    t.tiles_y = (f.height + tile_side - 1) / tile_side;
    t.start.assign(std::size_t(t.tiles_x) * t.tiles_y + 1, 0);
    const std::size_t n = scene.spheres.size();
    std::vector<pixel_box> boxes(n);
    std::vector<char> seen(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        const vec4<Real>& s = scene.spheres[i];
        if (!drawn(scene, i, style)) continue;
        seen[i] = sphere_pixels(f, {double(s.x), double(s.y), double(s.z)}, double(s.w), boxes[i]);
        if (!seen[i]) continue;
        for (long ty = boxes[i].y0 / tile_side; ty <= boxes[i].y1 / tile_side; ++ty)
            for (long tx = boxes[i].x0 / tile_side; tx <= boxes[i].x1 / tile_side; ++tx)
                ++t.start[std::size_t(ty) * t.tiles_x + std::size_t(tx) + 1];
    }
    for (std::size_t k = 1; k < t.start.size(); ++k) t.start[k] += t.start[k - 1];
    t.spheres.resize(t.start.back());
    std::vector<std::size_t> next(t.start.begin(), t.start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
        if (!seen[i]) continue;
        for (long ty = boxes[i].y0 / tile_side; ty <= boxes[i].y1 / tile_side; ++ty)
            for (long tx = boxes[i].x0 / tile_side; tx <= boxes[i].x1 / tile_side; ++tx)
                t.spheres[next[std::size_t(ty) * t.tiles_x + std::size_t(tx)]++] = unsigned(i);
    }
    return t;
}

} // namespace sphere
