// Determinism of the host backend: the same input gives bit-identical particle states, run
// after run, for 1 or 2 OpenMP threads and whatever order the particles are stored in, with
// either pair summation (each particle sums its contacts in an order fixed by the contact
// lists' ranks and layers, contact/interact.cuh; reductions sum fixed chunks in rank order,
// exec/algorithms.cuh). Every field of snapshot() is compared bytewise (memcmp), and so are
// the contact lists with their histories, the energy budget and the momentum. The two pair
// summations agree with each other to round-off.
#include <catch2/catch.hpp>

#include "support.hpp"

#include <omp.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_determinism {

namespace {

using sphere::vec3;

/// Restores the OpenMP thread count when a test leaves (also on failure).
struct thread_count_guard {
    int saved = omp_get_max_threads();
    ~thread_count_guard() { omp_set_num_threads(saved); }
};

/// Number of threads an OpenMP parallel region really gets after omp_set_num_threads(n).
int threads_in_parallel_region()
{
    int seen = 0;
#pragma omp parallel
    {
#pragma omp single
        seen = omp_get_num_threads();
    }
    return seen;
}

/// per_axis^3 polydisperse particles (radii uniform in [0.5, 1.5] x 1 cm) on a jittered lattice
/// with gaps of 0.02-2 cm, random velocities N(0, 1 m/s) and spins N(0, 100 rad/s), in a
/// closed box: they collide with each other and the walls within the first few hundred
/// steps. Friction (mu_s 0.5, mu_d 0.4), damping (gamma_n, gamma_t) on pairs and walls,
/// gravity. One particle in 50 is prescribed (keeps its velocity) and one in 50 is fixed.
template <class Real>
std::pair<sphere::settings<Real>, std::vector<sphere::particle<Real>>> assembly(int per_axis, Real skin,
                                                                               std::uint32_t seed)
{
    const double r0 = 0.01, spacing = 3.04 * r0;
    const double half = per_axis * spacing / 2;
    sphere::settings<Real> s = sphere_test::frictional_box<Real>(half);
    s.wall.gamma_t = Real(20);
    s.skin = skin;

    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < per_axis; ++k)
        for (int j = 0; j < per_axis; ++j)
            for (int i = 0; i < per_axis; ++i) {
                sphere::particle<Real> p;
                p.radius = Real(r0 * (0.5 + unit(gen)));
                p.density = Real(2500);
                p.position = {Real(-half + (i + 0.5) * spacing + 0.02 * r0 * (unit(gen) - 0.5)),
                              Real(-half + (j + 0.5) * spacing + 0.02 * r0 * (unit(gen) - 0.5)),
                              Real(-half + (k + 0.5) * spacing + 0.02 * r0 * (unit(gen) - 0.5))};
                for (int a = 0; a < 3; ++a) {
                    p.velocity[a] = Real(normal(gen));
                    p.angular_velocity[a] = Real(100 * normal(gen));
                }
                const std::size_t index = ps.size();
                if (index % 50 == 7) p.kind = sphere::motion::prescribed;
                if (index % 50 == 23) p.kind = sphere::motion::fixed;
                ps.push_back(p);
            }
    return {s, ps};
}

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b)
{
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/// Everything a simulation reports, recorded right after a run (so that the diagnostics,
/// which are reductions, run under the same thread count as the run).
template <class Real>
struct record {
    sphere::particle_snapshot<Real> snap;
    sphere::contact_table<Real> contacts;
    sphere::energy_budget<Real> energy;
    vec3<Real> momentum;
    std::size_t rebuilds, steps;
    double time;
};

template <class Sim>
record<typename Sim::real_type> record_of(const Sim& sim)
{
    return {sim.snapshot(),
            sim.contacts(),
            sim.energy(),
            sim.momentum(),
            sim.rebuilds(),
            sim.steps(),
            sim.time()};
}

/// Runs `steps` steps of a set-up on `threads` OpenMP threads and records the result (with
/// the diagnostics evaluated on the same thread count).
template <class P, class Real = sphere_test::user_real<P>>
record<Real> run_on_threads(const std::pair<sphere::settings<Real>, std::vector<sphere::particle<Real>>>& setup,
                            std::size_t steps, int threads, sphere::pair_summation how = sphere::pair_summation::automatic)
{
    omp_set_num_threads(threads);
    REQUIRE(threads_in_parallel_region() == threads);
    sphere::settings<Real> s = setup.first;
    s.pair_summation = how;
    sphere::simulation<P> sim(s, setup.second);
    sim.run(steps);
    return record_of(sim);
}

/// Names of the fields of two records that differ in any bit (empty: identical).
template <class Real>
std::vector<std::string> differences(const record<Real>& a, const record<Real>& b)
{
    std::vector<std::string> out;
    const auto &sa = a.snap, &sb = b.snap;
    if (!same_bytes(sa.x, sb.x)) out.push_back("x");
    if (!same_bytes(sa.v, sb.v)) out.push_back("v");
    if (!same_bytes(sa.omega, sb.omega)) out.push_back("omega");
    if (!same_bytes(sa.v_sync, sb.v_sync)) out.push_back("v_sync");
    if (!same_bytes(sa.omega_sync, sb.omega_sync)) out.push_back("omega_sync");
    if (!same_bytes(sa.angpos, sb.angpos)) out.push_back("angpos");
    if (!same_bytes(sa.displacement, sb.displacement)) out.push_back("displacement");
    if (!same_bytes(sa.force, sb.force)) out.push_back("force");
    if (!same_bytes(sa.torque, sb.torque)) out.push_back("torque");
    if (!same_bytes(sa.mass, sb.mass)) out.push_back("mass");
    if (!same_bytes(sa.pressure, sb.pressure)) out.push_back("pressure");
    if (!same_bytes(sa.e_visc, sb.e_visc)) out.push_back("e_visc");
    if (!same_bytes(sa.e_fric, sb.e_fric)) out.push_back("e_fric");
    if (!same_bytes(sa.p_visc, sb.p_visc)) out.push_back("p_visc");
    if (!same_bytes(sa.p_fric, sb.p_fric)) out.push_back("p_fric");
    if (!same_bytes(sa.kind, sb.kind)) out.push_back("kind");
    if (!same_bytes(sa.material, sb.material)) out.push_back("material");
    if (!same_bytes(a.contacts.offset, b.contacts.offset)) out.push_back("contact offsets");
    if (!same_bytes(a.contacts.partner, b.contacts.partner)) out.push_back("contact partners");
    if (!same_bytes(a.contacts.history, b.contacts.history)) out.push_back("contact histories");
    if (!same_bytes(a.contacts.force, b.contacts.force)) out.push_back("contact forces");
    if (std::memcmp(&a.energy, &b.energy, sizeof a.energy) != 0) out.push_back("energy budget");
    if (std::memcmp(&a.momentum, &b.momentum, sizeof a.momentum) != 0) out.push_back("momentum");
    if (a.rebuilds != b.rebuilds) out.push_back("rebuilds");
    if (a.steps != b.steps || std::memcmp(&a.time, &b.time, sizeof a.time) != 0) out.push_back("steps or time");
    return out;
}

/// The run did something worth comparing: contacts formed, friction slid, walls were hit.
template <class Real>
void require_eventful(const record<Real>& r)
{
    const auto& e = r.energy;
    const auto& snap = r.snap;
    std::size_t touching = 0;
    for (std::size_t i = 0; i < snap.size(); ++i)
        if (snap.pressure[i] > 0) ++touching;
    INFO("dissipated: viscous " << e.dissipated_visc << " J, frictional " << e.dissipated_fric << " J; "
                                << touching << " of " << snap.size() << " particles in contact; "
                                << r.rebuilds << " rebuilds in " << r.steps << " steps");
    REQUIRE(e.dissipated_visc > 0);
    REQUIRE(e.dissipated_fric > 0);
    REQUIRE(touching >= 10);
}

} // namespace

