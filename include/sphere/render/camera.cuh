#pragma once
/// \file
/// The camera of the ray tracer: `camera` (what the user sets: eye, look-at point, up
/// direction, image size in pixels, the width of the view, orthographic or perspective),
/// its validation, and `camera_frame<Real>`, the orthonormal frame the pixel kernel casts
/// rays from (host and device code), with the projection of points onto the image that
/// bins the spheres (render/tiles.cuh).
#include <cmath>
#include <cstddef>

#include "../core/config.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"

namespace sphere {

enum class projection { orthographic, perspective };

/// Pixels are square; (0, 0) is the top-left pixel and the image's centre lies on the line
/// from `eye` to `look_at`. `view_width` is the width of the view in world units in the plane
/// through `look_at` facing the camera (orthographic: everywhere). With a perspective
/// projection the rays leave the eye, whose field of view is then 2 atan(view_width / (2 |look_at - eye|)).
/// Orthographic rays leave the plane through `eye`: what lies behind that plane is not drawn.
struct camera {
    vec3<double> eye{0, -1, 0};
    vec3<double> look_at{0, 0, 0};
    vec3<double> up{0, 0, 1}; ///< the image's upward direction (need not be perpendicular to the view)
    std::size_t width = 800, height = 800; ///< pixels
    double view_width = 1;
    projection kind = projection::orthographic;
};

/// The largest width and height of an image, in pixels.
inline constexpr std::size_t max_image_side = 1 << 15;

/// Throws sphere::error naming the first bad field of a camera.
inline void validate_camera(const camera& c)
{
    if (c.width == 0 || c.height == 0 || c.width > max_image_side || c.height > max_image_side)
        detail::fail("render: camera image size ", c.width, " x ", c.height, " px: each side must be between 1 and ",
                     max_image_side, " pixels");
    if (!isfinite(c.eye) || !isfinite(c.look_at) || !isfinite(c.up))
        detail::fail("render: camera eye, look_at and up must be finite");
    const vec3<double> view = c.look_at - c.eye;
    if (!(norm(view) > 0)) detail::fail("render: camera eye and look_at are the same point");
    if (!(norm(cross(view, c.up)) > 1e-9 * norm(view) * norm(c.up)))
        detail::fail("render: camera up (", c.up.x, ", ", c.up.y, ", ", c.up.z,
                     ") is zero or parallel to the view direction");
    if (!(c.view_width > 0) || !std::isfinite(c.view_width))
        detail::fail("render: camera view_width = ", c.view_width, " must be positive and finite");
}

template <class Real>
struct ray {
    vec3<Real> origin, direction; ///< direction of unit length
};

/// A validated camera as an orthonormal frame in precision Real: right, up and forward (from
/// the eye towards look_at) of unit length, the world size of a pixel, and the distance from
/// the eye to look_at. Trivially copyable: a kernel's member.
template <class Real>
struct camera_frame {
    vec3<Real> eye, right, up, forward;
    Real pixel, distance;
    unsigned width, height;
    bool perspective;

    /// The frame of camera `c` (validated here), computed in double.
    static camera_frame of(const camera& c)
    {
        validate_camera(c);
        const vec3<double> view = c.look_at - c.eye;
        const double distance = norm(view);
        const vec3<double> forward = view / distance;
        const vec3<double> right = cross(forward, c.up) / norm(cross(forward, c.up));
        const vec3<double> up = cross(right, forward);
        auto cast = [](const vec3<double>& v) { return vec3<Real>{Real(v.x), Real(v.y), Real(v.z)}; };
        return {cast(c.eye),
                cast(right),
                cast(up),
                cast(forward),
                Real(c.view_width / double(c.width)),
                Real(distance),
                static_cast<unsigned>(c.width),
                static_cast<unsigned>(c.height),
                c.kind == projection::perspective};
    }

    /// The ray through the centre of pixel (x, y), y counted from the top.
    SPHERE_HDI ray<Real> through(unsigned x, unsigned y) const
    {
        const Real u = (Real(x) + Real(0.5) - Real(0.5) * Real(width)) * pixel;
        const Real v = (Real(0.5) * Real(height) - Real(y) - Real(0.5)) * pixel;
        if (perspective) {
            const vec3<Real> d = distance * forward + u * right + v * up;
            return {eye, d / norm(d)};
        }
        return {eye + u * right + v * up, forward};
    }

    /// Where point p falls on the image, in pixels from the top-left corner (pixel (x, y)
    /// spans [x, x + 1) x [y, y + 1)), and its depth along the view direction from the eye.
    /// With a perspective projection, only points of positive depth have a place.
    SPHERE_HDI vec3<Real> project(const vec3<Real>& p) const
    {
        const vec3<Real> rel = p - eye;
        const Real depth = dot(rel, forward);
        const Real scale = perspective ? distance / depth : Real(1);
        return {Real(0.5) * Real(width) + scale * dot(rel, right) / pixel,
                Real(0.5) * Real(height) - scale * dot(rel, up) / pixel, depth};
    }
};

} // namespace sphere
