#pragma once
/// \file
/// Tangential contact laws (policy types). Each takes the unit normal n, the tangential
/// contact velocity v_t (m/s) at the time of the positions, the tangential displacement of the
/// contact point during the last step (m), |f_n| (N) and the contact's history entry
/// h = (delta_t.x, delta_t.y, delta_t.z, sliding flag), and returns the tangential force on
/// this particle with its dissipation rates. Equations: docs/physics.md, "Tangential force".
#include <cmath>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "params.cuh"

namespace sphere {

/// The tangential part of one contact evaluation.
template <class Real>
struct tangential_force {
    vec3<Real> force{0, 0, 0}; ///< f_t on this particle (N)
    Real visc_rate = 0;        ///< power dissipated by gamma_t (W)
    Real fric_rate = 0;        ///< power dissipated by Coulomb sliding (W)
};

namespace tangential {

/// f_t = -gamma_t v_t, limited to mu |f_n| (static limit mu_s while sticking, mu_d while
/// sliding). Keeps no displacement; only the sliding flag h.w.
struct visco_frictional {
    static constexpr const char* name = "visco_frictional";

    template <class Real>
    static void validate(const contact_params<Real>&, const char*) {}

    template <class Real>
    SPHERE_HDI static tangential_force<Real> evaluate(const contact_params<Real>& p, const vec3<Real>& /*n*/,
                                                     const vec3<Real>& vt, const vec3<Real>& /*step_t*/, Real fn,
                                                     vec4<Real>& h, Real /*dt*/)
    {
        // Written without branches (selects), so that a loop over contacts vectorises.
        tangential_force<Real> out;
        const vec3<Real> trial = -p.gamma_t * vt;
        const Real ft2 = norm2(trial);
        const bool was_sliding = h.w != Real(0);
        const Real limit = (was_sliding ? p.mu_d : p.mu_s) * fn;
        const bool slides = ft2 > limit * limit;
        const Real slide_limit = p.mu_d * fn;
        const Real scale = slide_limit / std::sqrt(slides ? ft2 : Real(1));
        out.force = select(slides, trial * scale, trial);
        out.fric_rate = slides ? slide_limit * norm(vt) : Real(0);
        out.visc_rate = slides ? Real(0) : p.gamma_t * norm2(vt);
        h.w = slides ? Real(1) : Real(0);
        return out;
    }

    template <class Real>
    SPHERE_HDI static Real stored_energy(const contact_params<Real>&, const vec4<Real>&) { return 0; }
};

/// f_t = -k_t delta_t - gamma_t v_t with the incremental tangential displacement delta_t
/// (incremented by the contact point's tangential displacement in each step), kept in the
/// current contact plane (projected and rescaled to its length, so a rigid
/// rotation of the pair rotates it without shrinking it). At the Coulomb limit the
/// displacement is set so that the spring alone carries the sliding force:
/// f_t = mu_d |f_n| t_hat and delta_t = -mu_d |f_n| t_hat / k_t (docs/physics.md, "Tangential
/// force", on why the dashpot force is left out). Sticking, the dashpot dissipates
/// gamma_t |v_t|^2; sliding, the contact dissipates the power -f_t . v_t it takes from the
/// motion less the change of the spring's energy, so the energy budget closes whatever
/// gamma_t is.
struct elastic_viscous_frictional {
    static constexpr const char* name = "elastic_viscous_frictional";

    template <class Real>
    static void validate(const contact_params<Real>& p, const char* where)
    {
        if (!(p.k_t > 0) || !std::isfinite(p.k_t))
            detail::fail(where, ".k_t = ", p.k_t, " N/m: the elastic tangential law needs a positive, finite k_t");
    }

    template <class Real>
    SPHERE_HDI static tangential_force<Real> evaluate(const contact_params<Real>& p, const vec3<Real>& n,
                                                     const vec3<Real>& vt, const vec3<Real>& step_t, Real fn,
                                                     vec4<Real>& h, Real dt)
    {
        // Written without branches (selects, divisions by guarded denominators), so that a
        // loop over contacts vectorises.
        tangential_force<Real> out;
        // Carry the displacement into the current contact plane, keeping its length; a new
        // contact has none to carry.
        const vec3<Real> d{h.x, h.y, h.z};
        const vec3<Real> in_plane = d - n * dot(n, d);
        const Real len2 = norm2(d), in_plane2 = norm2(in_plane);
        const bool carried = len2 > Real(0) && in_plane2 > Real(0);
        const Real stretch = std::sqrt(len2 / (carried ? in_plane2 : Real(1)));
        vec3<Real> before = select(carried, in_plane * stretch, vec3<Real>{0, 0, 0});
        const vec3<Real> spring = before + step_t; // the spring follows the contact point's actual motion

        const vec3<Real> trial = -p.k_t * spring - p.gamma_t * vt;
        const Real ft2 = norm2(trial);
        const bool was_sliding = h.w != Real(0);
        const Real limit = (was_sliding ? p.mu_d : p.mu_s) * fn;
        const bool slides = ft2 > limit * limit;
        const Real slide_limit = p.mu_d * fn;
        const vec3<Real> t_hat = trial / std::sqrt(slides ? ft2 : Real(1));
        const vec3<Real> slid = -(slide_limit / p.k_t) * t_hat;
        out.force = select(slides, slide_limit * t_hat, trial);
        // Sliding: the power taken from the motion, -f_t . v_t, less what the spring stored.
        out.fric_rate =
            slides ? -dot(out.force, vt) - Real(0.5) * p.k_t * (norm2(slid) - norm2(before)) / dt : Real(0);
        out.visc_rate = slides ? Real(0) : p.gamma_t * norm2(vt);
        vec3<Real> kept = select(slides, slid, spring);
        h = {kept.x, kept.y, kept.z, slides ? Real(1) : Real(0)};
        return out;
    }

    /// Elastic energy of the tangential spring, k_t |delta_t|^2 / 2 (J).
    template <class Real>
    SPHERE_HDI static Real stored_energy(const contact_params<Real>& p, const vec4<Real>& h)
    {
        return Real(0.5) * p.k_t * (h.x * h.x + h.y * h.y + h.z * h.z);
    }
};

} // namespace tangential
} // namespace sphere
