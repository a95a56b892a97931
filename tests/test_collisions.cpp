// Binary collisions: validation cases D1-D6 of ../shared/VALIDATION.md (elastic and damped
// restitution, contact duration, maximum overlap, energy audit, oblique impacts with and
// without sliding, between two particles and against a wall) and the restitution helpers of
// contact/restitution.cuh. Set P throughout (support.hpp): R = 0.01 m, rho = 2500 kg/m^3
// (m = 1.047198e-2 kg), k_n = 1e5 N/m, k_t = 2/7 k_n, no gravity, particles near the origin.
// Every test runs in float and double (most also in mixed), on the host backend and, in the CUDA
// test binary (tests/cuda/tests.cu), on sphere::cuda.
//
// Where a result at the default time step depends on where the contact starts within a step
// (the "entry phase"), the test sweeps the entry phase instead of picking one.
#include <catch2/catch.hpp>

#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_collisions {

namespace {

using sphere::vec3;
using sphere_test::ball;
using sphere_test::box_settings;
using sphere_test::rel_err;
using sphere_test::set_p;
using sphere_test::to_double;

template <class P, class Integrator = sphere::integrate::semi_implicit_euler>
using test_sim = sphere::simulation<P, sphere_test::policy, sphere::contact::linear<>, Integrator>;
using sphere_test::single_fields;
using sphere_test::user_real;

constexpr double pi = 3.14159265358979323846;

// Set P in double, for the references.
const double mass_p = 4.0 / 3.0 * pi * 1e-6 * 2500.0;  // 1.047198e-2 kg
const double k_n_p = 1e5;                              // N/m
const double dt_p = 0.075 * std::sqrt(mass_p / k_n_p); // 2.42703e-5 s, the default time step

// D2 viscosities from VALIDATION.md (zeta = 0.215454): pair (m* = m/2) and wall (m* = m).
constexpr double gamma_pair = 9.860147;  // N s/m
constexpr double gamma_wall = 13.944354; // N s/m

/// Entry phases swept where a result depends on them: the gap before contact is
/// (j + 1/2)/n_phases of the distance the bodies close in one step.
constexpr int n_phases = 8;
double entry_gap(int j, double closing_speed, double dt) { return (j + 0.5) / n_phases * closing_speed * dt; }

double norm_d(const vec3<double>& a) { return std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z); }

/// The normal kinematics of the contact a test watches, in double: the overlap delta_n (m,
/// negative in contact) and its rate d(delta_n)/dt (m/s), from the velocities at the time of
/// the positions (v_sync), which the contact law sees on the next step.
struct normal_state {
    double delta;
    double rate;
};

/// Particles 0 and 1, normal from 1 to 0. (The rotational terms of the contact velocity are
/// perpendicular to the normal and do not enter the rate.)
template <class Real>
normal_state pair_state(const sphere::particle_snapshot<Real>& s)
{
    const vec3<double> d = to_double(s.position(0)) - to_double(s.position(1));
    const double dist = norm_d(d);
    const vec3<double> n = d / dist;
    const double rate = dot(to_double(s.v_sync[0]) - to_double(s.v_sync[1]), n);
    return {dist - static_cast<double>(s.radius(0)) - static_cast<double>(s.radius(1)), rate};
}

/// Particle 0 against the wall plane z = z_wall below it (inward normal +z).
template <class Real>
normal_state floor_state(const sphere::particle_snapshot<Real>& s, double z_wall)
{
    return {static_cast<double>(s.x[0].z) - z_wall - static_cast<double>(s.radius(0)),
            static_cast<double>(s.v_sync[0].z)};
}

/// What one collision looked like.
struct contact_record {
    bool separated = false;      ///< the contact began and ended, and the bodies came apart
    double t_c = 0;              ///< contact duration (s), from interpolated crossings (see watch_collision)
    double max_overlap = 0;      ///< largest sampled |delta_n| (m)
    std::size_t force_steps = 0; ///< steps on which particle 0 felt a contact force
};

/// Steps `sim` through one collision of particle 0 and measures it. Stops two force-free steps
/// after the bodies stopped overlapping (so that no elastic energy is left and the velocities
/// are final: the synchronous velocity v + a dt/2 of a step that still had a force is not), or
/// after max_steps.
///
/// Contact duration: the law applies a force on a step exactly when the indicator c of the
/// state before it is negative, with c = delta_n when tension is allowed and
/// c = max(delta_n, delta_n + gamma_n d(delta_n)/dt / k_n) without tension (delta_n < 0 and
/// an unclipped force -k_n delta_n - gamma_n d(delta_n)/dt > 0). Without tension the contact
/// thus ends when the force reaches zero while the spheres still overlap, which is where
/// Schwager & Poeschel's t_c ends. The start and the end are the zero crossings of c,
/// interpolated linearly between the steps around them: before the contact the motion is
/// uniform, so the start is exact up to round-off; at the end c is smooth and the linear
/// interpolation errs by O(dt^2).
template <class Sim, class State>
contact_record watch_collision(Sim& sim, State state, double k_n, double gamma_n, bool tension, std::size_t max_steps)
{
    auto indicator = [&](const normal_state& n) {
        return tension ? n.delta : std::max(n.delta, n.delta + gamma_n * n.rate / k_n);
    };
    contact_record r;
    double c_prev = indicator(state(sim.snapshot()));
    double t_prev = sim.time(), t_in = 0;
    bool began = false, ended = false;
    int free_steps = 0;
    for (std::size_t k = 0; k < max_steps; ++k) {
        sim.step();
        const auto s = sim.snapshot();
        const normal_state n = state(s);
        const double c = indicator(n), t = sim.time();
        const bool force = s.pressure[0] > 0;
        if (force) ++r.force_steps;
        r.max_overlap = std::max(r.max_overlap, -n.delta);
        if (!began && c < 0) {
            began = true;
            t_in = t_prev + (t - t_prev) * c_prev / (c_prev - c);
        } else if (began && !ended && c >= 0) {
            ended = true;
            r.t_c = t_prev + (t - t_prev) * c_prev / (c_prev - c) - t_in;
        }
        free_steps = ended && n.delta >= 0 && !force ? free_steps + 1 : 0;
        if (free_steps == 2) {
            r.separated = true;
            break;
        }
        c_prev = c;
        t_prev = t;
    }
    return r;
}

/// D1 set-up: sphere A (radius r_a) at 1 m/s along +x towards sphere B (radius r_b) at rest,
/// `gap` apart, the point of first contact at the origin; default time step.
struct head_on_result {
    contact_record c;
    double dt;
    double v_a, v_b;     ///< x-velocities after the collision (m/s)
    vec3<double> p0, p1; ///< total momentum before and after (kg m/s)
};

template <class P, class Integrator = sphere::integrate::semi_implicit_euler, class Real = user_real<P>>
head_on_result head_on(Real r_a, Real r_b, Real gap)
{
    const sphere::settings<Real> s = box_settings<Real>();
    test_sim<P, Integrator> sim(s, {ball<Real>({-(r_a + gap / 2), 0, 0}, {1, 0, 0}, r_a),
                                       ball<Real>({r_b + gap / 2, 0, 0}, {0, 0, 0}, r_b)});
    head_on_result out;
    out.dt = sim.dt();
    out.p0 = to_double(sim.momentum());
    out.c = watch_collision(sim, [](const auto& snap) { return pair_state(snap); }, k_n_p, 0, false, 100000);
    const auto snap = sim.snapshot();
    out.v_a = snap.v[0].x;
    out.v_b = snap.v[1].x;
    out.p1 = to_double(sim.momentum());
    return out;
}

