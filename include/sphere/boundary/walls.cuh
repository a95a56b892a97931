#pragma once
/// \file
/// The planar walls on the faces of the world box, as seen by contact kernels.
#include "../core/vec.cuh"
#include "world.cuh"

namespace sphere {

/// One face of the world box. Face f lies on axis f / 2, at the lower end when f is even.
/// The wall's state is kept in double whatever the simulation's precision: a float position
/// advanced by steps of ~1e-8 m would lose most of each step to rounding.
template <class Real>
struct wall_face {
    bool active = false;  ///< true on wall axes, false on periodic ones
    double position = 0;  ///< coordinate of the plane along its axis (m)
    double velocity = 0;  ///< velocity of the plane along its axis (m/s)
    double force = 0;     ///< force of the particles on the wall along its axis in the last step (N)
    double work = 0;      ///< work done by the wall on the particles so far (J)
};

/// The six faces, copied into kernels by value.
template <class Real>
struct wall_set {
    static constexpr int count = 6;
    wall_face<Real> face[count];

    /// Walls at the faces of a world box, at rest.
    static wall_set from_world(const world<Real>& w)
    {
        wall_set s;
        for (int f = 0; f < count; ++f) {
            const int a = f / 2;
            s.face[f].active = !w.periodic(a);
            s.face[f].position = f % 2 == 0 ? w.lo[a] : w.hi[a];
        }
        return s;
    }

    /// Unit normal of face f pointing into the world (m/m).
    SPHERE_HDI static vec3<Real> inward_normal(int f) { return along_axis(f / 2, f % 2 == 0 ? Real(1) : Real(-1)); }
};

} // namespace sphere
