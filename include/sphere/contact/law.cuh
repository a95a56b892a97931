#pragma once
/// \file
/// What a contact law declares, and the time-step rule built on it.
///
/// A contact law is a type `Law` with (contact/linear.cuh, contact/hertz_mindlin.cuh and
/// contact/capillary.cuh are the examples; docs/architecture.md, "Policy types"):
///
///     template <class Real> using params = ...;         // the user's parameters, in settings
///                                                      // (.contact for pairs, .wall for walls)
///     template <class Real> using kernel_params = ...;  // what the kernels receive, derived once
///     static std::string name();                        // stored in checkpoints
///     static constexpr const char* history_layout;      // what a contact's history holds
///     static constexpr time_step_rule time_step;        // factors of the time scale
///     template <class Real> static void validate(const params<Real>& pair, const params<Real>& wall);
///     template <class Real, class From> static kernel_params<Real> pair_kernel(const params<From>& pair);
///     template <class Real, class From>
///     static kernel_params<Real> wall_kernel(const params<From>& pair, const params<From>& wall);
///     template <class Real>   // the contact time scale of one particle (s): dt is a fraction of the smallest
///     static Real time_scale(const params<Real>& pair, const params<Real>& wall, Real mass, Real radius);
///     template <class Real>   // what time_scale used, for an error message
///     static std::string time_scale_inputs(const params<Real>& pair, const params<Real>& wall, Real mass, Real radius);
///     template <class Real>   // a pair contact (a wall contact): forces, a couple and dissipation rates
///     SPHERE_HDI static contact_result<Real> pair(const kernel_params<Real>&, const contact_motion<Real>&,
///                                                H& history, Real dt);                // and wall(...)
///     template <class Real>   // the elastic energy stored in a contact (J)
///     SPHERE_HDI static Real pair_energy(const kernel_params<Real>&, const contact_geometry<Real>&,
///                                       const H& history);                           // and wall_energy(...)
///
/// with H = law_history_t<Law, Real>: a vec4 (tangential displacement xyz, flags w), or for a
/// law that declares history_lanes a contact_history with its own lanes (contact/history.cuh).
///
/// Each params type P has `template <class Self, class F> static void fields(Self&, F&&)`,
/// calling f(name, field, unit) for every field (a floating value, a bool or an enumeration
/// with largest_value()), which checkpoints and the precision checks use.
///
/// A law that also acts between particles that do not touch (a liquid bridge) declares
///
///     static constexpr bool acts_apart = true;
///     template <class Real>   // the largest gap (m) at which it acts between two particles
///     SPHERE_HDI static Real range(const kernel_params<Real>&);
///
/// and then receives pairs with 0 <= delta_n < range too; pair_energy likewise. The contact
/// lists reach that much further. Walls see contacts only (delta_n < 0).
#include <cmath>
#include <sstream>
#include <string>
#include <type_traits>

#include "../core/config.cuh"
#include "../core/error.cuh"

namespace sphere {

namespace detail {
/// Refuses a law's parameter `where`.`name` = v (with its unit) unless it is positive and finite.
template <class Real>
void require_positive(const char* where, const char* name, Real v, const char* unit)
{
    if (!(v > 0) || !std::isfinite(v)) fail(where, ".", name, " = ", v, " ", unit, ": must be positive and finite");
}
/// Refuses a law's parameter unless it is non-negative and finite.
template <class Real>
void require_non_negative(const char* where, const char* name, Real v, const char* unit)
{
    if (!(v >= 0) || !std::isfinite(v)) fail(where, ".", name, " = ", v, " ", unit, ": must be non-negative and finite");
}

/// Mixing rules for the contact parameters of unlike materials (docs/physics.md, "Materials");
/// each gives a itself when a == b, so a pair of like materials keeps its parameters exactly.
/// Two springs or dashpots in series, each of half the contact: 2 a b / (a + b).
template <class Real>
Real series(Real a, Real b)
{
    return a == b ? a : 2 * a * b / (a + b);
}
/// sqrt(a b), for dimensionless coefficients (friction, restitution).
template <class Real>
Real geometric_mean(Real a, Real b)
{
    return a == b ? a : std::sqrt(a * b);
}
/// Refuses to mix materials whose `name` differs (a switch, or a quantity with no mixing rule).
template <class T>
void agree(const T& a, const T& b, const char* name, const char* a_where, const char* b_where)
{
    if (!(a == b))
        fail(a_where, ".", name, " and ", b_where, ".", name,
             " differ: they have no mixing rule; give the pair's parameters (contact::materials)");
}
} // namespace detail

/// How many particle materials Law tells apart (Law::material_count; 1 for a law without
/// materials, which then takes every particle's material to be 0).
template <class Law, class = void>
struct law_material_count : std::integral_constant<unsigned, 1> {};
template <class Law>
struct law_material_count<Law, std::void_t<decltype(Law::material_count)>>
    : std::integral_constant<unsigned, Law::material_count> {};

/// Whether Law acts between particles that do not touch (Law::acts_apart).
template <class Law, class = void>
struct acts_apart : std::false_type {};
template <class Law>
struct acts_apart<Law, std::enable_if_t<Law::acts_apart>> : std::true_type {};

/// The largest gap (m) at which Law acts between two particles: 0 for a contact law.
template <class Law, class Real, class KernelParams>
SPHERE_HDI Real law_range(const KernelParams& p)
{
    if constexpr (acts_apart<Law>::value) return Real(Law::range(p));
    else return Real(0);
}

/// A law's time-step rule: dt = default_factor * T unless the user sets one, and no dt above
/// bound_factor * T is accepted, with T the smallest of the law's time scale over the
/// particles (docs/physics.md, "Time step"); `scale` writes T as a formula.
struct time_step_rule {
    double default_factor;
    double bound_factor;
    const char* scale;

    /// The bound as a formula, e.g. "0.3 sqrt(m / k_max)".
    std::string bound_formula() const
    {
        std::ostringstream out;
        out << bound_factor << " " << scale;
        return out.str();
    }
};

} // namespace sphere
