#pragma once
// Shared set-up for the validation tests: the common parameter set "P" of
// ../shared/VALIDATION.md and small helpers. Every test is a TEMPLATE_TEST_CASE over float
// and double (the validation cases D1-D11 also over sphere::mixed); tolerances are stated
// where each test asserts.
#include <sphere/dem.cuh>

// The backend the physics tests run on: the host test binary leaves it unset (sphere::host);
// the CUDA test binary (tests/cuda/tests.cu) compiles the same test sources with sphere::cuda.
#ifndef SPHERE_TEST_POLICY
#define SPHERE_TEST_POLICY sphere::host
#endif

#include <cmath>
#include <type_traits>
#include <vector>

namespace sphere_test {

/// The execution policy of the simulations the physics tests create.
using policy = SPHERE_TEST_POLICY;

/// The type in which a simulation of precision P takes and hands out values (settings,
/// particles, snapshots): P itself, or double for sphere::mixed.
template <class P> using user_real = sphere::coord_t<P>;

/// True when the particles' velocities, forces and contact histories are float (float and
/// mixed): such tests use the float tolerances of ../shared/VALIDATION.md.
template <class P> inline constexpr bool single_fields = std::is_same_v<sphere::real_t<P>, float>;

/// Set P: R = 0.01 m, rho = 2500 kg/m^3, k_n = 1e5 N/m, no gravity.
template <class Real>
struct set_p {
    static constexpr Real radius = Real(0.01);
    static constexpr Real density = Real(2500);
    static constexpr Real k_n = Real(1e5);
    static Real mass() { return sphere::sphere_mass(radius, density); } // 1.047198e-2 kg
    static Real inertia() { return Real(0.4) * mass() * radius * radius; }
    static Real dt() { return Real(0.075) * std::sqrt(mass() / k_n); } // 2.42703e-5 s
};

/// Settings for a closed box [-half, half]^3 with set-P stiffness and frictionless, undamped
/// contacts; tests switch on what they need.
template <class Real>
sphere::settings<Real> box_settings(Real half = Real(0.1))
{
    sphere::settings<Real> s;
    s.box.lo = {-half, -half, -half};
    s.box.hi = {half, half, half};
    s.contact.k_n = set_p<Real>::k_n;
    s.contact.k_t = set_p<Real>::k_n * Real(2) / Real(7);
    s.wall = s.contact;
    return s;
}

/// A closed box [-half, half]^3 with set-P stiffness, damping (gamma_n = 5, gamma_t = 2 N s/m),
/// friction (mu_s = 0.5, mu_d = 0.4 between particles, 0.3 at the walls) and gravity: the
/// dissipative, frictional set-up of the grid and determinism tests.
template <class Real>
sphere::settings<Real> frictional_box(double half)
{
    sphere::settings<Real> s;
    s.box.lo = {Real(-half), Real(-half), Real(-half)};
    s.box.hi = {Real(half), Real(half), Real(half)};
    s.contact.k_n = Real(1e5);
    s.contact.k_t = Real(1e5 * 2.0 / 7.0);
    s.contact.gamma_n = Real(5);
    s.contact.gamma_t = Real(2);
    s.contact.mu_s = Real(0.5);
    s.contact.mu_d = Real(0.4);
    s.wall = s.contact;
    s.wall.mu_s = Real(0.3);
    s.wall.mu_d = Real(0.3);
    s.gravity = {Real(0), Real(0), Real(-9.81)};
    return s;
}

template <class Real>
sphere::particle<Real> ball(sphere::vec3<Real> position, sphere::vec3<Real> velocity = {0, 0, 0},
                            Real radius = set_p<Real>::radius)
{
    sphere::particle<Real> p;
    p.position = position;
    p.radius = radius;
    p.density = set_p<Real>::density;
    p.velocity = velocity;
    return p;
}

/// A vector's components in double.
template <class Real>
sphere::vec3<double> to_double(const sphere::vec3<Real>& a)
{
    return {static_cast<double>(a.x), static_cast<double>(a.y), static_cast<double>(a.z)};
}

/// |a - b| / |b|
template <class Real>
double rel_err(Real a, double b)
{
    return std::abs(static_cast<double>(a) - b) / std::abs(b);
}

/// Steps until no particle touches another or a wall (all contact lists hold no overlap),
/// at most max_steps; returns the number of steps taken.
template <class Sim>
std::size_t run_until_separated(Sim& sim, std::size_t max_steps)
{
    std::size_t k = 0;
    bool touched = false;
    for (; k < max_steps; ++k) {
        sim.step();
        const auto s = sim.snapshot();
        double fn = 0;
        for (std::size_t i = 0; i < s.size(); ++i) fn += static_cast<double>(s.pressure[i]);
        if (fn > 0) touched = true;
        else if (touched) break;
    }
    return k;
}

/// F8's bed: fixed spheres of diameter d on a simple cubic lattice of spacing d, 8 x 8 x
/// (2 nz - 1), at (i + offset, j + offset, k + offset) d.
template <class Real>
std::vector<sphere::particle<Real>> fixed_lattice_bed(int nz, double d, double offset)
{
    std::vector<sphere::particle<Real>> bed;
    for (int k = 0; k < 2 * nz - 1; ++k)
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i) {
                sphere::particle<Real> p;
                p.position = {Real((i + offset) * d), Real((j + offset) * d), Real((k + offset) * d)};
                p.radius = Real(d / 2);
                p.density = 2600;
                p.kind = sphere::motion::fixed;
                bed.push_back(p);
            }
    return bed;
}

} // namespace sphere_test
