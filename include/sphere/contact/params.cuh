#pragma once
/// \file
/// Parameters of the linear contact model, for particle pairs and for walls.
#include <cstdint>

namespace sphere {

/// How the dashpot coefficients gamma_n and gamma_t are given.
enum class damping_convention : std::uint8_t {
    absolute = 0,    ///< in N s/m, the same for every contact (sphere's convention)
    mass_scaled = 1, ///< in 1/s, multiplied by the contact's effective mass m_eff (kg): the
                     ///< convention of LAMMPS gran/hooke and LIGGGHTS (docs/physics.md, "Normal force")
    damping_ratio = 2, ///< dimensionless ratios zeta to critical damping: c = 2 zeta sqrt(m_eff k_n), so
                       ///< every pair has the same restitution whatever its masses (damping_ratio_from_restitution)
};

/// Linear elastic-viscous contact parameters, SI units (docs/physics.md, "Contact model").
/// For walls, gamma_n/gamma_t/mu_s/mu_d play the role of sphere's gamma_wn/gamma_wt/mu_ws/mu_wd.
template <class Real>
struct contact_params {
    Real k_n = 0;      ///< normal stiffness (N/m), > 0
    Real k_t = 0;      ///< tangential stiffness (N/m), > 0 for elastic tangential laws
    Real gamma_n = 0;  ///< normal viscosity, >= 0: N s/m, 1/s when mass-scaled, or a damping ratio
    Real gamma_t = 0;  ///< tangential viscosity, >= 0: N s/m, 1/s when mass-scaled, or a damping ratio
    Real mu_s = 0;     ///< static friction coefficient, >= 0
    Real mu_d = 0;     ///< dynamic friction coefficient, 0 <= mu_d <= mu_s
    bool tension = false; ///< allow an attractive normal force (false: clipped at 0, as sphere does)
    damping_convention damping = damping_convention::absolute; ///< units of gamma_n and gamma_t

    /// Calls f(name, field, unit) for every field, in the order of checkpoints (io/checkpoint.cuh)
    /// and of the precision checks; Self is contact_params or const contact_params.
    template <class Self, class F>
    static void fields(Self& p, F&& f)
    {
        f("k_n", p.k_n, "N/m");
        f("k_t", p.k_t, "N/m");
        f("gamma_n", p.gamma_n, "");
        f("gamma_t", p.gamma_t, "");
        f("mu_s", p.mu_s, "");
        f("mu_d", p.mu_d, "");
        f("tension", p.tension, "");
        f("damping", p.damping, "");
    }
};

/// The largest valid value of the enumeration (checkpoints refuse larger ones).
constexpr unsigned largest_value(damping_convention) { return 2; }

/// The same parameters in another precision (the user's double values for a contact law that
/// computes in float, precision mixed).
template <class To, class From>
contact_params<To> params_cast(const contact_params<From>& p)
{
    return {To(p.k_n), To(p.k_t), To(p.gamma_n), To(p.gamma_t), To(p.mu_s), To(p.mu_d), p.tension, p.damping};
}

} // namespace sphere
