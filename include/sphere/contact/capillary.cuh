#pragma once
/// \file
/// Capillary cohesion (the seeds' `capillaryCohesion`): a liquid bridge between two particles
/// added to any contact law (the interface of contact/law.cuh). A bridge forms when the
/// particles touch and pulls them together until their gap exceeds the rupture distance.
/// Force: Rabinovich et al. (2005), Langmuir 21:5526, sphere-sphere with a constant bridge
/// volume; rupture distance: Lian et al. (1993), J. Colloid Interface Sci. 161:138.
/// Equations and units: docs/physics.md, "Capillary cohesion".
#include <cmath>
#include <string>

#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "history.cuh"
#include "law.cuh"
#include "linear.cuh"
#include "result.cuh"

namespace sphere {

/// The parameters of a base law plus those of the liquid bridges between particles, SI
/// units. In settings.wall only the base law's fields are used: bridges form between
/// particles, not at walls.
template <class Real, class Base>
struct capillary_params : Base {
    Real surface_tension = 0; ///< gamma (N/m), >= 0
    Real contact_angle = 0;   ///< theta (rad), 0 <= theta < pi/2
    Real bridge_volume = 0;   ///< V, the liquid volume of each bridge (m^3), > 0

    /// Calls f(name, field, unit) for every field: the base law's, then the bridge's.
    template <class Self, class F>
    static void fields(Self& p, F&& f)
    {
        Base::fields(p, f);
        f("surface_tension", p.surface_tension, "N/m");
        f("contact_angle", p.contact_angle, "rad");
        f("bridge_volume", p.bridge_volume, "m^3");
    }
};

/// What the kernels receive: the base law's kernel parameters and the bridge's.
template <class Real, class BaseKernel>
struct capillary_contact {
    BaseKernel base;
    Real tension;  ///< 2 pi gamma cos(theta) (N/m): the pull at contact per unit R
    Real volume;   ///< V (m^3)
    Real rupture;  ///< H_r = (1 + theta / 2) V^(1/3) (m)
};

namespace contact {

/// Capillary cohesion on top of the contact law `Base`. With R = 2 R* (the harmonic mean of
/// the radii), H >= 0 the gap and a = 2 V / (pi R), a bridge pulls each particle towards the
/// other with
///   F(H) = 2 pi R gamma cos(theta) (1 - H / sqrt(H^2 + a))        (N; 0 <= H < H_r)
/// and with F(0) while the particles overlap, on top of the base law's forces.
template <class Base = linear<>>
struct capillary {
    using base_law = Base;
    template <class Real>
    using params = capillary_params<Real, typename Base::template params<Real>>;
    template <class Real>
    using kernel_params = capillary_contact<Real, typename Base::template kernel_params<Real>>;

    static std::string name() { return "capillary<" + Base::name() + ">"; }
    static constexpr const char* history_layout =
        law_history_shape<Base>::value.lanes == 0
            ? "tangential displacement (m) xyz, flags w (bit 0 sliding, bit 1 liquid bridge)"
            : "tangential displacement (m) xyz, flags w (bit 0 sliding, bit 1 liquid bridge); lanes: the base law's";
    static constexpr time_step_rule time_step = Base::time_step;
    static constexpr bool acts_apart = true;
    static constexpr unsigned history_lanes = law_history_shape<Base>::value.lanes; // the base law's
    static constexpr unsigned history_mirror = law_history_shape<Base>::value.mirror;
    template <class Real>
    using history = law_history_t<Base, Real>;

    /// Throws sphere::error naming the first bad parameter (where: the settings they came from).
    template <class Real>
    static void validate(const params<Real>& pair, const params<Real>& wall,
                         const char* pair_where = "settings.contact", const char* wall_where = "settings.wall")
    {
        Base::validate(pair, wall, pair_where, wall_where);
        const char* where = pair_where;
        detail::require_non_negative(where, "surface_tension", pair.surface_tension, "N/m");
        if (!(pair.contact_angle >= 0 && pair.contact_angle < Real(pi<double> / 2)))
            detail::fail(where, ".contact_angle = ", pair.contact_angle, " rad: must lie in [0, pi/2)");
        detail::require_positive(where, "bridge_volume", pair.bridge_volume, "m^3");
    }

    /// Particles of materials a and b with the pair's parameters `contact` (its bridges').
    template <class Real, class From>
    static kernel_params<Real> kernel(const params<From>& a, const params<From>& b, const params<From>& contact)
    {
        const double theta = double(contact.contact_angle), v = double(contact.bridge_volume);
        return {Base::template kernel<Real>(a, b, contact),
                Real(2 * pi<double> * double(contact.surface_tension) * std::cos(theta)), Real(v),
                Real((1 + theta / 2) * std::cbrt(v))};
    }
    template <class Real, class From>
    static kernel_params<Real> pair_kernel(const params<From>& pair)
    {
        return kernel<Real>(pair, pair, pair);
    }
    template <class Real, class From>
    static kernel_params<Real> wall_kernel(const params<From>& pair, const params<From>& wall)
    {
        return {Base::template wall_kernel<Real>(pair, wall), Real(0), Real(0), Real(0)};
    }

