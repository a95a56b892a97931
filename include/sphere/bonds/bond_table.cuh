#pragma once
/// \file
/// The bonds of a simulation as the user sees them: pairs of user indices and, per bond, its
/// state (host memory; checkpoints store it).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../core/vec.cuh"

namespace sphere {

/// A bond to create between the particles of user indices i and j, at their distance then.
struct bond {
    std::size_t i, j;
};

/// Every bond of a simulation, in the order they were created (bond k is row k of each array).
template <class Real>
struct bond_table {
    std::vector<unsigned> i, j;      ///< user indices of the two particles
    std::vector<Real> rest;          ///< distance of the centres at creation (m)
    std::vector<vec4<Real>> shear;   ///< shear displacement of i's bond point relative to j's (m) in xyz, twist (rad) in w
    std::vector<vec3<Real>> bend;    ///< bending rotation of i relative to j (rad, a rotation vector)
    std::vector<std::uint8_t> broken; ///< 1 once the bond has broken: it acts no more
    std::vector<Real> released;      ///< the elastic energy the bond held when it broke (J)
    std::vector<Real> dissipated;    ///< energy its dashpots have dissipated (J; 0 without the energy audit)
    std::vector<vec3<Real>> force;   ///< the last step's force on i (N); j feels -force
    std::vector<vec3<Real>> torque_i, torque_j; ///< the last step's torques on i and on j (N m)

    std::size_t size() const { return i.size(); }
    /// Bonds that have not broken.
    std::size_t intact() const
    {
        std::size_t out = 0;
        for (std::uint8_t b : broken) out += b == 0;
        return out;
    }
    /// Appends a fresh bond of particles a and b at rest length `length` (m).
    void add(unsigned a, unsigned b, Real length)
    {
        i.push_back(a);
        j.push_back(b);
        rest.push_back(length);
        shear.push_back({0, 0, 0, 0});
        bend.push_back({0, 0, 0});
        broken.push_back(0);
        released.push_back(0);
        dissipated.push_back(0);
        force.push_back({0, 0, 0});
        torque_i.push_back({0, 0, 0});
        torque_j.push_back({0, 0, 0});
    }
};

} // namespace sphere
