#pragma once
/// \file
/// What a contact law is given for one contact, and what it returns.
#include "../core/vec.cuh"

namespace sphere {

/// The geometry of one contact, as seen by the particle i it acts on. At a wall the partner j
/// is the wall: r_j = m_j = 0 stand for its infinite radius and mass (r_eff = r_i, m_eff = m_i).
template <class Real>
struct contact_geometry {
    vec3<Real> n;  ///< unit normal, from the partner (particle or wall) towards this particle
    Real delta_n;  ///< overlap (m), negative while in contact
    Real r_i, r_j; ///< radii (m)
    Real r_eff;    ///< effective radius (m): r_i r_j / (r_i + r_j) for a pair, r_i at a wall
    Real m_i, m_j; ///< masses (kg)
    Real m_eff;    ///< effective mass (kg): m_i m_j / (m_i + m_j) for a pair, m_i at a wall
    unsigned material_i; ///< this particle's material index (0 unless the law tells materials apart)
    unsigned material_j; ///< the partner's material index; at a wall, the wall's face (0 to 5)
};

/// The geometry and relative motion of one contact, as seen by the particle it acts on.
template <class Real>
struct contact_motion : contact_geometry<Real> {
    vec3<Real> velocity; ///< velocity of this particle's contact point relative to the partner's,
                         ///< at the time of the positions (m/s): drives the dashpots
    vec3<Real> step;     ///< displacement of the contact point relative to the partner's during
                         ///< the step that led to the positions (m): drives the tangential spring
    vec3<Real> spin;      ///< angular velocity of this particle less the partner's (rad/s, a wall's is 0),
                          ///< at the time of the positions
    vec3<Real> spin_step; ///< rotation of this particle relative to the partner during the step that
                          ///< led to the positions (rad, a rotation vector)
};

/// One evaluated contact, as seen by the particle it acts on.
template <class Real>
struct contact_result {
    vec3<Real> normal{0, 0, 0};     ///< f_n (N)
    vec3<Real> tangential{0, 0, 0}; ///< f_t (N)
    vec3<Real> couple{0, 0, 0};     ///< a torque on this particle beside that of f_t (N m), e.g. rolling
                                    ///< resistance; the partner feels -couple
    Real fn = 0;                    ///< |f_n| (N)
    Real visc_rate = 0;             ///< viscous dissipation, normal + tangential (W)
    Real fric_rate = 0;             ///< frictional dissipation (W)
};

} // namespace sphere
