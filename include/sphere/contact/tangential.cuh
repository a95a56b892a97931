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
    template <class Real>
    static void validate(const contact_params<Real>&, const char*) {}

    template <class Real>
    SPHERE_HDI static tangential_force<Real> evaluate(const contact_params<Real>& p, const vec3<Real>& /*n*/,
                                                     const vec3<Real>& vt, const vec3<Real>& /*step_t*/, Real fn,
                                                     vec4<Real>& h, Real /*dt*/)
    {
        tangential_force<Real> out;
        out.force = -p.gamma_t * vt;
        const Real ft2 = norm2(out.force);
        const bool was_sliding = h.w != Real(0);
        const Real limit = (was_sliding ? p.mu_d : p.mu_s) * fn;
        if (ft2 > limit * limit) {
            const Real ft = std::sqrt(ft2);
            const Real slide_limit = p.mu_d * fn;
            out.force = out.force * (slide_limit / ft);
            out.fric_rate = slide_limit * norm(vt);
            h.w = 1;
        } else {
            out.visc_rate = p.gamma_t * norm2(vt);
            h.w = 0;
        }
        return out;
    }

    template <class Real>
    SPHERE_HDI static Real stored_energy(const contact_params<Real>&, const vec4<Real>&) { return 0; }
};

/// f_t = -k_t delta_t - gamma_t v_t with the incremental tangential displacement delta_t
/// (incremented by the contact point's tangential displacement in each step), kept in the
/// current contact plane (projected and rescaled to its length, so a rigid
/// rotation of the pair rotates it without shrinking it). At the Coulomb limit the
/// displacement is rescaled so that f_t = mu_d |f_n| t_hat:
/// delta_t = -(mu_d |f_n| t_hat + gamma_t v_t) / k_t (VALIDATION pitfall 4: note the sign).
/// Sticking, the dashpot dissipates gamma_t |v_t|^2; sliding, the contact dissipates the power
/// -f_t . v_t it takes from the motion less the change of the spring's energy, so the energy
/// budget closes whatever gamma_t is.
struct elastic_viscous_frictional {
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
        tangential_force<Real> out;
        // Carry the displacement into the current contact plane, keeping its length.
        vec3<Real> d{h.x, h.y, h.z};
        vec3<Real> before{0, 0, 0};
        const Real len2 = norm2(d);
        if (len2 > Real(0)) { // a new contact has no displacement to carry
            d -= n * dot(n, d);
            const Real in_plane2 = norm2(d);
            if (in_plane2 > Real(0)) before = d * std::sqrt(len2 / in_plane2);
        }
        d = before + step_t; // the spring follows the contact point's actual motion

        out.force = -p.k_t * d - p.gamma_t * vt;
        const Real ft2 = norm2(out.force);
        const bool was_sliding = h.w != Real(0);
        const Real limit = (was_sliding ? p.mu_d : p.mu_s) * fn;
        if (ft2 > limit * limit) {
            const Real ft = std::sqrt(ft2);
            const Real slide_limit = p.mu_d * fn;
            const vec3<Real> t_hat = out.force / ft;
            const vec3<Real> slid = -(slide_limit / p.k_t) * t_hat;
            out.force = slide_limit * t_hat;
            // Sliding: the power taken from the motion, -f_t . v_t, less what the spring stored.
            out.fric_rate = -dot(out.force, vt) - Real(0.5) * p.k_t * (norm2(slid) - norm2(before)) / dt;
            d = slid;
            h.w = 1;
        } else {
            out.visc_rate = p.gamma_t * norm2(vt);
            h.w = 0;
        }
        h.x = d.x;
        h.y = d.y;
        h.z = d.z;
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
