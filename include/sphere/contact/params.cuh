#pragma once
/// \file
/// Parameters of the linear contact model, for particle pairs and for walls.

namespace sphere {

/// Linear elastic-viscous contact parameters, SI units (docs/physics.md, "Contact model").
/// For walls, gamma_n/gamma_t/mu_s/mu_d play the role of sphere's gamma_wn/gamma_wt/mu_ws/mu_wd.
template <class Real>
struct contact_params {
    Real k_n = 0;      ///< normal stiffness (N/m), > 0
    Real k_t = 0;      ///< tangential stiffness (N/m), > 0 for elastic tangential laws
    Real gamma_n = 0;  ///< normal viscosity (N s/m), absolute, >= 0
    Real gamma_t = 0;  ///< tangential viscosity (N s/m), >= 0
    Real mu_s = 0;     ///< static friction coefficient, >= 0
    Real mu_d = 0;     ///< dynamic friction coefficient, 0 <= mu_d <= mu_s
    bool tension = false; ///< allow an attractive normal force (false: clipped at 0, as sphere does)
};

} // namespace sphere
