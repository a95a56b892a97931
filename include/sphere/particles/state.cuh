#pragma once
/// \file
/// Particle state as structure-of-arrays in a policy's memory, its kernel view, and a host
/// snapshot of it. Particles keep the index the user gave them for the whole run: the
/// neighbour grid sorts scratch copies, never this state.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../core/constants.cuh"
#include "../core/vec.cuh"
#include "../exec/buffer.cuh"
#include "particle.cuh"

namespace sphere {

/// Raw pointers to every per-particle field; trivially copyable, handed to kernels by value.
template <class Real>
struct particle_view {
    std::size_t n;
    vec4<Real>* x;          ///< position (m) in xyz, radius (m) in w
    vec3<Real>* v;          ///< velocity (m/s)
    vec3<Real>* omega;      ///< angular velocity (rad/s)
    vec3<Real>* v_sync;     ///< velocity at the time of the positions (m/s), seen by contact laws
    vec3<Real>* omega_sync; ///< angular velocity at the time of the positions (rad/s)
    vec3<Real>* angpos;     ///< integrated angular position (rad)
    vec3<Real>* force;      ///< sum of contact forces of the last step (N), without gravity
    vec3<Real>* torque;     ///< sum of contact torques of the last step (N m)
    Real* mass;             ///< (kg)
    Real* pressure;         ///< sum of normal contact force magnitudes over the surface, 4 pi r^2 (Pa)
    Real* e_visc;           ///< energy dissipated by normal and tangential viscous damping (J)
    Real* e_fric;           ///< energy dissipated by Coulomb sliding (J)
    Real* p_visc;           ///< rate of e_visc in the last step (W)
    Real* p_fric;           ///< rate of e_fric in the last step (W)
    std::uint8_t* kind;     ///< motion, as its underlying value
};

namespace detail {
/// Copies particle i's position and radius (kernel body): positions at a reference time, for
/// displacements since then.
template <class Real>
struct copy_positions {
    const vec4<Real>* from;
    vec4<Real>* to;
    SPHERE_HD void operator()(std::size_t i) const { to[i] = from[i]; }
};
} // namespace detail

/// A host copy of every per-particle field, in the user's particle order.
template <class Real>
struct particle_snapshot {
    std::vector<vec4<Real>> x;
    std::vector<vec3<Real>> v, omega, v_sync, omega_sync, angpos, force, torque;
    std::vector<Real> mass, pressure, e_visc, e_fric, p_visc, p_fric;
    std::vector<std::uint8_t> kind;

    std::size_t size() const { return x.size(); }
    vec3<Real> position(std::size_t i) const { return x[i].xyz(); }
    Real radius(std::size_t i) const { return x[i].w; }
};

/// The owning particle arrays.
template <class Real, class Policy>
class particle_state {
public:
    particle_state() = default;

    /// Fills the arrays from validated particle descriptions.
    explicit particle_state(const std::vector<particle<Real>>& particles)
    {
        particle_snapshot<Real> s;
        const std::size_t n = particles.size();
        s.x.resize(n);
        s.v.resize(n);
        s.omega.resize(n);
        s.angpos.assign(n, vec3<Real>{0, 0, 0});
        s.force.assign(n, vec3<Real>{0, 0, 0});
        s.torque.assign(n, vec3<Real>{0, 0, 0});
        s.mass.resize(n);
        s.pressure.assign(n, 0);
        s.e_visc.assign(n, 0);
        s.e_fric.assign(n, 0);
        s.p_visc.assign(n, 0);
        s.p_fric.assign(n, 0);
        s.kind.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            const particle<Real>& p = particles[i];
            s.x[i] = {p.position.x, p.position.y, p.position.z, p.radius};
            const bool still = p.kind == motion::fixed;
            s.v[i] = still ? vec3<Real>{0, 0, 0} : p.velocity;
            s.omega[i] = still ? vec3<Real>{0, 0, 0} : p.angular_velocity;
            s.mass[i] = sphere_mass(p.radius, p.density);
            s.kind[i] = static_cast<std::uint8_t>(p.kind);
        }
        s.v_sync = s.v;
        s.omega_sync = s.omega;
        restore(s);
    }

    std::size_t size() const { return x_.size(); }

    particle_view<Real> view()
    {
        return {x_.size(),       x_.data(),      v_.data(),      omega_.data(),  v_sync_.data(),
                omega_sync_.data(),                                               angpos_.data(),
                force_.data(),   torque_.data(), mass_.data(),   pressure_.data(), e_visc_.data(),
                e_fric_.data(),  p_visc_.data(), p_fric_.data(), kind_.data()};
    }

    particle_snapshot<Real> snapshot() const
    {
        return {x_.to_host(),      v_.to_host(),      omega_.to_host(),    v_sync_.to_host(),
                omega_sync_.to_host(),                                       angpos_.to_host(),
                force_.to_host(),  torque_.to_host(), mass_.to_host(),     pressure_.to_host(),
                e_visc_.to_host(), e_fric_.to_host(), p_visc_.to_host(),   p_fric_.to_host(),
                kind_.to_host()};
    }

    /// Replaces every field by a snapshot's (for restarts and for host-side edits).
    void restore(const particle_snapshot<Real>& s)
    {
        x_.assign(s.x);
        v_.assign(s.v);
        omega_.assign(s.omega);
        v_sync_.assign(s.v_sync);
        omega_sync_.assign(s.omega_sync);
        angpos_.assign(s.angpos);
        force_.assign(s.force);
        torque_.assign(s.torque);
        mass_.assign(s.mass);
        pressure_.assign(s.pressure);
        e_visc_.assign(s.e_visc);
        e_fric_.assign(s.e_fric);
        p_visc_.assign(s.p_visc);
        p_fric_.assign(s.p_fric);
        kind_.assign(s.kind);
    }

private:
    buffer<vec4<Real>, Policy> x_;
    buffer<vec3<Real>, Policy> v_, omega_, v_sync_, omega_sync_, angpos_, force_, torque_;
    buffer<Real, Policy> mass_, pressure_, e_visc_, e_fric_, p_visc_, p_fric_;
    buffer<std::uint8_t, Policy> kind_;
};

} // namespace sphere