TEMPLATE_TEST_CASE("two runs of the same input give bit-identical states", "[determinism]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    const std::size_t steps = 300;
    Real skin = 0;
    SECTION("skin 0") { skin = 0; }
    SECTION("skin 0.2 r0") { skin = Real(0.002); }
    const auto setup = assembly<Real>(7, skin, 99); // 343 particles

    sphere::simulation<P> first(setup.first, setup.second);
    first.run(steps / 2);
    const auto halfway = first.snapshot();
    first.run(steps - steps / 2);

    sphere::simulation<P> second(setup.first, setup.second);
    second.run(steps / 2);
    const auto halfway2 = second.snapshot();
    second.run(steps - steps / 2);

    require_eventful(record_of(first));
    if (skin > 0) CHECK(first.rebuilds() < steps); // the skin case really skips rebuilds
    CHECK(same_bytes(halfway.x, halfway2.x));
    CHECK(same_bytes(halfway.v, halfway2.v));
    const std::vector<std::string> diff = differences(record_of(first), record_of(second));
    INFO("fields that differ: " << Catch::Detail::stringify(diff));
    CHECK(diff.empty());
}

TEMPLATE_TEST_CASE("1 and 2 OpenMP threads give bit-identical states", "[determinism][openmp]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    thread_count_guard guard;
    // The host backend runs loops and sorts of fewer than sphere::host_parallel_threshold
    // indices on the calling thread, and splits reductions into chunks of host_chunk: the
    // cases are large enough for every phase to run on both threads.
    REQUIRE(sphere::host_parallel_threshold <= 2744);
    sphere::pair_summation how = sphere::pair_summation::slabs;
    SECTION("pair sums by slabs") { how = sphere::pair_summation::slabs; }
    SECTION("pair sums by gather") { how = sphere::pair_summation::gather; }

    SECTION("2744 particles, 100 steps")
    {
        const std::size_t steps = 100;
        Real skin = 0;
        SECTION("skin 0") { skin = 0; }
        SECTION("skin 0.2 r0") { skin = Real(0.002); }
        const auto setup = assembly<Real>(14, skin, 5);

        const auto with_one = run_on_threads<P>(setup, steps, 1, how);
        const auto with_two = run_on_threads<P>(setup, steps, 2, how);

        require_eventful(with_one);
        if (skin > 0) CHECK(with_one.rebuilds < steps);
        const std::vector<std::string> diff = differences(with_one, with_two);
        INFO("fields that differ: " << Catch::Detail::stringify(diff));
        CHECK(diff.empty());
    }
    SECTION("9261 particles, 30 steps: reductions over many chunks")
    {
        const std::size_t steps = 30;
        const auto setup = assembly<Real>(21, Real(0.002), 6);

        const auto with_one = run_on_threads<P>(setup, steps, 1, how);
        const auto with_two = run_on_threads<P>(setup, steps, 2, how);

        const std::vector<std::string> diff = differences(with_one, with_two);
        INFO("fields that differ: " << Catch::Detail::stringify(diff));
        CHECK(diff.empty());
        CHECK(with_one.energy.dissipated_visc > 0);
    }
}