    /// Unlike materials (docs/physics.md, "Materials"): the base law's mixing; the liquid (its
    /// surface tension, the bridges' volume) must agree, and the contact angle is the one whose
    /// cosine is the mean of the two cosines.
    template <class Real>
    static params<Real> mix(const params<Real>& a, const params<Real>& b, const char* a_where, const char* b_where)
    {
        detail::agree(a.surface_tension, b.surface_tension, "surface_tension", a_where, b_where);
        detail::agree(a.bridge_volume, b.bridge_volume, "bridge_volume", a_where, b_where);
        params<Real> out = a;
        static_cast<typename Base::template params<Real>&>(out) = Base::mix(a, b, a_where, b_where);
        if (a.contact_angle != b.contact_angle)
            out.contact_angle = Real(std::acos((std::cos(double(a.contact_angle)) + std::cos(double(b.contact_angle))) / 2));
        return out;
    }

    template <class Real>
    static Real time_scale(const params<Real>& pair, const params<Real>& wall, Real mass, Real radius)
    {
        return Base::time_scale(pair, wall, mass, radius);
    }
    template <class Real>
    static std::string time_scale_inputs(const params<Real>& pair, const params<Real>& wall, Real mass, Real radius)
    {
        return Base::time_scale_inputs(pair, wall, mass, radius);
    }

    /// The rupture distance H_r (m).
    template <class Real>
    SPHERE_HDI static Real range(const kernel_params<Real>& p)
    {
        return p.rupture;
    }

    /// The bridge's pull F(H) (N) at gap `gap` (0 while overlapping) for R = 2 R*.
    template <class Real>
    SPHERE_HDI static Real pull(const kernel_params<Real>& p, Real r, Real gap)
    {
        const Real a = Real(2) * p.volume / (pi<Real> * r);
        return p.tension * r * (Real(1) - gap / std::sqrt(gap * gap + a));
    }

    /// The bridge's potential energy (J, <= 0, zero at rupture): minus the work its pull does
    /// from here to the rupture distance, U(H) = -F(0) (H_r - H - sqrt(H_r^2 + a) + sqrt(H^2 + a))
    /// at a gap H = delta_n >= 0, and U(0) + F(0) delta_n while overlapping (docs/physics.md,
    /// "Capillary cohesion"); r = 2 R*.
    template <class Real>
    SPHERE_HDI static Real bridge_energy(const kernel_params<Real>& p, Real r, Real delta_n)
    {
        const Real a = Real(2) * p.volume / (pi<Real> * r);
        const Real h = delta_n > Real(0) ? delta_n : Real(0), inside = delta_n > Real(0) ? Real(0) : delta_n;
        const Real hr = p.rupture;
        return -p.tension * r * (hr - h - std::sqrt(hr * hr + a) + std::sqrt(h * h + a) - inside);
    }

    /// A pair: the base law while the particles overlap, the bridge's pull while one exists.
    /// A bridge forms on contact; its potential energy at that moment is booked as dissipated
    /// (the energy the liquid's surface releases), so that the budget closes.
    template <class Real>
    SPHERE_HDI static contact_result<Real> pair(const kernel_params<Real>& p, const contact_motion<Real>& m,
                                               history<Real>& h, Real dt)
    {
        const bool had_bridge = history_base(h).w >= Real(2);
        history<Real> hb = h; // the base law's history: the flags without the bridge's bit
        history_base(hb).w -= had_bridge ? Real(2) : Real(0);
        const bool touching = m.delta_n < Real(0);
        // Evaluated whatever the overlap (branchless), kept only while touching.
        contact_result<Real> c = Base::pair(p.base, m, hb, dt);
        const vec3<Real> zero{0, 0, 0};
        const bool bridge = touching || (had_bridge && m.delta_n < p.rupture);
        const Real r = Real(2) * m.r_eff;
        const Real gap = touching ? Real(0) : m.delta_n;
        const Real f = bridge ? pull(p, r, gap) : Real(0);
        const Real formed = bridge && !had_bridge ? -bridge_energy(p, r, m.delta_n) / dt : Real(0);
        contact_result<Real> out;
        out.normal = select(touching, c.normal, zero) - m.n * f;
        out.tangential = select(touching, c.tangential, zero);
        out.couple = select(touching, c.couple, zero);
        out.fn = touching ? c.fn : Real(0);
        out.visc_rate = (touching ? c.visc_rate : Real(0)) + formed;
        out.fric_rate = touching ? c.fric_rate : Real(0);
        h = select(touching, hb, history<Real>{});
        history_base(h).w += bridge ? Real(2) : Real(0);
        return out;
    }

    /// A wall contact: the base law's (no bridges at walls).
    template <class Real>
    SPHERE_HDI static contact_result<Real> wall(const kernel_params<Real>& p, const contact_motion<Real>& m,
                                               history<Real>& h, Real dt)
    {
        return Base::wall(p.base, m, h, dt);
    }

    /// The base law's springs while overlapping, plus the bridge's potential energy (J).
    template <class Real>
    SPHERE_HDI static Real pair_energy(const kernel_params<Real>& p, const contact_geometry<Real>& g,
                                      const history<Real>& h)
    {
        const bool bridge = history_base(h).w >= Real(2);
        history<Real> hb = h;
        history_base(hb).w -= bridge ? Real(2) : Real(0);
        const Real spring = g.delta_n < Real(0) ? Base::pair_energy(p.base, g, hb) : Real(0);
        return spring + (bridge ? bridge_energy(p, Real(2) * g.r_eff, g.delta_n) : Real(0));
    }

    template <class Real>
    SPHERE_HDI static Real wall_energy(const kernel_params<Real>& p, const contact_geometry<Real>& g,
                                      const history<Real>& h)
    {
        return Base::wall_energy(p.base, g, h);
    }
};

} // namespace contact
} // namespace sphere
