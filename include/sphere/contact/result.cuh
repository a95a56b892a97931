#pragma once
/// \file
/// What a contact law returns for one contact.
#include "../core/vec.cuh"

namespace sphere {

/// One evaluated contact, as seen by the particle it acts on.
template <class Real>
struct contact_result {
    vec3<Real> normal{0, 0, 0};     ///< f_n (N)
    vec3<Real> tangential{0, 0, 0}; ///< f_t (N)
    Real fn = 0;                    ///< |f_n| (N)
    Real visc_rate = 0;             ///< viscous dissipation, normal + tangential (W)
    Real fric_rate = 0;             ///< frictional dissipation (W)
};

} // namespace sphere
