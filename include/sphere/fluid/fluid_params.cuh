#pragma once
/// \file
/// Material and boundary parameters of the pore fluid (docs/fluid.md, *Navier-Stokes solver*).
#include <cmath>

#include "../core/config.cuh"
#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "poisson.cuh"

namespace sphere {

/// What the top or bottom of the fluid grid is.
enum class fluid_boundary_kind {
    no_flow,  ///< an impermeable, free-slip wall at the face of the grid (zero normal gradient of
              ///< the pressure increment; zero normal velocity)
    pressure, ///< a prescribed pressure held at the centres of the outermost cell layer (drained)
    inflow    ///< a prescribed superficial velocity through the face of the grid (zero normal
              ///< gradient of the pressure increment); the other end must prescribe the pressure
};

/// A boundary kind's name as written in C++ ("no_flow", "pressure", "inflow").
inline const char* name(fluid_boundary_kind k)
{
    switch (k) {
    case fluid_boundary_kind::no_flow: return "no_flow";
    case fluid_boundary_kind::pressure: return "pressure";
    case fluid_boundary_kind::inflow: return "inflow";
    }
    return "?";
}

/// One z end of the fluid grid. For `pressure`, the value at time t is
///   p(t) = pressure + amplitude sin(2 pi frequency t + phase)   (Pa).
/// For `inflow`, `velocity` is the superficial velocity U = phi w through the end face (m/s,
/// along +z at either end: U > 0 at the bottom brings fluid in, at the top takes it out).
template <class Real>
struct fluid_boundary {
    fluid_boundary_kind kind = fluid_boundary_kind::no_flow;
    Real pressure = 0;   ///< mean prescribed pressure (Pa)
    Real amplitude = 0;  ///< amplitude of its sinusoidal modulation (Pa)
    Real frequency = 0;  ///< modulation frequency (Hz)
    Real phase = 0;      ///< modulation phase (rad)
    Real velocity = 0;   ///< inflow: superficial velocity along +z (m/s)

    Real value(double t) const
    {
        return Real(double(pressure) + double(amplitude) * std::sin(2 * pi<double> * double(frequency) * t + double(phase)));
    }

    static fluid_boundary no_flow() { return {}; }
    static fluid_boundary prescribed_pressure(Real p, Real amplitude = 0, Real frequency = 0, Real phase = 0)
    {
        return {fluid_boundary_kind::pressure, p, amplitude, frequency, phase, Real(0)};
    }
    /// A prescribed superficial velocity U (m/s, along +z) through the end face.
    static fluid_boundary inflow(Real superficial_velocity)
    {
        return {fluid_boundary_kind::inflow, Real(0), Real(0), Real(0), Real(0), superficial_velocity};
    }
};

/// The fluid: a Newtonian liquid, water at 25 C by default.
template <class Real>
struct fluid_params {
    Real density = Real(997.05);     ///< rho_f (kg/m^3)
    Real viscosity = Real(8.90e-4);  ///< dynamic viscosity mu_f (Pa s)
    /// Weight of the old pressure in the projection (Langtangen et al. 2002), in [0, 1]:
    /// 0 is Chorin's method, 1 the incremental pressure-correction scheme.
    Real beta = 0;
    vec3<Real> gravity{0, 0, 0};     ///< g (m/s^2)
    fluid_boundary<Real> bottom{};   ///< the z = lo end
    fluid_boundary<Real> top{};      ///< the z = hi end
    poisson_settings poisson{};      ///< tolerance and iteration limit of the pressure solve

    /// Throws sphere::error naming the first invalid value.
    void validate() const
    {
        if (!(density > 0) || !std::isfinite(density))
            detail::fail("fluid: density = ", density, " kg/m^3 must be positive and finite");
        if (!(viscosity > 0) || !std::isfinite(viscosity))
            detail::fail("fluid: viscosity = ", viscosity, " Pa s must be positive and finite");
        if (!(beta >= 0 && beta <= 1)) detail::fail("fluid: beta = ", beta, " must lie in [0, 1]");
        for (int a = 0; a < 3; ++a)
            if (!std::isfinite(gravity[a])) detail::fail("fluid: gravity component ", a, " = ", gravity[a], " is not finite");
        const fluid_boundary<Real>* ends[2] = {&bottom, &top};
        const char* names[2] = {"bottom", "top"};
        for (int e = 0; e < 2; ++e) {
            const auto& b = *ends[e];
            const Real values[5] = {b.pressure, b.amplitude, b.frequency, b.phase, b.velocity};
            const char* fields[5] = {"pressure", "amplitude", "frequency", "phase", "velocity"};
            const char* units[5] = {" Pa", " Pa", " Hz", " rad", " m/s"};
            for (int k = 0; k < 5; ++k)
                if (!std::isfinite(values[k]))
                    detail::fail("fluid: ", names[e], ".", fields[k], " = ", values[k], units[k], " is not finite");
            if (b.frequency < 0)
                detail::fail("fluid: the ", names[e], " boundary frequency = ", b.frequency, " Hz is negative");
            const fluid_boundary<Real>& other = *ends[1 - e];
            if (b.kind == fluid_boundary_kind::inflow && other.kind != fluid_boundary_kind::pressure)
                detail::fail("fluid: an inflow ", names[e], " (velocity ", b.velocity, " m/s) needs a prescribed pressure at the ",
                             names[1 - e], ", where the fluid can leave or enter; it is ",
                             name(other.kind));
        }
    }
};

} // namespace sphere