/// D2/D3 set-up: a pair (A at 1 m/s along +x onto B at rest) or one sphere at 1 m/s onto the
/// floor, `gap` from contact, with the D2 viscosities and time step dt.
struct damped_result {
    contact_record c;
    double e;        ///< coefficient of restitution, -(normal relative velocity after) / (before)
    double ke0, ke1; ///< kinetic energy before and after (J)
    double e_visc;   ///< viscous dissipation booked by the library (J)
    double e_fric;   ///< frictional dissipation booked by the library (J)
    double elastic1; ///< elastic energy left after the collision (J)
};

template <class P, class Integrator = sphere::integrate::semi_implicit_euler, class Real = user_real<P>>
damped_result damped_collision(bool wall, bool tension, Real dt, Real gap)
{
    const Real r = set_p<Real>::radius;
    sphere::settings<Real> s = box_settings<Real>();
    s.contact.gamma_n = Real(gamma_pair);
    s.wall.gamma_n = Real(gamma_wall);
    s.contact.tension = s.wall.tension = tension;
    s.dt = dt;
    std::vector<sphere::particle<Real>> particles;
    if (wall) {
        s.box.lo.z = -(r + gap); // the floor; the sphere starts at the origin
        particles = {ball<Real>({0, 0, 0}, {0, 0, -1})};
    } else {
        particles = {ball<Real>({-(r + gap / 2), 0, 0}, {1, 0, 0}), ball<Real>({r + gap / 2, 0, 0})};
    }
    test_sim<P, Integrator> sim(s, particles);
    REQUIRE(sim.dt() == Real(sphere::real_t<P>(dt))); // mixed: dt is rounded to float, the velocities' type
    damped_result out;
    out.ke0 = sim.energy().kinetic;
    const double z_wall = static_cast<double>(s.box.lo.z);
    if (wall) {
        out.c = watch_collision(sim, [z_wall](const auto& snap) { return floor_state(snap, z_wall); }, k_n_p,
                                gamma_wall, tension, 100000);
        out.e = static_cast<double>(sim.snapshot().v[0].z); // incoming -1 m/s
    } else {
        out.c = watch_collision(sim, [](const auto& snap) { return pair_state(snap); }, k_n_p, gamma_pair, tension,
                                100000);
        const auto snap = sim.snapshot();
        out.e = static_cast<double>(snap.v[1].x) - static_cast<double>(snap.v[0].x); // incoming 1 m/s
    }
    const auto en = sim.energy();
    out.ke1 = en.kinetic;
    out.e_visc = en.dissipated_visc;
    out.e_fric = en.dissipated_fric;
    out.elastic1 = en.elastic;
    return out;
}

/// D4/D5 set-up: sphere A at (0, 0, -R) with velocity v_a, sphere B at rest directly above it
/// at (0, 0, R), touching; elastic (gamma_n = gamma_t = 0), k_t = 2/7 k_n, mu_s = mu_d = mu.
struct oblique_result {
    contact_record c;
    vec3<double> v_a, v_b, w_a, w_b; ///< final velocities (m/s) and angular velocities (rad/s)
    double e0;                       ///< kinetic energy before (J)
    double ke1, rot1, elastic1;      ///< translational, rotational, elastic energy after (J)
    double e_visc, e_fric;           ///< dissipation booked by the library (J)
    double slip1;                    ///< x-velocity of A's contact point relative to B's after (m/s)
};

