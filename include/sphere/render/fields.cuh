#pragma once
/// \file
/// The particle values a picture can show, as the original sphere's `render` methods:
/// `normal` (every particle in one colour), `pres` (the particle pressure of the energy
/// audit), `vel` (speed), `angvel` (angular speed), `xdisp` (the accumulated displacement along
/// x); their names, and their values from a particle snapshot. Any other per-particle value is
/// rendered by passing its values directly (render/particles.cuh).
#include <cstddef>
#include <initializer_list>
#include <string>
#include <vector>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../particles/state.cuh"

namespace sphere {

enum class render_method { normal, pres, vel, angvel, xdisp };

inline const char* method_name(render_method m)
{
    switch (m) {
    case render_method::pres: return "pres";
    case render_method::vel: return "vel";
    case render_method::angvel: return "angvel";
    case render_method::xdisp: return "xdisp";
    default: return "normal";
    }
}

/// The method called `name` (normal, pres, vel, angvel, xdisp); throws sphere::error for another
/// name.
inline render_method render_method_named(const std::string& name)
{
    for (render_method m :
         {render_method::normal, render_method::pres, render_method::vel, render_method::angvel, render_method::xdisp})
        if (name == method_name(m)) return m;
    detail::fail("render: unknown method '", name,
                 "' (normal, pres, vel, angvel or xdisp; other values are passed as values)");
}

/// The values method m shows, one per particle in the snapshot's order: empty for normal; the
/// particle pressure (Pa; zeros when the simulation keeps no energy audit); the length of the
/// velocity and of the angular velocity at the time of the positions (m/s, rad/s); the x
/// component of the accumulated displacement (m; zeros when the simulation keeps none). Throws
/// sphere::error when the snapshot's array of that field does not hold one value per particle.
template <class Real>
std::vector<Real> particle_values(const particle_snapshot<Real>& s, render_method m)
{
    std::vector<Real> out;
    if (m == render_method::normal) return out;
    const std::size_t held = m == render_method::pres    ? s.pressure.size()
                             : m == render_method::vel   ? s.v_sync.size()
                             : m == render_method::xdisp ? s.displacement.size()
                                                         : s.omega_sync.size();
    if (held != s.size())
        detail::fail("render: the snapshot holds ", held, " values of ", method_name(m), " for ", s.size(), " particles");
    out.resize(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (m == render_method::pres) out[i] = s.pressure[i];
        else if (m == render_method::xdisp) out[i] = s.displacement[i].x;
        else out[i] = norm(m == render_method::vel ? s.v_sync[i] : s.omega_sync[i]);
    }
    return out;
}

} // namespace sphere