TEMPLATE_TEST_CASE("switching between 1 and 2 threads during a run (the thread governor) keeps the bits",
                   "[determinism][openmp]", double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    thread_count_guard guard;
    // sphere::thread_governor changes host_team_limit() between steps; a run whose limit
    // alternates 1, 2, 2, 1, ... must end where a run on one thread does.
    const std::size_t steps = 60;
    const auto setup = assembly<Real>(14, Real(0.002), 7);
    const auto with_one = run_on_threads<P>(setup, steps, 1);

    omp_set_num_threads(2);
    REQUIRE(threads_in_parallel_region() == 2);
    sphere::simulation<P> sim(setup.first, setup.second);
    for (std::size_t k = 0; k < steps; ++k) {
        sphere::host_team_limit() = (k / 2) % 2 == 0 ? 1 : 0;
        REQUIRE(sphere::host_team() == ((k / 2) % 2 == 0 ? 1 : 2));
        sim.step();
    }
    sphere::host_team_limit() = 0;
    require_eventful(with_one);
    const std::vector<std::string> diff = differences(with_one, record_of(sim));
    INFO("fields that differ: " << Catch::Detail::stringify(diff));
    CHECK(diff.empty());
}

TEMPLATE_TEST_CASE("the storage order does not change the physics: reordering on and off agree bit for bit",
                   "[determinism][reorder]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    // The particles are stored in the grid's cell order (settings.reorder, the default) or in
    // the user's order. Every sum follows the ranks of the contact lists either way (pair
    // sums, wall loads, energy, momentum), so everything is the same bits, also with a
    // stress-controlled top wall that the particles' load moves. The snapshots and contact
    // tables are in user order.
    auto setup = assembly<Real>(9, Real(0.002), 17); // 729 particles, skin 0.2 r0
    setup.first.walls[5].mode = sphere::wall_mode::stress;
    setup.first.walls[5].stress = Real(2000);
    setup.first.walls[5].mass = Real(1);
    sphere::pair_summation how = sphere::pair_summation::slabs;
    SECTION("pair sums by slabs") { how = sphere::pair_summation::slabs; }
    SECTION("pair sums by gather") { how = sphere::pair_summation::gather; }
    setup.first.pair_summation = how;
    auto compare = [&](auto integrator) {
        using Integrator = decltype(integrator);
        using sim_type = sphere::simulation<P, sphere::host, sphere::contact::linear<>, Integrator>;
        sphere::settings<Real> kept = setup.first;
        kept.reorder = false;
        sim_type sorted(setup.first, setup.second), unsorted(kept, setup.second);
        sorted.run(250);
        unsorted.run(250);
        // The storage orders really differ.
        const std::vector<unsigned> storage = sorted.state().storage, identity = unsorted.state().storage;
        std::size_t moved = 0;
        for (std::size_t k = 0; k < storage.size(); ++k) moved += storage[k] != k;
        CHECK(moved > storage.size() / 2);
        for (std::size_t k = 0; k < identity.size(); ++k) REQUIRE(identity[k] == k);
        const auto a = record_of(sorted), b = record_of(unsorted);
        require_eventful(a);
        CHECK(sorted.rebuilds() > 2);
        // positions() copies what snapshot().x holds, in user order, whatever the storage order.
        for (const auto& [sim, snap_x] : {std::pair{&sorted, &a.snap.x}, std::pair{&unsorted, &b.snap.x}}) {
            const auto x = sim->positions();
            REQUIRE(x.size() == snap_x->size());
            CHECK(std::memcmp(x.data(), snap_x->data(), x.size() * sizeof(x[0])) == 0);
        }
        CHECK(sorted.walls().face[5].position != setup.first.box.hi.z); // the top wall moved
        const std::vector<std::string> diff = differences(a, b);
        INFO("fields that differ: " << Catch::Detail::stringify(diff));
        CHECK(diff.empty());
        CHECK(sorted.walls().face[5].position == unsorted.walls().face[5].position);
    };
    SECTION("semi-implicit Euler") { compare(sphere::integrate::semi_implicit_euler{}); }
    SECTION("velocity Verlet") { compare(sphere::integrate::velocity_verlet{}); }
}