template <class P, class Real = user_real<P>>
oblique_result oblique_pair(vec3<Real> v_a, Real mu, Real dt)
{
    const Real r = set_p<Real>::radius;
    sphere::settings<Real> s = box_settings<Real>();
    s.contact.mu_s = s.contact.mu_d = mu;
    s.dt = dt;
    test_sim<P> sim(s, {ball<Real>({0, 0, -r}, v_a), ball<Real>({0, 0, r})});
    REQUIRE(sim.dt() == Real(sphere::real_t<P>(dt))); // mixed: dt is rounded to float, the velocities' type
    oblique_result out;
    out.e0 = sim.energy().kinetic;
    out.c = watch_collision(sim, [](const auto& snap) { return pair_state(snap); }, k_n_p, 0, false, 100000);
    const auto snap = sim.snapshot();
    out.v_a = to_double(snap.v[0]);
    out.v_b = to_double(snap.v[1]);
    out.w_a = to_double(snap.omega[0]);
    out.w_b = to_double(snap.omega[1]);
    // v_c = v_a - v_b + R n x w_a + R n x w_b with n = -z (from B to A): (n x w).x = w.y.
    out.slip1 = out.v_a.x - out.v_b.x + 0.01 * (out.w_a.y + out.w_b.y);
    const auto en = sim.energy();
    out.ke1 = en.kinetic;
    out.rot1 = en.rotational;
    out.elastic1 = en.elastic;
    out.e_visc = en.dissipated_visc;
    out.e_fric = en.dissipated_fric;
    return out;
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Restitution helpers (contact/restitution.cuh) against the D1/D2 tables and the closed forms.
// ---------------------------------------------------------------------------------------------
TEMPLATE_TEST_CASE("restitution helpers reproduce the D1/D2 reference values", "[collision][restitution]", float,
                   double)
{
    using P = TestType;
    using Real = user_real<P>;
    const bool single = single_fields<P>;
    const Real m = set_p<Real>::mass(), k = set_p<Real>::k_n;
    const Real m_pair = sphere::effective_mass(m, m), m_wall = m;
    // effective_mass: m m / (m + m) = m / 2, to round-off.
    CHECK(rel_err(m_pair, mass_p / 2) < (single ? 1e-6 : 1e-14));

    // Tolerances: the table values carry 7 significant digits (gamma_n), 6 (zeta, e) or 5 (t_c);
    // each tolerance is about half a unit in the last digit, relative. Float evaluates the same
    // few closed-form operations in single precision (epsilon 6e-8), well inside them.
    SECTION("gamma_n for e = 0.5 with tension: 9.860147 (pair), 13.944354 (wall) N s/m")
    {
        CHECK(rel_err(sphere::gamma_n_from_restitution(Real(0.5), m_pair, k, true), gamma_pair) < 1e-6);
        CHECK(rel_err(sphere::gamma_n_from_restitution(Real(0.5), m_wall, k, true), gamma_wall) < 1e-6);
        // Damping ratio -ln e / sqrt(pi^2 + ln^2 e) = 0.215454 (6 digits).
        CHECK(rel_err(sphere::damping_ratio_from_restitution(Real(0.5), true), 0.215454) < 3e-6);
    }
    SECTION("the same viscosities give e = 0.550283 without tension")
    {
        // Inverting the rounded e = 0.550283 (half a unit: 9e-7 relative) by bisection; with
        // de/dzeta = -1.49 there, zeta (and gamma_n) inherit up to 1.6e-6 of that rounding.
        CHECK(rel_err(sphere::gamma_n_from_restitution(Real(0.550283), m_pair, k, false), gamma_pair) < 3e-6);
        CHECK(rel_err(sphere::gamma_n_from_restitution(Real(0.550283), m_wall, k, false), gamma_wall) < 3e-6);
    }
    SECTION("restitution_from_damping_ratio and contact_duration give the D2 table")
    {
        const Real zeta_pair = Real(gamma_pair) / (2 * std::sqrt(m_pair * k));
        const Real zeta_wall = Real(gamma_wall) / (2 * std::sqrt(m_wall * k));
        CHECK(rel_err(zeta_pair, 0.215454) < 3e-6);
        CHECK(rel_err(zeta_wall, 0.215454) < 3e-6);
        CHECK(rel_err(sphere::restitution_from_damping_ratio(zeta_pair, true), 0.5) < 1e-6);
        CHECK(rel_err(sphere::restitution_from_damping_ratio(zeta_pair, false), 0.550283) < 1e-6);
        CHECK(rel_err(sphere::contact_duration(zeta_pair, m_pair, k, true), 7.3616e-4) < 1e-5);
        CHECK(rel_err(sphere::contact_duration(zeta_wall, m_wall, k, true), 1.04108e-3) < 1e-5);
        CHECK(rel_err(sphere::contact_duration(zeta_pair, m_pair, k, false), 6.3439e-4) < 1e-5);
        CHECK(rel_err(sphere::contact_duration(zeta_wall, m_wall, k, false), 8.9716e-4) < 1e-5);
    }
    SECTION("undamped limit: e = 1 and t_c = pi sqrt(m*/k_n) (D1)")
    {
        CHECK(sphere::restitution_from_damping_ratio(Real(0), true) == Real(1));
        CHECK(sphere::restitution_from_damping_ratio(Real(0), false) == Real(1));
        CHECK(rel_err(sphere::contact_duration(Real(0), m_pair, k, false), 7.18868e-4) < 1e-5);
        CHECK(rel_err(sphere::contact_duration(Real(0), m_pair, k, true), 7.18868e-4) < 1e-5);
        const Real m_unequal = sphere::effective_mass(Real(8) * m, m); // radii 0.02 / 0.01
        CHECK(rel_err(sphere::contact_duration(Real(0), m_unequal, k, false), 9.58491e-4) < 1e-5);
    }
    SECTION("damping_ratio_from_restitution inverts restitution_from_damping_ratio")
    {
        // Closed form (tension) and bisection to machine epsilon (no tension): the round trip
        // recovers zeta to a few units of round-off, absolute (a float e near 1 carries 6e-8,
        // i.e. 2e-8 of zeta; the float bisection stops at a bracket of 1.2e-7).
        const double tol = single ? 2e-7 : 1e-14;
        for (const Real zeta : {Real(0.01), Real(0.215454), Real(0.5), Real(0.9)}) {
            for (const bool tension : {true, false}) {
                INFO("zeta = " << zeta << ", tension = " << tension);
                const Real e = sphere::restitution_from_damping_ratio(zeta, tension);
                CHECK(std::abs(static_cast<double>(sphere::damping_ratio_from_restitution(e, tension)) -
                               static_cast<double>(zeta)) < tol);
            }
        }
    }
    SECTION("out-of-range arguments are refused")
    {
        CHECK_THROWS_AS(sphere::damping_ratio_from_restitution(Real(1.5), true), sphere::error);
        CHECK_THROWS_AS(sphere::damping_ratio_from_restitution(Real(0), true), sphere::error);
        // Without tension e = exp(-2) = 0.1353 is the critically damped limit.
        CHECK_THROWS_AS(sphere::damping_ratio_from_restitution(Real(0.1), false), sphere::error);
        CHECK_NOTHROW(sphere::damping_ratio_from_restitution(Real(0.1), true));
        CHECK_THROWS_AS(sphere::restitution_from_damping_ratio(Real(1), true), sphere::error);
        CHECK_THROWS_AS(sphere::contact_duration(Real(-0.1), m_pair, k, true), sphere::error);
    }
}

// ---------------------------------------------------------------------------------------------
// D1: elastic head-on collisions.
// ---------------------------------------------------------------------------------------------
TEMPLATE_TEST_CASE("D1: elastic head-on collisions", "[collision][D1]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    // Momentum: each pair force is evaluated from both sides with n and v_c exactly negated, so
    // the forces cancel exactly; only the rounding of v += F/m dt remains: 1e-12 in double,
    // 1e-6 in float (VALIDATION D1).
    const double momentum_tol = single_fields<P> ? 1e-6 : 1e-12;

    SECTION("equal radii: velocities exchange, t_c = 7.18868e-4 s, max overlap 2.28823e-4 m")
    {
        for (int j = 0; j < n_phases; ++j) {
            const head_on_result r = head_on<P>(Real(0.01), Real(0.01), Real(entry_gap(j, 1, dt_p)));
            INFO("phase " << j << ": dt = " << r.dt << " s, v_a = " << r.v_a << ", v_b = " << r.v_b
                          << " m/s, t_c = " << r.c.t_c << " s, max overlap = " << r.c.max_overlap
                          << " m, force steps = " << r.c.force_steps);
            REQUIRE(r.c.separated);
            CHECK(rel_err(r.dt, dt_p) < 1e-6); // the default time step of set P
            // e = (v_b - v_a) / 1 m/s = 1 within 0.3% (VALIDATION D1); A stops, B takes 1 m/s.
            CHECK(rel_err(r.v_b - r.v_a, 1.0) < 3e-3);
            CHECK(std::abs(r.v_a) < 3e-3);
            CHECK(rel_err(r.v_b, 1.0) < 3e-3);
            CHECK(norm_d(r.p1 - r.p0) / norm_d(r.p0) < momentum_tol);
            // t_c = pi sqrt(m*/k_n) = 7.18868e-4 s (29.6 steps). The discrete oscillator's half
            // period is longer by (omega dt)^2/24 = 0.05% (3.4e-7 s = 0.014 dt), and the
            // interpolated crossings resolve it to a small fraction of a step (see
            // watch_collision). Tolerance 0.1 dt (0.34%). The count of steps with a force
            // agrees with it to one step.
            CHECK(std::abs(r.c.t_c - 7.18868e-4) < 0.1 * dt_p);
            CHECK(std::abs(static_cast<double>(r.c.force_steps) * r.dt - r.c.t_c) <= r.dt);
            // Maximum overlap v sqrt(m*/k_n) = 2.28823e-4 m, sampled once per step: near the
            // turning point delta = delta_max cos(omega t), so sampling misses at most
            // 1 - cos(omega dt/2) = 0.14%; the scheme's phase-dependent energy error (the 0.3% of
            // e above) adds as much again. Tolerance 0.5%.
            CHECK(rel_err(r.c.max_overlap, 2.28823e-4) < 5e-3);
        }
    }
    SECTION("unequal radii 0.02 / 0.01, the larger moving: v1' = 7/9, v2' = 16/9 m/s, t_c = 9.58491e-4 s")
    {
        for (int j = 0; j < n_phases; ++j) {
            const head_on_result r = head_on<P>(Real(0.02), Real(0.01), Real(entry_gap(j, 1, dt_p)));
            INFO("phase " << j << ": dt = " << r.dt << " s, v_a = " << r.v_a << ", v_b = " << r.v_b
                          << " m/s, t_c = " << r.c.t_c << " s, force steps = " << r.c.force_steps);
            REQUIRE(r.c.separated);
            // m_a = 8 m, m_b = m: v_a' = (8 - 1)/9, v_b' = 2 * 8/9 (elastic). Their difference is
            // e, within 0.3% of 1 (VALIDATION D1); each velocity to 0.3% as well.
            CHECK(rel_err(r.v_b - r.v_a, 1.0) < 3e-3);
            CHECK(rel_err(r.v_a, 7.0 / 9.0) < 3e-3);
            CHECK(rel_err(r.v_b, 16.0 / 9.0) < 3e-3);
            CHECK(norm_d(r.p1 - r.p0) / norm_d(r.p0) < momentum_tol);
            // t_c = pi sqrt(m*/k_n), m* = 8m/9. The default dt follows the lighter sphere, so the
            // contact lasts 39.5 steps (omega dt = 0.080). Tolerance 0.1 dt, as above.
            CHECK(rel_err(r.dt, dt_p) < 1e-6);
            CHECK(std::abs(r.c.t_c - 9.58491e-4) < 0.1 * dt_p);
            CHECK(std::abs(static_cast<double>(r.c.force_steps) * r.dt - r.c.t_c) <= r.dt);
        }
    }
}

TEMPLATE_TEST_CASE("D1: integrators at the default time step (pitfall 1)", "[collision][D1][integrators]", float,
                   double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    namespace integrate = sphere::integrate;
    // Elastic equal-radius pair at dt = 0.075 sqrt(m/k_n), every entry phase: e = v_b' - v_a'
    // (1 m/s incoming). References: VALIDATION pitfall 1.
    for (int j = 0; j < n_phases; ++j) {
        const Real gap = Real(entry_gap(j, 1, dt_p));
        const head_on_result semi = head_on<P, integrate::semi_implicit_euler>(Real(0.01), Real(0.01), gap);
        const head_on_result taylor = head_on<P, integrate::taylor2>(Real(0.01), Real(0.01), gap);
        const head_on_result euler = head_on<P, integrate::explicit_euler>(Real(0.01), Real(0.01), gap);
        const head_on_result verlet = head_on<P, integrate::velocity_verlet>(Real(0.01), Real(0.01), gap);
        INFO("phase " << j << ": e = " << semi.v_b - semi.v_a << " (semi-implicit Euler), " << taylor.v_b - taylor.v_a
                      << " (taylor2), " << euler.v_b - euler.v_a << " (explicit Euler), " << verlet.v_b - verlet.v_a
                      << " (velocity Verlet)");
        REQUIRE(verlet.c.separated);
        CHECK(rel_err(verlet.v_b - verlet.v_a, 1.0) < 3e-3); // velocity Verlet: 1 within 0.3%, as the default
        CHECK(norm_d(verlet.p1 - verlet.p0) / norm_d(verlet.p0) < (single_fields<P> ? 1e-6 : 1e-12));
        REQUIRE(semi.c.separated);
        REQUIRE(taylor.c.separated);
        REQUIRE(euler.c.separated);
        CHECK(rel_err(semi.v_b - semi.v_a, 1.0) < 3e-3);     // semi-implicit Euler (default): 1 within 0.3%
        CHECK(rel_err(taylor.v_b - taylor.v_a, 1.087) < 5e-3); // sphere's Taylor scheme: 1.087 within 0.5%
        CHECK(rel_err(euler.v_b - euler.v_a, 1.181) < 5e-3);   // explicit Euler: 1.181 within 0.5%
    }
}

// ---------------------------------------------------------------------------------------------
// D2 and D3: damped restitution and its energy audit, pair and wall, with and without tension.
// ---------------------------------------------------------------------------------------------
namespace {
struct d2_reference {
    bool wall, tension;
    double m_eff, gamma_n; // kg, N s/m
    double e, t_c;         // VALIDATION D2
    const char* name;
};
const d2_reference d2_cases[] = {
    // Tension allowed: e = exp(-pi zeta / sqrt(1 - zeta^2)), t_c = pi / omega_d.
    {false, true, mass_p / 2, gamma_pair, 0.500000, 7.3616e-4, "pair, tension"},
    {true, true, mass_p, gamma_wall, 0.500000, 1.04108e-3, "wall, tension"},
    // No tension (force clipped at 0, the default): Schwager & Poeschel (2007).
    {false, false, mass_p / 2, gamma_pair, 0.550283, 6.3439e-4, "pair, no tension"},
    {true, false, mass_p, gamma_wall, 0.550283, 8.9716e-4, "wall, no tension"},
};
} // namespace

namespace {
template <class P, class Integrator>
void check_d2()
{
    using Real = user_real<P>;
    // Tolerances (VALIDATION D2): 3% at the default dt, 0.5% at dt/10 (dt set explicitly).
    //
    // At the default dt, e depends on the entry phase: the dashpot switches on with a force
    // gamma_n v at the first step inside the contact (and, with tension, off at the last), so
    // where the contact starts within a step shifts a damping impulse of up to about
    // gamma_n v dt / 2 at entry and at exit: |e - e_ref| <= (1 + e_ref) gamma_n dt / (2 m*)
    // (0.034-0.035 for the pair, 0.024-0.025 at the wall). Measured over the phases: pair with
    // tension 0.482..0.506 (-3.5%..+1.2%), without 0.537..0.561; wall 0.497..0.514 and
    // 0.541..0.558.
    // So at dt every phase is held to that bound and the phase mean to the 3% of the table;
    // at dt/10 every phase meets 0.5%. The contact duration meets the table at every phase.
    for (const d2_reference& ref : d2_cases) {
        for (const int refine : {1, 10}) {
            const double dt = dt_p / refine, tol = refine == 1 ? 3e-2 : 5e-3;
            const double phase_bound = (1 + ref.e) * ref.gamma_n * dt / (2 * ref.m_eff);
            double e_mean = 0;
            for (int j = 0; j < n_phases; ++j) {
                const damped_result r =
                    damped_collision<P, Integrator>(ref.wall, ref.tension, Real(dt), Real(entry_gap(j, 1, dt)));
                INFO(ref.name << ", dt = " << dt << " s, phase " << j << ": e = " << r.e << " (" << ref.e
                              << "), t_c = " << r.c.t_c << " s (" << ref.t_c << "), force steps = "
                              << r.c.force_steps);
                REQUIRE(r.c.separated);
                e_mean += r.e / n_phases;
                if (refine == 1) CHECK(std::abs(r.e - ref.e) < phase_bound);
                else CHECK(rel_err(r.e, ref.e) < tol);
                CHECK(rel_err(r.c.t_c, ref.t_c) < tol);
                // The interpolated duration agrees with the count of steps with a force to one step.
                CHECK(std::abs(static_cast<double>(r.c.force_steps) * dt - r.c.t_c) <= dt);
            }
            INFO(ref.name << ", dt = " << dt << " s: e averaged over the entry phases = " << e_mean);
            CHECK(rel_err(e_mean, ref.e) < tol);
        }
    }
}

template <class P, class Integrator>
void check_d3()
{
    using Real = user_real<P>;
    // KE0 = KE1 + E_visc, relative to KE0: no elastic energy is left once the bodies are apart,
    // and a head-on impact has no friction. Tolerances (VALIDATION D3): 2.5% at dt, 0.3% at
    // dt/10, at every entry phase.
    for (const d2_reference& ref : d2_cases) {
        for (const int refine : {1, 10}) {
            const double dt = dt_p / refine, tol = refine == 1 ? 2.5e-2 : 3e-3;
            for (int j = 0; j < n_phases; ++j) {
                const damped_result r =
                    damped_collision<P, Integrator>(ref.wall, ref.tension, Real(dt), Real(entry_gap(j, 1, dt)));
                INFO(ref.name << ", dt = " << dt << " s, phase " << j << ": KE0 = " << r.ke0 << ", KE1 = " << r.ke1
                              << ", E_visc = " << r.e_visc << " J, (KE1 + E_visc) / KE0 = "
                              << (r.ke1 + r.e_visc) / r.ke0);
                REQUIRE(r.c.separated);
                CHECK(rel_err(r.ke1 + r.e_visc, r.ke0) < tol);
                CHECK(r.elastic1 == 0);
                CHECK(r.e_fric == 0);
                // The audit is not vacuous: E_visc is the relative-motion energy (pair: half of
                // KE0; wall: all of it) times 1 - e^2. With e within the D2 bounds (|e - e_ref| <=
                // 0.035 at dt, 0.5% at dt/10), 1 - e^2 is within 2 e |e - e_ref|: 5.6% at dt, 0.4%
                // at dt/10 of its value. Tolerances 6% and 1%.
                const double share = ref.wall ? 1.0 : 0.5;
                CHECK(rel_err(r.e_visc, share * (1 - ref.e * ref.e) * r.ke0) < (refine == 1 ? 6e-2 : 1e-2));
            }
        }
    }
}
} // namespace

TEMPLATE_TEST_CASE("D2: damped restitution and contact duration", "[collision][D2]", float, double, sphere::mixed)
{
    SECTION("semi-implicit Euler (default)") { check_d2<TestType, sphere::integrate::semi_implicit_euler>(); }
    SECTION("velocity Verlet") { check_d2<TestType, sphere::integrate::velocity_verlet>(); }
}

TEMPLATE_TEST_CASE("D3: energy audit of the damped collisions", "[collision][D3]", float, double, sphere::mixed)
{
    SECTION("semi-implicit Euler (default)") { check_d3<TestType, sphere::integrate::semi_implicit_euler>(); }
    SECTION("velocity Verlet") { check_d3<TestType, sphere::integrate::velocity_verlet>(); }
}

// ---------------------------------------------------------------------------------------------
// D4: oblique elastic pair without slip.
// ---------------------------------------------------------------------------------------------
TEMPLATE_TEST_CASE("D4: oblique elastic pair, no slip", "[collision][D4]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    // A at (0.01, 0, 0.01) m/s hits B at rest directly above it. Normal: the z-velocities
    // exchange. Tangential: with k_t = 2/7 k_n the tangential oscillation (effective mass 2/7 m*)
    // has the normal frequency, so the contact-point slip 0.01 m/s reverses exactly: impulse
    // J_t = (2/7) m 0.01 -> v_Ax = 5/7 0.01 = 7.142857e-3, v_Bx = 2/7 0.01 = 2.857143e-3 m/s,
    // omega_y = -(5/2) J_t / (m R) = -0.714286 rad/s on both.
    // Tolerances (VALIDATION D4): 1% at dt; 0.1% at dt/10, 0.5% in float (the tangential
    // displacement accumulates increments v_t dt ~ 2e-8 m onto ~1e-6 m in single precision
    // over 300 steps).
    for (const int refine : {1, 10}) {
        const double tol = refine == 1 ? 1e-2 : (single_fields<P> ? 5e-3 : 1e-3);
        const oblique_result r = oblique_pair<P>({Real(0.01), 0, Real(0.01)}, Real(1e9), Real(dt_p / refine));
        INFO("dt = " << dt_p / refine << " s: v_A = (" << r.v_a.x << ", " << r.v_a.z << "), v_B = (" << r.v_b.x
                     << ", " << r.v_b.z << ") m/s, omega_y = " << r.w_a.y << ", " << r.w_b.y
                     << " rad/s, slip after = " << r.slip1 << " m/s, (KE + rot) / KE0 = " << (r.ke1 + r.rot1) / r.e0);
        REQUIRE(r.c.separated);
        CHECK(rel_err(r.v_a.x, 7.142857e-3) < tol);
        CHECK(rel_err(r.v_b.x, 2.857143e-3) < tol);
        CHECK(rel_err(r.w_a.y, -0.714286) < tol);
        CHECK(rel_err(r.w_b.y, -0.714286) < tol);
        // Normal exchange: A stops along z, B leaves at 0.01 m/s (same tolerance, of 0.01 m/s).
        CHECK(std::abs(r.v_a.z) < tol * 0.01);
        CHECK(rel_err(r.v_b.z, 0.01) < tol);
        // Energy: translational + rotational kinetic energy conserved.
        CHECK(rel_err(r.ke1 + r.rot1, r.e0) < tol);
        // It really stuck: no Coulomb sliding at all (mu = 1e9), no dissipation, and the slip
        // reversed (reference -0.01 m/s).
        CHECK(r.e_fric == 0);
        CHECK(r.e_visc == 0);
        CHECK(rel_err(r.slip1, -0.01) < tol);
    }
}

// ---------------------------------------------------------------------------------------------
// D5: oblique elastic pair in gross sliding.
// ---------------------------------------------------------------------------------------------
TEMPLATE_TEST_CASE("D5: oblique elastic pair, gross sliding", "[collision][D5]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    // A at (0.05, 0, 0.01) m/s onto B above it, mu = 0.3: normal impulse J_n = m 0.01 (elastic
    // exchange), tangential J_t = mu J_n = 0.003 m throughout -> v_Ax = 0.047, v_Bx = 0.003 m/s,
    // |omega_y| = (5/2) J_t / (m R) = 0.75 rad/s (negative on both). The slip 0.05 m/s drops by
    // 7 J_t / m = 0.021 to 0.029 m/s and never stops. E_fric / E0 = 0.09115 with
    // E0 = m (0.05^2 + 0.01^2) / 2.
    const Real mu = Real(0.3);
    const double e0_ref = 0.5 * mass_p * (0.05 * 0.05 + 0.01 * 0.01);

    SECTION("VALIDATION set-up at the default dt")
    {
        // Tolerances (VALIDATION D5): 0.5% v_Ax; 2% v_Bx and omega; energy 0.2%. The contact
        // normal turns by ~1.5e-3 rad while A slides 3e-5 m past B (pitfall 8), which costs v_Bx
        // and omega ~0.7% and E_fric 0.23% of itself at dt, 0.29% as dt -> 0 (measured; both
        // shrink tenfold at a tenth of the speed, next section). So E_fric / E0 cannot meet 0.2%
        // of itself here: it is held to 0.5% of itself, the energy balance to 0.2% of E0, and
        // the 0.2% on E_fric is checked at a tenth of the speed.
        const oblique_result r = oblique_pair<P>({Real(0.05), 0, Real(0.01)}, mu, Real(dt_p));
        INFO("v_A = (" << r.v_a.x << ", " << r.v_a.z << "), v_B = (" << r.v_b.x << ", " << r.v_b.z
                       << ") m/s, omega_y = " << r.w_a.y << ", " << r.w_b.y << " rad/s, slip after = " << r.slip1
                       << " m/s, E_fric / E0 = " << r.e_fric / r.e0 << ", balance = "
                       << (r.ke1 + r.rot1 + r.elastic1 + r.e_visc + r.e_fric) / r.e0);
        REQUIRE(r.c.separated);
        CHECK(rel_err(r.e0, e0_ref) < 1e-6);
        CHECK(rel_err(r.v_a.x, 0.047) < 5e-3);
        CHECK(rel_err(r.v_b.x, 0.003) < 2e-2);
        CHECK(rel_err(r.w_a.y, -0.75) < 2e-2);
        CHECK(rel_err(r.w_b.y, -0.75) < 2e-2);
        CHECK(rel_err(norm_d(r.w_a), 0.75) < 2e-2);
        CHECK(rel_err(norm_d(r.w_b), 0.75) < 2e-2);
        // Normal exchange as in D4 (elastic), to 0.5% of 0.01 m/s.
        CHECK(std::abs(r.v_a.z) < 5e-3 * 0.01);
        CHECK(rel_err(r.v_b.z, 0.01) < 5e-3);
        // Energy: the frictional dissipation (0.5%, above), and the balance
        // E0 = KE + rot + E_fric (+ 0 elastic once apart, + 0 viscous with gamma = 0) to 0.2%.
        CHECK(rel_err(r.e_fric / r.e0, 0.09115) < 5e-3);
        CHECK(rel_err(r.ke1 + r.rot1 + r.elastic1 + r.e_visc + r.e_fric, r.e0) < 2e-3);
        CHECK(r.e_visc == 0);
        // It really slid: the contact point still slips forwards at the end (reference 0.029 m/s,
        // to the 2% of the tangential impulse it derives from: 0.021 * 2% = 4.2e-4 m/s).
        CHECK(std::abs(r.slip1 - 0.029) < 4.2e-4);
    }
    SECTION("a tenth of the speed at dt/10: the fixed-normal reference holds to 0.2%")
    {
        // All velocities scaled by 0.1 (references scale with them; E_fric / E0 is unchanged),
        // so the normal turns 10x less; dt/10 removes the time-step error of the friction
        // bookkeeping. Then E_fric / E0 = 0.09115 to 0.2% of itself, velocities to 0.2%.
        // Float: positions of ~0.01 m carry 1e-9 m against overlaps of 2.3e-7 m, 0.4% per ulp,
        // averaged over 300 steps; 0.2% still holds (measured 0.1%).
        const oblique_result r = oblique_pair<P>({Real(0.005), 0, Real(0.001)}, mu, Real(dt_p / 10));
        INFO("v_A = (" << r.v_a.x << ", " << r.v_a.z << "), v_B = (" << r.v_b.x << ", " << r.v_b.z
                       << ") m/s, omega_y = " << r.w_a.y << ", " << r.w_b.y << " rad/s, slip after = " << r.slip1
                       << " m/s, E_fric / E0 = " << r.e_fric / r.e0 << ", balance = "
                       << (r.ke1 + r.rot1 + r.elastic1 + r.e_visc + r.e_fric) / r.e0);
        REQUIRE(r.c.separated);
        CHECK(rel_err(r.v_a.x, 0.0047) < 2e-3);
        CHECK(rel_err(r.v_b.x, 0.0003) < 2e-3);
        CHECK(rel_err(r.w_a.y, -0.075) < 2e-3);
        CHECK(rel_err(r.w_b.y, -0.075) < 2e-3);
        CHECK(rel_err(r.e_fric / r.e0, 0.09115) < 2e-3);
        CHECK(rel_err(r.ke1 + r.rot1 + r.elastic1 + r.e_visc + r.e_fric, r.e0) < 2e-3);
        CHECK(std::abs(r.slip1 - 0.0029) < 0.0029 * 2e-3);
    }
}

// ---------------------------------------------------------------------------------------------
// D6: oblique impact on a wall in sliding.
// ---------------------------------------------------------------------------------------------
TEMPLATE_TEST_CASE("D6: oblique impact on a wall, sliding", "[collision][D6]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    // A sphere at (0.05, 0, -0.01) m/s onto the floor z = lo, touching it; wall law
    // visco-frictional with gamma_wt = 100 N s/m (|gamma_wt v_t| = 5 N always exceeds
    // mu_w f_n <= 0.3 * 0.32 N, so it slides the whole contact), mu_w = 0.3, gamma_wn = 0.
    // J_n = 2 m 0.01 -> v_z' = +0.01 m/s; J_t = mu J_n -> v_x = 0.05 - 0.006 = 0.044 m/s;
    // omega_y = (5/2) J_t / (m R) = +1.5 rad/s; E_fric / E0 = 1 - (0.044^2 + 0.01^2 + 0.4 R^2 1.5^2)
    // / (0.05^2 + 0.01^2) = 0.182308.
    // Tolerances (VALIDATION D6): 0.1% on the velocities; energy 0.5% (the balance relative to
    // E0, and E_fric relative to itself).
    const Real r_p = set_p<Real>::radius;
    for (const int refine : {1, 10}) {
        sphere::settings<Real> s = box_settings<Real>();
        s.box.lo.z = -r_p; // the floor touches the sphere at the origin
        s.wall.gamma_n = 0;
        s.wall.gamma_t = Real(100);
        s.wall.mu_s = s.wall.mu_d = Real(0.3);
        s.dt = Real(dt_p / refine);
        test_sim<P> sim(s, {ball<Real>({0, 0, 0}, {Real(0.05), 0, Real(-0.01)})});
        const double e0 = sim.energy().kinetic;
        const double z_wall = static_cast<double>(s.box.lo.z);
        const contact_record c = watch_collision(
            sim, [z_wall](const auto& snap) { return floor_state(snap, z_wall); }, k_n_p, 0, false, 100000);
        const auto snap = sim.snapshot();
        const vec3<double> v = to_double(snap.v[0]), w = to_double(snap.omega[0]);
        const auto en = sim.energy();
        const double slip = v.x - 0.01 * w.y; // contact point at -R z: (v + w x (-R z)).x
        const double total = en.kinetic + en.rotational + en.elastic + en.dissipated_visc + en.dissipated_fric;
        INFO("dt = " << dt_p / refine << " s: v = (" << v.x << ", " << v.y << ", " << v.z << ") m/s, omega_y = "
                     << w.y << " rad/s, slip after = " << slip << " m/s, E_fric / E0 = " << en.dissipated_fric / e0
                     << ", E_visc = " << en.dissipated_visc << " J, balance = " << total / e0);
        REQUIRE(c.separated);
        CHECK(rel_err(e0, 0.5 * mass_p * (0.05 * 0.05 + 0.01 * 0.01)) < 1e-6);
        CHECK(rel_err(v.x, 0.044) < 1e-3);
        CHECK(rel_err(w.y, 1.5) < 1e-3);
        CHECK(rel_err(v.z, 0.01) < 1e-3);
        CHECK(std::abs(v.y) + std::abs(w.x) + std::abs(w.z) == 0); // nothing leaves the x-z plane
        CHECK(rel_err(en.dissipated_fric / e0, 0.182308) < 5e-3);
        CHECK(rel_err(total, e0) < 5e-3);
        // It slid on every step of the contact: the viscous branch (sticking) never ran, and the
        // contact point still slips at the end (0.044 - 0.015 = 0.029 m/s, to 0.1%).
        CHECK(en.dissipated_visc == 0);
        CHECK(std::abs(slip - 0.029) < 0.029 * 1e-3);
    }
}

TEMPLATE_TEST_CASE("angular position: the time integral of the angular velocity", "[collision][angular_position]",
                   float, double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    // The D6 impact: omega_y grows from 0 to 1.5 rad/s while the sphere slides on the floor,
    // then stays. The angular position is sum omega(t_k) dt over the steps (semi-implicit
    // Euler: the angular velocity each step has just set), which the test adds up in double
    // from the snapshots; with velocity Verlet it is the mid-step omega, which the test cannot
    // see: only the free spin after the impact is checked, phi_y(t2) - phi_y(t1) =
    // omega_y (t2 - t1). Tolerance: the rounding of the field's own sum of 2000 terms, at
    // most 2000 x 6e-8 = 1.2e-4 in float fields, 1e-10 in double.
    const Real r_p = set_p<Real>::radius;
    const double tol = sphere_test::single_fields<P> ? 1.2e-4 : 1e-10;
    sphere::settings<Real> s = box_settings<Real>();
    s.box.lo.z = -r_p;
    s.wall.gamma_n = 0;
    s.wall.gamma_t = Real(100);
    s.wall.mu_s = s.wall.mu_d = Real(0.3);
    s.dt = Real(dt_p);
    const std::vector<sphere::particle<Real>> ball_on_floor{ball<Real>({0, 0, 0}, {Real(0.05), 0, Real(-0.01)})};
    const std::size_t steps = 2000;
    SECTION("semi-implicit Euler: every step")
    {
        test_sim<P> sim(s, ball_on_floor);
        double phi = 0;
        for (std::size_t k = 0; k < steps; ++k) {
            sim.step();
            phi += double(sim.snapshot().omega[0].y) * double(sim.dt());
        }
        const auto snap = sim.snapshot();
        INFO("phi_y = " << double(snap.angpos[0].y) << " rad, sum of omega_y dt = " << phi << " rad");
        CHECK(double(snap.omega[0].y) > 1.4); // it did spin up
        CHECK(rel_err(snap.angpos[0].y, phi) < tol);
        CHECK(snap.angpos[0].x == 0);
        CHECK(snap.angpos[0].z == 0);
    }
    SECTION("velocity Verlet: the free spin after the impact")
    {
        test_sim<P, sphere::integrate::velocity_verlet> sim(s, ball_on_floor);
        sim.run(steps / 2);
        const auto before = sim.snapshot();
        sim.run(steps / 2);
        const auto after = sim.snapshot();
        REQUIRE(after.omega[0].y == before.omega[0].y); // off the floor: omega stays
        const double turned = double(after.angpos[0].y) - double(before.angpos[0].y);
        INFO("turned " << turned << " rad at omega_y = " << double(after.omega[0].y) << " rad/s");
        CHECK(rel_err(turned, double(after.omega[0].y) * double(sim.dt()) * double(steps / 2)) < tol);
    }
}

TEMPLATE_TEST_CASE("accumulated displacement: the time integral of the velocity, across periodic boundaries",
                   "[collision][displacement]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    // A free sphere falling under gravity while it moves at 0.5 m/s along a periodic x axis
    // 0.2 m long, and a prescribed one moving at (-0.1, 0.05, 0) m/s with no gravity on it,
    // for 0.6 s: the accumulated displacement is sum v dt with the velocity each step moved the
    // particle by, x unwrapped (0.3 m: one and a half box lengths while the position wraps),
    // z the fall. References: x and the prescribed one exactly v t, z the position's own change
    // (no wrap on z) and -g t (t + dt) / 2 for semi-implicit Euler (v_k = -g k dt), the Verlet
    // drift's -g t^2 / 2. Tolerance: the rounding of sums of 12000 terms, 12000 x 6e-8 = 7e-4
    // relative where they are float: the displacement against the position's change in float
    // positions (float), against the references in float velocities (float, mixed); 1e-9 in
    // double.
    const bool float_sums = std::is_same_v<sphere::coord_t<P>, float>;
    const double tol = float_sums ? 7e-4 : 1e-9, tol_ref = sphere_test::single_fields<P> ? 7e-4 : 1e-9;
    const double g = 9.81, dt = 5e-5;
    const std::size_t steps = 12000;
    sphere::settings<Real> s = box_settings<Real>();
    s.box.axis[0] = sphere::boundary::periodic;
    s.box.lo.z = Real(-3);
    s.gravity = {0, 0, Real(-g)};
    s.dt = Real(dt);
    std::vector<sphere::particle<Real>> ps{ball<Real>({0, 0, 0}, {Real(0.5), 0, 0}),
                                           ball<Real>({Real(0.05), Real(0.05), Real(0.05)}, {Real(-0.1), Real(0.05), 0})};
    ps[1].kind = sphere::motion::prescribed;
    auto check = [&](auto sim, double fall) {
        const double z0 = double(sim.snapshot().x[0].z);
        sim.run(steps);
        const auto snap = sim.snapshot();
        const double t = double(steps) * double(sim.dt());
        INFO("x " << double(snap.displacement[0].x) << " m (position " << double(snap.x[0].x) << " m), z "
                  << double(snap.displacement[0].z) << " m, fall " << fall << " m");
        CHECK(rel_err(snap.displacement[0].x, 0.5 * t) < tol_ref);
        CHECK(double(snap.x[0].x) < 0.1); // it wrapped
        CHECK(snap.displacement[0].y == 0);
        CHECK(rel_err(snap.displacement[0].z, double(snap.x[0].z) - z0) < tol);
        CHECK(rel_err(snap.displacement[0].z, fall) < tol_ref);
        CHECK(rel_err(snap.displacement[1].x, -0.1 * t) < tol_ref);
        CHECK(rel_err(snap.displacement[1].y, 0.05 * t) < tol_ref);
        CHECK(snap.displacement[1].z == 0);
        // Off, the field reads zero and the motion is the same.
        sphere::settings<Real> off = s;
        off.accumulated_displacement = false;
        decltype(sim) lean(off, ps);
        lean.run(steps);
        const auto q = lean.snapshot();
        CHECK(q.x[0].x == snap.x[0].x);
        CHECK(q.x[0].z == snap.x[0].z);
        CHECK(q.displacement[0].x == 0);
        CHECK(q.displacement[0].z == 0);
    };
    const double t = double(steps) * dt;
    SECTION("semi-implicit Euler") { check(test_sim<P>(s, ps), -g * t * (t + dt) / 2); }
    SECTION("velocity Verlet") { check(test_sim<P, sphere::integrate::velocity_verlet>(s, ps), -g * t * t / 2); }
}

// ---------------------------------------------------------------------------------------------
// Mass-scaled damping (damping_convention::mass_scaled): c = gamma m* per contact.
// ---------------------------------------------------------------------------------------------
TEMPLATE_TEST_CASE("mass-scaled damping: each pair gets c = gamma m*, so its restitution follows its masses",
                   "[collision][damping]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    // Head-on pairs of radii (r_a, r_b) at 1 m/s with tension allowed, at dt/10: with
    // gamma = 1883.0 1/s every pair gets c_n = gamma m*, damping ratio zeta = gamma sqrt(m*) /
    // (2 sqrt(k_n)), restitution exp(-pi zeta / sqrt(1 - zeta^2)): 0.5 for the set-P pair (m* = m/2),
    // lower for heavier pairs. Tolerance 0.5% (VALIDATION D2 at dt/10).
    const double gamma = 2 * gamma_pair / mass_p; // 1/s: c_n = gamma_pair for the set-P pair
    struct pair_case {
        double r_a, r_b;
    };
    for (const pair_case pc : {pair_case{0.01, 0.01}, pair_case{0.02, 0.01}, pair_case{0.015, 0.015}}) {
        const double m_a = sphere::sphere_mass(pc.r_a, 2500.0), m_b = sphere::sphere_mass(pc.r_b, 2500.0);
        const double m_eff = m_a * m_b / (m_a + m_b);
        const double zeta = gamma * m_eff / (2 * std::sqrt(m_eff * k_n_p));
        const double e_ref = sphere::restitution_from_damping_ratio(zeta, true);
        sphere::settings<Real> s = box_settings<Real>();
        s.contact.gamma_n = Real(gamma);
        s.contact.damping = sphere::damping_convention::mass_scaled;
        s.contact.tension = true;
        s.dt = Real(dt_p / 10);
        const Real gap = Real(1e-4);
        test_sim<P> sim(s, {ball<Real>({-(Real(pc.r_a) + gap / 2), 0, 0}, {1, 0, 0}, Real(pc.r_a)),
                               ball<Real>({Real(pc.r_b) + gap / 2, 0, 0}, {0, 0, 0}, Real(pc.r_b))});
        const contact_record c =
            watch_collision(sim, [](const auto& snap) { return pair_state(snap); }, k_n_p, gamma * m_eff, true, 200000);
        REQUIRE(c.separated);
        const auto snap = sim.snapshot();
        const double e = double(snap.v[1].x) - double(snap.v[0].x);
        INFO("radii " << pc.r_a << ", " << pc.r_b << " m: m* = " << m_eff << " kg, e = " << e << " (" << e_ref << ")");
        CHECK(rel_err(e, e_ref) < 5e-3);
    }
    // The validation names the units of the convention.
    sphere::settings<Real> s = box_settings<Real>();
    s.contact.damping = sphere::damping_convention::mass_scaled;
    s.contact.gamma_n = Real(-1);
    REQUIRE_THROWS_WITH((test_sim<P>(s, {ball<Real>({0, 0, 0})})),
                        Catch::Contains("settings.contact.gamma_n = -1 1/s (mass-scaled): must be non-negative"));
}

// ---------------------------------------------------------------------------------------------
// Damping ratios (damping_convention::damping_ratio): c = 2 zeta sqrt(m* k_n) per contact.
// ---------------------------------------------------------------------------------------------
TEMPLATE_TEST_CASE("damping ratios: every pair has the restitution its ratio gives, whatever its masses",
                   "[collision][damping]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    // Head-on pairs of unlike radii and densities at 1 m/s, at dt/10: with gamma_n = damping_ratio_from_restitution(0.5, tension) every contact rebounds
    // with e = 0.5, with and without tension (the linear law's restitution depends on its
    // damping ratio alone: docs/physics.md, "Restitution"). Tolerance 0.5% (VALIDATION D2 at
    // dt/10; the stiffest pair sets dt).
    struct pair_case {
        double r_a, r_b, rho_a, rho_b;
    };
    for (bool tension : {true, false}) {
        CAPTURE(tension);
        const double zeta = sphere::damping_ratio_from_restitution(0.5, tension);
        for (const pair_case pc : {pair_case{0.01, 0.01, 2500, 2500}, pair_case{0.02, 0.01, 2500, 2500},
                                   pair_case{0.015, 0.008, 1000, 7800}}) {
            const double m_a = sphere::sphere_mass(pc.r_a, pc.rho_a), m_b = sphere::sphere_mass(pc.r_b, pc.rho_b);
            const double m_eff = m_a * m_b / (m_a + m_b);
            sphere::settings<Real> s = box_settings<Real>();
            s.contact.gamma_n = Real(zeta);
            s.contact.damping = sphere::damping_convention::damping_ratio;
            s.contact.tension = tension;
            s.dt = Real(dt_p / 10);
            const Real gap = Real(1e-4);
            auto a = ball<Real>({-(Real(pc.r_a) + gap / 2), 0, 0}, {1, 0, 0}, Real(pc.r_a));
            auto b = ball<Real>({Real(pc.r_b) + gap / 2, 0, 0}, {0, 0, 0}, Real(pc.r_b));
            a.density = Real(pc.rho_a);
            b.density = Real(pc.rho_b);
            test_sim<P> sim(s, {a, b});
            const double c_n = 2 * zeta * std::sqrt(m_eff * k_n_p);
            const contact_record c =
                watch_collision(sim, [](const auto& snap) { return pair_state(snap); }, k_n_p, c_n, tension, 400000);
            REQUIRE(c.separated);
            const auto snap = sim.snapshot();
            const double e = double(snap.v[1].x) - double(snap.v[0].x);
            INFO("radii " << pc.r_a << ", " << pc.r_b << " m, m* = " << m_eff << " kg: e = " << e);
            CHECK(rel_err(e, 0.5) < 5e-3);
        }
    }
    // The validation names the convention's unit.
    sphere::settings<Real> s = box_settings<Real>();
    s.contact.damping = sphere::damping_convention::damping_ratio;
    s.contact.gamma_t = Real(-1);
    REQUIRE_THROWS_WITH((test_sim<P>(s, {ball<Real>({0, 0, 0})})),
                        Catch::Contains("settings.contact.gamma_t = -1 (ratio to critical damping): must be non-negative"));
}

TEMPLATE_TEST_CASE("particles at rest: the pair sums walk the near partners alone and never open the far rows",
                   "[collision][near]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = user_real<P>;
    // Three balls of set P at rest in a row, no gravity, skin r / 5: a and b a twentieth of
    // the skin apart (near partners: within an eighth of the skin; apart), c half the skin
    // beyond b (listed, in b's or c's far row). Nothing moves, so no particle ever moves a
    // sixteenth of the skin: the pair sums walk the near rows alone at every step (on the
    // gather schedule from the second on: its first walks every entry to store the far pair's
    // zero result) and the far rows never get histories (docs/architecture.md, *Near
    // partners*). In sphere_cuda_tests this checks that the CUDA step hands `near_only` over.
    const Real r = set_p<Real>::radius, skin = r / 5;
    sphere::settings<Real> s = box_settings<Real>();
    s.skin = skin;
    s.pair_summation = GENERATE(sphere::pair_summation::automatic, sphere::pair_summation::gather);
    const Real xb = 2 * r + skin / 20, xc = xb + 2 * r + skin / 2;
    test_sim<P> sim(s, {ball<Real>({0, 0, 0}), ball<Real>({xb, 0, 0}), ball<Real>({xc, 0, 0})});
    const std::size_t steps = 50;
    sim.run(steps);
    INFO("pair summation " << unsigned(s.pair_summation) << ": " << sim.near_walks() << " of " << steps
                           << " steps on the near partners alone");
    CHECK(sim.contact_entries() == 2); // {a, b} and {b, c}
    CHECK(sim.rebuilds() == 1);
    CHECK(sim.near_walks() >= steps - 1);
    CHECK(sim.far_openings() == 0);
    const auto snap = sim.snapshot();
    for (std::size_t i = 0; i < 3; ++i) CHECK(snap.v[i] == vec3<Real>{0, 0, 0}); // apart: no force
}

} // namespace test_collisions