/// The record of a simulation whose last particle is left out: its snapshot's fields and the
/// contact offsets truncated to the others (the contact tables' entries stay: the left-out
/// particle must have none, or they differ).
template <class Real>
record<Real> without_last(record<Real> r)
{
    auto& s = r.snap;
    const std::size_t n = s.size() - 1;
    s.x.resize(n);
    for (auto* f : {&s.v, &s.omega, &s.v_sync, &s.omega_sync, &s.angpos, &s.force, &s.torque, &s.displacement})
        if (!f->empty()) f->resize(n);
    for (auto* f : {&s.mass, &s.pressure, &s.e_visc, &s.e_fric, &s.p_visc, &s.p_fric})
        if (!f->empty()) f->resize(n);
    s.kind.resize(n);
    s.material.resize(n);
    r.contacts.offset.resize(n + 1);
    return r;
}

TEMPLATE_TEST_CASE("free particles move by the same bits in a simulation of free particles only and beside a fixed one",
                   "[determinism]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    // On the host's slab schedule, a simulation whose particles are all free (and without
    // external forces) integrates them without loading their motion kinds
    // (integrate/integrate_particles.cuh, kind_of). The same particles beside one fixed
    // particle, out of everyone's reach, take the general path: their motion must be the same
    // bits.
    auto setup = assembly<Real>(7, Real(0.002), 5); // 343 particles
    const double r0 = 0.01;
    setup.first.box.hi.z += Real(8 * r0); // room above the assembly for the fixed particle
    for (auto& p : setup.second) p.kind = sphere::motion::free;
    auto beside = setup.second;
    sphere::particle<Real> fixed;
    fixed.radius = Real(r0);
    fixed.density = Real(2500);
    fixed.position = {Real(0), Real(0), Real(double(setup.first.box.hi.z) - 2 * r0)};
    fixed.kind = sphere::motion::fixed;
    beside.push_back(fixed);
    auto compare = [&](auto integrator) {
        using sim_type = sphere::simulation<P, sphere::host, sphere::contact::linear<>, decltype(integrator)>;
        sim_type alone(setup.first, setup.second), with_fixed(setup.first, beside);
        alone.run(200);
        with_fixed.run(200);
        const auto a = record_of(alone), b = record_of(with_fixed);
        require_eventful(a);
        const std::size_t last = b.snap.size() - 1;
        CHECK(b.snap.position(last) == fixed.position); // it stayed
        CHECK(b.contacts.begin(last) == b.contacts.end(last)); // out of everyone's reach
        std::vector<std::string> diff = differences(a, without_last(b));
        // Sums over all particles (energy, momentum) also hold the fixed one's share.
        diff.erase(std::remove_if(diff.begin(), diff.end(),
                                  [](const std::string& f) { return f == "energy budget" || f == "momentum"; }),
                   diff.end());
        INFO("fields that differ: " << Catch::Detail::stringify(diff));
        CHECK(diff.empty());
    };
    SECTION("semi-implicit Euler") { compare(sphere::integrate::semi_implicit_euler{}); }
    SECTION("velocity Verlet") { compare(sphere::integrate::velocity_verlet{}); }
}

TEMPLATE_TEST_CASE("switching off what a run does not read (audit, contact forces, angular positions, displacements) "
                   "keeps the motion's bits",
                   "[determinism][memory]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    // settings.energy_audit, contact_forces and angular_position only decide what is booked
    // and allocated besides the motion: with all three off, positions, velocities, forces,
    // contact lists and histories are the same bits, and the fields that are not kept read
    // zero (or, for the contact forces, are absent).
    const auto setup = assembly<Real>(9, Real(0.002), 23); // 729 particles, skin 0.2 r0
    auto compare = [&](auto integrator) {
        using Integrator = decltype(integrator);
        using sim_type = sphere::simulation<P, sphere::host, sphere::contact::linear<>, Integrator>;
        sphere::settings<Real> lean = setup.first;
        lean.energy_audit = lean.contact_forces = lean.angular_position = lean.accumulated_displacement = false;
        sim_type full(setup.first, setup.second), trimmed(lean, setup.second);
        full.run(250);
        trimmed.run(250);
        const auto a = record_of(full), b = record_of(trimmed);
        require_eventful(a);
        CHECK(full.rebuilds() > 2);
        std::vector<std::string> diff = differences(a, b);
        const std::vector<std::string> not_kept{"angpos",   "displacement", "pressure", "e_visc", "e_fric",
                                                "p_visc",   "p_fric",   "contact forces", "energy budget"};
        for (const std::string& f : not_kept) diff.erase(std::remove(diff.begin(), diff.end(), f), diff.end());
        INFO("fields that differ: " << Catch::Detail::stringify(diff));
        CHECK(diff.empty());
        // What is not kept reads zero; the full run really has it.
        auto zero = [](const std::vector<Real>& values) {
            return std::all_of(values.begin(), values.end(), [](Real v) { return v == Real(0); });
        };
        double turned = 0;
        for (const auto& w : a.snap.angpos) turned = std::max(turned, double(sphere::norm(w)));
        CHECK(turned > 0.1); // rad
        for (const auto& w : b.snap.angpos) REQUIRE(sphere::norm(w) == Real(0));
        double moved = 0;
        for (const auto& d : a.snap.displacement) moved = std::max(moved, double(sphere::norm(d)));
        CHECK(moved > 1e-3); // m
        for (const auto& d : b.snap.displacement) REQUIRE(sphere::norm(d) == Real(0));
        CHECK(zero(b.snap.e_visc));
        CHECK(zero(b.snap.pressure));
        CHECK(!zero(a.snap.e_visc));
        CHECK(b.contacts.force.empty());
        CHECK(a.contacts.force.size() == a.contacts.partner.size());
    };
    SECTION("semi-implicit Euler") { compare(sphere::integrate::semi_implicit_euler{}); }
    SECTION("velocity Verlet") { compare(sphere::integrate::velocity_verlet{}); }
}

TEMPLATE_TEST_CASE("a state continues bit for bit in a simulation that stores its particles in another order",
                   "[determinism][reorder][restart]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    // restore() puts the particles into the ranks of the last rebuild (or the user's order
    // without reordering), whatever order the state was saved in: a state of a reordering run
    // continues in a run that keeps the user's order with the same bits, and back.
    const auto setup = assembly<Real>(8, Real(0.002), 41);
    sphere::settings<Real> kept = setup.first;
    kept.reorder = false;
    const bool reordered_first = GENERATE(true, false);
    const sphere::settings<Real>& first_settings = reordered_first ? setup.first : kept;
    const sphere::settings<Real>& second_settings = reordered_first ? kept : setup.first;
    sphere::simulation<P> original(first_settings, setup.second);
    original.run(120);
    sphere::simulation<P> resumed(second_settings, setup.second);
    resumed.restore(original.state());
    original.run(120);
    resumed.run(120);
    const auto a = record_of(original), b = record_of(resumed);
    require_eventful(a);
    const std::vector<std::string> diff = differences(a, b);
    INFO("first run reorders: " << reordered_first << "; fields that differ: " << Catch::Detail::stringify(diff));
    CHECK(diff.empty());
}

namespace {
/// A compressed crystal: 10 x 10 x 10 spheres on a jittered cubic lattice of spacing 2 r0,
/// radii uniform in [1.0, 1.1] r0, so that every sphere overlaps most of its six lattice
/// neighbours from the start (overlaps up to 0.2 r0), in a box periodic in x and y with walls
/// at the bottom and top, at rest, with friction and damping.
template <class Real>
std::pair<sphere::settings<Real>, std::vector<sphere::particle<Real>>> compressed_crystal()
{
    const double r0 = 0.01, side = 20 * r0;
    sphere::settings<Real> s = sphere_test::frictional_box<Real>(side / 2);
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.skin = Real(0.1 * r0);
    std::mt19937 gen(7);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 10; ++k)
        for (int j = 0; j < 10; ++j)
            for (int i = 0; i < 10; ++i) {
                sphere::particle<Real> p;
                p.radius = Real(r0 * (1.0 + 0.1 * unit(gen)));
                p.density = Real(2500);
                const double c[3] = {(i + 0.5) * 2 * r0, (j + 0.5) * 2 * r0, (k + 0.5) * 2 * r0};
                for (int a = 0; a < 3; ++a) p.position[a] = Real(-side / 2 + c[a] + 0.05 * r0 * (unit(gen) - 0.5));
                ps.push_back(p);
            }
    return {s, ps};
}
} // namespace

TEMPLATE_TEST_CASE("pair sums by slabs and by gather agree to round-off", "[determinism][summation]", float, double,
                   sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    // Both summations evaluate every listed pair once with the same contact law; they differ
    // in the order in which a particle's contributions are added. In a compressed crystal
    // every particle sums 6-8 contacts: the forces agree to a few roundings of the largest
    // force, and after 100 steps the velocities still agree far below the motion's scale.
    const auto setup = compressed_crystal<Real>();
    auto run = [&](sphere::pair_summation how, std::size_t steps) {
        sphere::settings<Real> s = setup.first;
        s.pair_summation = how;
        sphere::simulation<P> sim(s, setup.second);
        sim.run(steps);
        return record_of(sim);
    };
    const bool single = sphere_test::single_fields<P>;
    auto largest = [](const std::vector<vec3<Real>>& a) {
        double m = 0;
        for (const vec3<Real>& v : a) m = std::max(m, double(sphere::norm(v)));
        return m;
    };
    auto max_diff = [](const std::vector<vec3<Real>>& a, const std::vector<vec3<Real>>& b) {
        double m = 0;
        for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, double(sphere::norm(a[i] - b[i])));
        return m;
    };
    SECTION("one step")
    {
        const auto a = run(sphere::pair_summation::slabs, 1), b = run(sphere::pair_summation::gather, 1);
        std::size_t summed = 0; // particles with three or more contacts: their sums can round differently
        for (std::size_t i = 0; i < a.contacts.particles(); ++i) summed += a.contacts.partners_of(i).size() >= 3;
        const double f_scale = largest(a.snap.force), t_scale = largest(a.snap.torque);
        const double df = max_diff(a.snap.force, b.snap.force), dt = max_diff(a.snap.torque, b.snap.torque);
        INFO(summed << " particles with 3 or more partners; largest force " << f_scale << " N, difference " << df
                    << " N; largest torque " << t_scale << " N m, difference " << dt << " N m");
        REQUIRE(summed > 500);
        CHECK(df > 0); // the orders really differ
        const double tol = single ? 1e-5 : 1e-13;
        CHECK(df <= tol * f_scale);
        CHECK(dt <= tol * t_scale);
        CHECK(same_bytes(a.contacts.partner, b.contacts.partner)); // the same lists
    }
    SECTION("100 steps")
    {
        const auto a = run(sphere::pair_summation::slabs, 100), b = run(sphere::pair_summation::gather, 100);
        double dx = 0;
        for (std::size_t i = 0; i < a.snap.size(); ++i)
            dx = std::max(dx, double(sphere::norm(a.snap.position(i) - b.snap.position(i))));
        const double v_scale = largest(a.snap.v), dv = max_diff(a.snap.v, b.snap.v);
        INFO("largest position difference " << dx << " m; largest velocity " << v_scale << " m/s, difference " << dv
                                            << " m/s; energy " << a.energy.total() << " and " << b.energy.total() << " J");
        REQUIRE(v_scale > 0.01);
        const double tol = single ? 1e-3 : 1e-9;
        CHECK(dx <= tol * 0.01); // of the radius
        CHECK(dv <= tol * v_scale);
        CHECK(std::abs(double(a.energy.total() - b.energy.total())) <= tol * double(a.energy.elastic + a.energy.kinetic));
    }
}

TEMPLATE_TEST_CASE("owners away from the periodic faces skip the nearest image: every contact's force is the gather "
                   "schedule's, bit for bit, also across the faces",
                   "[determinism][summation]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    // The slab schedule separates an owner that lies farther than (r_i + r_max + range) 17/16
    // from the faces of the periodic axes by x_i - x_j alone (pair_contact::images_inside); the
    // gather schedule always takes the nearest image. Each contact's recorded force (at
    // construction: the same positions and velocities for both) depends on its separation's
    // bits only, not on the order of any sum, so the two must agree to the bit. The compressed
    // crystal's columns lie 1, 3, ..., 19 r0 from the faces of x and y, and the margin is about
    // 2.3 r0: the outer columns' owners (36%) take the nearest image, the others do not, and
    // the outer columns touch across the faces.
    auto setup = compressed_crystal<Real>();
    setup.first.contact_forces = true;
    std::mt19937 gen(11);
    std::normal_distribution<double> normal(0.0, 1.0);
    for (sphere::particle<Real>& p : setup.second)
        for (int a = 0; a < 3; ++a) {
            p.velocity[a] = Real(0.01 * normal(gen));
            p.angular_velocity[a] = Real(normal(gen));
        }
    auto contacts = [&](sphere::pair_summation how) {
        sphere::settings<Real> s = setup.first;
        s.pair_summation = how;
        // velocity Verlet evaluates the forces of the start at construction
        return sphere::simulation<P, sphere_test::policy, sphere::contact::linear<>, sphere::integrate::velocity_verlet>(
                   s, setup.second)
            .contacts();
    };
    const auto a = contacts(sphere::pair_summation::slabs), b = contacts(sphere::pair_summation::gather);

    const double r0 = 0.01, side = 20 * r0, margin = 2.2 * r0 * 17 / 16;
    std::size_t near_face = 0, across = 0, acting = 0;
    for (std::size_t i = 0; i < setup.second.size(); ++i) {
        const auto& xi = setup.second[i].position;
        bool near = false;
        for (int ax = 0; ax < 2; ++ax) near = near || double(xi[ax]) + side / 2 < margin || side / 2 - double(xi[ax]) < margin;
        near_face += near;
        for (std::size_t e = b.begin(i); e < b.end(i); ++e) { // the reference's pairs
            if (b.partner[e] >= sphere::wall_partner_base) continue;
            const auto& xj = setup.second[b.partner[e]].position;
            const bool touches = b.force[e].w != Real(0);
            bool crosses = false;
            for (int ax = 0; ax < 2; ++ax) crosses = crosses || std::abs(double(xi[ax] - xj[ax])) > side / 2;
            acting += touches;
            across += touches && crosses;
        }
    }
    INFO(near_face << " of " << setup.second.size() << " particles within the margin of a periodic face; " << acting
                   << " entries of touching pairs (each pair from both sides), " << across << " of them across a face");
    REQUIRE(near_face == 360);
    REQUIRE(acting > 2000);
    REQUIRE(across > 100);
    CHECK(same_bytes(a.partner, b.partner));
    CHECK(same_bytes(a.force, b.force));
}

TEMPLATE_TEST_CASE("run-time errors name the user's particle index, not its storage slot", "[determinism][reorder]",
                   float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    const auto setup = assembly<Real>(7, Real(0.002), 23);
    sphere::simulation<P> sim(setup.first, setup.second);
    sim.run(20);
    const std::vector<unsigned> storage = sim.state().storage;
    // A free particle whose slot is not its user index.
    std::size_t user = storage.size(), slot = 0;
    for (std::size_t k = 0; k < storage.size() && user == storage.size(); ++k)
        if (storage[k] != k && setup.second[storage[k]].kind == sphere::motion::free) {
            user = storage[k];
            slot = k;
        }
    REQUIRE(user < storage.size());
    INFO("particle " << user << " is stored in slot " << slot);
    sim.set_velocity(user, {0, 0, Real(1e7)}, {0, 0, 0}); // leaves through the top within a step
    REQUIRE_THROWS_WITH(sim.step(), Catch::Contains("step 21: particle " + std::to_string(user) + " left the world"));
}

TEMPLATE_TEST_CASE("walking only the near partners gives the bits of walking every listed pair",
                   "[determinism][summation][restart]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    // While no particle has moved half the near skin since the last rebuild, the pair sums
    // walk each row's near partners alone (docs/architecture.md, *Near partners*). A restored
    // simulation does not know whether the others are clear of history (nor, on the gather
    // schedule, whether their stored results are zero) and walks every entry at its first
    // step: the original, which walks the near ones alone at that step, must give the same
    // bits, then and after.
    auto setup = assembly<Real>(8, Real(0.002), 43);
    SECTION("pair sums by slabs") { setup.first.pair_summation = sphere::pair_summation::slabs; }
    SECTION("pair sums by gather") { setup.first.pair_summation = sphere::pair_summation::gather; }
    sphere::simulation<P> original(setup.first, setup.second);
    original.run(30);
    sphere::simulation_state<Real> before = original.state();
    std::size_t tries = 0;
    for (; tries < 400; ++tries) {
        before = original.state();
        const std::size_t walks = original.near_walks(), rebuilds = original.rebuilds();
        original.step();
        if (original.near_walks() > walks && original.rebuilds() == rebuilds) break; // without a rebuild at it
    }
    INFO(original.steps() << " steps, " << original.near_walks() << " of them on the near partners alone, "
                          << original.rebuilds() << " rebuilds");
    REQUIRE(tries < 400);
    sphere::simulation<P> resumed(setup.first, setup.second);
    resumed.restore(before);
    const std::size_t resumed_walks = resumed.near_walks();
    resumed.step();
    CHECK(resumed.near_walks() == resumed_walks); // every entry walked
    std::vector<std::string> diff = differences(record_of(original), record_of(resumed));
    INFO("after the step: fields that differ: " << Catch::Detail::stringify(diff));
    CHECK(diff.empty());
    original.run(150);
    resumed.run(150);
    const auto a = record_of(original), b = record_of(resumed);
    require_eventful(a);
    CHECK(resumed.near_walks() > resumed_walks);
    diff = differences(a, b);
    INFO("150 steps later: fields that differ: " << Catch::Detail::stringify(diff));
    CHECK(diff.empty());
}

TEMPLATE_TEST_CASE("colliding particles whose partners come near and touch between rebuilds: slabs agree with gather",
                   "[determinism][summation]", float, double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    // Both schedules walk the near partners alone while the others cannot touch, then all of
    // them; the gather schedule also walks all of them at each step that rebuilds, which stores
    // the others' zero results that its sums add up later. Pairs listed apart from the
    // near ones come into contact between rebuilds here: were one missed, or had it kept a
    // history (or, on gather, a stored result) from an earlier contact, the forces would differ
    // by far more than the order of the additions makes them.
    const auto setup = assembly<Real>(10, Real(0.002), 44);
    auto run = [&](sphere::pair_summation how, std::size_t steps) {
        sphere::settings<Real> s = setup.first;
        s.pair_summation = how;
        sphere::simulation<P> sim(s, setup.second);
        sim.run(steps);
        CHECK(sim.far_openings() > 1); // the far rows got histories in more than one list's life
        return std::make_pair(record_of(sim), sim.near_walks());
    };
    const std::size_t steps = 60;
    const auto [a, walks] = run(sphere::pair_summation::slabs, steps);
    const auto [b, gather_walks] = run(sphere::pair_summation::gather, steps);
    require_eventful(a);
    double dx = 0, dv = 0, v_scale = 0;
    for (std::size_t i = 0; i < a.snap.size(); ++i) {
        dx = std::max(dx, double(sphere::norm(a.snap.position(i) - b.snap.position(i))));
        dv = std::max(dv, double(sphere::norm(a.snap.v[i] - b.snap.v[i])));
        v_scale = std::max(v_scale, double(sphere::norm(a.snap.v[i])));
    }
    INFO(walks << " (slabs) and " << gather_walks << " (gather) of " << steps << " steps on the near partners alone, "
               << a.rebuilds << " rebuilds; largest position difference " << dx << " m, velocity difference " << dv
               << " of " << v_scale << " m/s");
    CHECK(walks > 0);
    CHECK(walks < steps);
    CHECK(gather_walks > 0);
    CHECK(gather_walks < walks); // not at the steps that rebuild
    CHECK(a.rebuilds > 2);
    CHECK(same_bytes(a.contacts.partner, b.contacts.partner));
    const double tol = sphere_test::single_fields<P> ? 1e-4 : 1e-10;
    CHECK(dx <= tol * 0.01); // of the radius
    CHECK(dv <= tol * v_scale);
}

} // namespace test_determinism
