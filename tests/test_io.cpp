// Output and restart (include/sphere/io/, docs/io.md), host backend, float and double:
// (a) a checkpoint restart continues bit-identically to the uninterrupted run, and converts
//     between precisions; (b) a writer killed with SIGKILL while writing leaves the previous
//     checkpoint intact; (c) corrupt, truncated, wrong-magic, wrong-version, over-long and
//     inconsistent files raise the documented errors; (d) CSV series read back exactly, and a
//     failed write throws and leaves no file; (e) .vtu and .pvd files hold every particle and
//     field exactly (parsed here independently; tests/vtk_read.py reads them with VTK itself).
#include <catch2/catch.hpp>

#include "checkpoint_bytes.hpp"
#include "temp_folder.hpp"

#include "support.hpp"

#include <sphere/io.cuh>

#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_io {

namespace {

namespace fs = std::filesystem;
using sphere::vec3;
using sphere::vec4;

using sphere_test::read_bytes;
using sphere_test::same_bits;
using sphere_test::temp_folder;
using sphere_test::write_bytes;

/// Every evolving field of two states compared bytewise (wall faces field by field: the
/// struct has padding).
template <class Real>
void require_identical(const sphere::simulation_state<Real>& a, const sphere::simulation_state<Real>& b)
{
    const auto& p = a.particles;
    const auto& q = b.particles;
    CHECK(same_bits(p.x, q.x));
    CHECK(same_bits(p.v, q.v));
    CHECK(same_bits(p.omega, q.omega));
    CHECK(same_bits(p.v_sync, q.v_sync));
    CHECK(same_bits(p.omega_sync, q.omega_sync));
    CHECK(same_bits(p.angpos, q.angpos));
    CHECK(same_bits(p.force, q.force));
    CHECK(same_bits(p.torque, q.torque));
    CHECK(same_bits(p.mass, q.mass));
    CHECK(same_bits(p.pressure, q.pressure));
    CHECK(same_bits(p.e_visc, q.e_visc));
    CHECK(same_bits(p.e_fric, q.e_fric));
    CHECK(same_bits(p.p_visc, q.p_visc));
    CHECK(same_bits(p.p_fric, q.p_fric));
    CHECK(same_bits(p.kind, q.kind));
    CHECK(same_bits(p.displacement, q.displacement));
    CHECK(same_bits(a.contacts.offset, b.contacts.offset));
    CHECK(same_bits(a.contacts.partner, b.contacts.partner));
    CHECK(same_bits(a.contacts.history, b.contacts.history));
    CHECK(same_bits(a.storage, b.storage));
    CHECK(same_bits(a.x_at_build, b.x_at_build));
    CHECK(same_bits(a.drive_work, b.drive_work));
    const auto& c = a.bonds;
    const auto& d = b.bonds;
    CHECK((same_bits(c.i, d.i) && same_bits(c.j, d.j) && same_bits(c.rest, d.rest) && same_bits(c.shear, d.shear)));
    CHECK((same_bits(c.bend, d.bend) && same_bits(c.broken, d.broken) && same_bits(c.released, d.released)));
    CHECK((same_bits(c.dissipated, d.dissipated) && same_bits(c.force, d.force) && same_bits(c.torque_i, d.torque_i) &&
           same_bits(c.torque_j, d.torque_j)));
    for (int f = 0; f < 6; ++f) {
        INFO("wall face " << f);
        CHECK(a.walls.face[f].active == b.walls.face[f].active);
        CHECK(same_bits(a.walls.face[f].position, b.walls.face[f].position));
        CHECK(same_bits(a.walls.face[f].velocity, b.walls.face[f].velocity));
        CHECK(same_bits(a.walls.face[f].force, b.walls.face[f].force));
        CHECK(same_bits(a.walls.face[f].work, b.walls.face[f].work));
    }
    CHECK(a.steps == b.steps);
    CHECK(a.rebuilds == b.rebuilds);
    CHECK(a.needs_rebuild == b.needs_rebuild);
}

/// The frictional, damped, gravitating box of support.hpp (0.1 m wide, 0.09 m high) under a
/// stress-controlled upper wall (1000 Pa +- 300 Pa at 50 Hz, 0.05 kg) with a contact skin of
/// 2 mm: contacts form, slide and break, the lists are rebuilt and the wall moves.
template <class Real>
sphere::settings<Real> eventful_settings()
{
    sphere::settings<Real> s = sphere_test::frictional_box<Real>(0.05);
    s.box.hi.z = Real(0.04);
    s.skin = Real(0.002);
    sphere::wall_control<Real>& top = s.walls[5];
    top.mode = sphere::wall_mode::stress;
    top.stress = Real(1000);
    top.amplitude = Real(300);
    top.frequency = Real(50);
    top.phase = Real(0.5);
    top.mass = Real(0.05);
    return s;
}

/// 4 x 4 x 4 particles on a 22 mm lattice, radii uniform in [8.5, 10.5] mm, random velocities
/// up to 0.3 m/s and spins up to 30 rad/s (seeded); particle 0 fixed, particle 1 prescribed.
template <class Real>
std::vector<sphere::particle<Real>> eventful_particles()
{
    std::mt19937 gen(20240611u);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                sphere::particle<Real> p;
                p.position = {Real(-0.033 + 0.022 * i), Real(-0.033 + 0.022 * j), Real(-0.039 + 0.022 * k)};
                p.radius = Real(0.0095 + 0.001 * unit(gen));
                p.density = Real(2500);
                p.velocity = {Real(0.3 * unit(gen)), Real(0.3 * unit(gen)), Real(0.3 * unit(gen))};
                p.angular_velocity = {Real(30 * unit(gen)), Real(30 * unit(gen)), Real(30 * unit(gen))};
                ps.push_back(p);
            }
    ps[0].kind = sphere::motion::fixed;
    ps[1].kind = sphere::motion::prescribed;
    ps[1].velocity = {Real(0.05), Real(0), Real(0)};
    ps[2].kind = sphere::motion::prescribed_horizontal;
    ps[2].velocity = {Real(-0.05), Real(0.02), Real(0)};
    return ps;
}

template <class P>
using host_sim = sphere::simulation<P>;

/// A state with every field set: eventful_settings/particles after `steps` steps.
template <class P>
host_sim<P> eventful_run(std::size_t steps)
{
    using Real = sphere_test::user_real<P>;
    host_sim<P> sim(eventful_settings<Real>(), eventful_particles<Real>());
    sim.run(steps);
    return sim;
}

/// Returns a copy of `text` with the first occurrence of `from` replaced by `to` (REQUIREs it).
std::string replace_once(std::string text, const std::string& from, const std::string& to)
{
    const std::size_t at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
}

} // namespace

// ---------------------------------------------------------------------------------------------
// (a) restart
// ---------------------------------------------------------------------------------------------

TEMPLATE_TEST_CASE("checkpoint restart continues bit-identically", "[io][checkpoint]", float, double, sphere::mixed)
{
    // A mixed simulation's checkpoint holds its user-facing values (double): its float fields
    // convert exactly, so the restart is bit-identical too.
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    temp_folder dir;
    const std::string path = dir / "run.ck";
    const std::size_t n_before = 600, n_after = 600;

    host_sim<P> original = eventful_run<P>(n_before);
    const sphere::simulation_state<Real> at_checkpoint = original.state();
    sphere::write_checkpoint(path, original);
    const std::size_t rebuilds_before = original.rebuilds();
    original.run(n_after);

    host_sim<P> restarted = sphere::restart<host_sim<P>>(path);
    // The restored simulation starts from exactly the checkpointed state and settings.
    require_identical(restarted.state(), at_checkpoint);
    CHECK(restarted.dt() == original.dt());
    CHECK(restarted.time() == static_cast<double>(n_before) * static_cast<double>(original.dt()));
    restarted.run(n_after);
    require_identical(restarted.state(), original.state());
    CHECK(restarted.time() == original.time());

    // The per-contact forces of the last step agree on every listed entry, walls included.
    CHECK(same_bits(original.contacts().force, restarted.contacts().force));

    // The comparison means something: at the checkpoint particles touched with tangential
    // history, and afterwards the lists were rebuilt, particles slid, and the top wall moved
    // down onto the particles (it started at 0.04 m) and carries a force.
    bool history = false;
    for (const vec4<Real>& h : at_checkpoint.contacts.history) history |= h.x != 0 || h.y != 0 || h.z != 0;
    CHECK(history);
    CHECK(original.rebuilds() > rebuilds_before + 1);
    double e_fric = 0;
    for (const Real e : original.snapshot().e_fric) e_fric += double(e);
    CHECK(e_fric > 0);
    CHECK(double(original.walls().face[5].position) < 0.0395);
    CHECK(double(original.walls().face[5].force) > 0);
    CHECK(double(at_checkpoint.walls.face[5].velocity) != 0);
    CHECK(at_checkpoint.drive_work != 0); // the driven particles had pushed others
}

TEMPLATE_TEST_CASE("checkpoints convert between float and double", "[io][checkpoint]", float, double)
{
    using Real = TestType;
    using Other = std::conditional_t<std::is_same<Real, float>::value, double, float>;
    temp_folder dir;
    const std::string path = dir / "run.ck";
    host_sim<Real> original = eventful_run<Real>(400);
    sphere::write_checkpoint(path, original);

    const sphere::checkpoint_data<Other> c = sphere::read_checkpoint<Other>(path);
    CHECK(c.written_precision == sizeof(Real));
    CHECK(sphere::read_checkpoint_header(path).written_precision == sizeof(Real));
    CHECK(sphere::read_checkpoint_header(path).law == sphere::contact::linear<>::name());
    // Every value is the writer's value converted with static_cast (double on disk holds a
    // float exactly and rounds to float as a direct cast does).
    const sphere::simulation_state<Real> s = original.state();
    auto cast4 = [](const vec4<Real>& a) { return vec4<Other>{Other(a.x), Other(a.y), Other(a.z), Other(a.w)}; };
    auto cast3 = [](const vec3<Real>& a) { return sphere::vec_cast<Other>(a); };
    auto map = [](const auto& from, auto f) {
        std::vector<decltype(f(from[0]))> out;
        for (const auto& v : from) out.push_back(f(v));
        return out;
    };
    auto scalar = [](Real v) { return Other(v); };
    CHECK(same_bits(c.state.particles.x, map(s.particles.x, cast4)));
    CHECK(same_bits(c.state.particles.v_sync, map(s.particles.v_sync, cast3)));
    CHECK(same_bits(c.state.particles.torque, map(s.particles.torque, cast3)));
    CHECK(same_bits(c.state.particles.mass, map(s.particles.mass, scalar)));
    CHECK(same_bits(c.state.particles.e_fric, map(s.particles.e_fric, scalar)));
    CHECK(same_bits(c.state.contacts.history, map(s.contacts.history, cast4)));
    CHECK(same_bits(c.state.contacts.partner, s.contacts.partner));
    CHECK(same_bits(c.state.contacts.offset, s.contacts.offset));
    CHECK(same_bits(c.state.storage, s.storage));
    CHECK(c.config.dt == Other(original.dt()));
    CHECK(c.config.walls[5].amplitude == Other(original.config().walls[5].amplitude));
    CHECK(c.config.skin == Other(original.config().skin));
    CHECK(c.state.steps == 400);

    // The other precision continues from there. Over 100 more steps (2 ms) positions agree
    // with the writer's own continuation within 1 um (1e-4 of a radius): they differ by the
    // float run's rounding, about 4e-9 m per position and step plus float contact forces
    // (measured: 1.8e-7 m, a factor 5 below the bound).
    host_sim<Other> converted = sphere::restart<host_sim<Other>>(path);
    converted.run(100);
    original.run(100);
    const auto a = original.snapshot();
    const auto b = converted.snapshot();
    double worst = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(double(a.position(i)[k]) - double(b.position(i)[k])));
    INFO("largest position difference " << worst << " m");
    CHECK(worst < 1e-6);
}

// ---------------------------------------------------------------------------------------------
// (b) kill during write
// ---------------------------------------------------------------------------------------------

TEMPLATE_TEST_CASE("a writer killed while writing leaves the previous checkpoint intact", "[io][checkpoint]", float,
                   double)
{
    using Real = TestType;
    temp_folder dir;
    const std::string path = dir / "run.ck", tmp = path + ".tmp";

    host_sim<Real> small = eventful_run<Real>(200);
    const sphere::simulation_state<Real> previous = small.state();
    sphere::write_checkpoint(path, small);
    const std::string previous_bytes = read_bytes(path);

    // A large checkpoint (40^3 particles on a touching lattice, 6 contact entries each: about
    // 27 MB) that takes long enough to write that the kill lands inside the write.
    sphere::settings<Real> big_settings = eventful_settings<Real>();
    big_settings.box.lo = {Real(-0.45), Real(-0.45), Real(-0.45)};
    big_settings.box.hi = {Real(0.45), Real(0.45), Real(0.45)};
    big_settings.walls[5] = sphere::wall_control<Real>{};
    std::vector<sphere::particle<Real>> many;
    for (int k = 0; k < 40; ++k)
        for (int j = 0; j < 40; ++j)
            for (int i = 0; i < 40; ++i)
                many.push_back(sphere_test::ball<Real>({Real(-0.4 + 0.0199 * i), Real(-0.4 + 0.0199 * j),
                                                        Real(-0.4 + 0.0199 * k)}));
    const host_sim<Real> big(big_settings, many);
    const std::size_t big_size = sphere::encode_checkpoint(big.config(), big.dt(), big.state()).size();
    REQUIRE(big_size > 20u * 1000 * 1000);

    // Fork a child that writes the large checkpoint over `path`; kill it with SIGKILL once its
    // temporary file holds some bytes. The child uses no OpenMP (state(), encoding and the
    // POSIX writes are sequential), so forking a process with an OpenMP pool is safe.
    // A kill that lands after the rename (the child was quicker) would prove nothing, so the
    // attempt repeats, up to five times, until one kills the child mid-write.
    bool killed_mid_write = false;
    for (int attempt = 0; attempt < 5 && !killed_mid_write; ++attempt) {
        ::unlink(tmp.c_str());
        const pid_t child = ::fork();
        REQUIRE(child >= 0);
        if (child == 0) {
            try {
                sphere::write_checkpoint(path, big);
            } catch (...) {
                ::_exit(2);
            }
            ::_exit(0);
        }
        struct stat st {};
        int status = 0;
        bool reaped = false; // the child finished (or failed) before its temporary was seen
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (!(::stat(tmp.c_str(), &st) == 0 && st.st_size > 0) && std::chrono::steady_clock::now() < deadline)
            if (::waitpid(child, &status, WNOHANG) == child) {
                reaped = true;
                break;
            }
        if (!reaped) {
            ::kill(child, SIGKILL);
            ::waitpid(child, &status, 0);
        }
        const bool tmp_left = ::stat(tmp.c_str(), &st) == 0;
        const bool partial = tmp_left && static_cast<std::size_t>(st.st_size) < big_size;
        INFO("attempt " << attempt << ": killed " << (WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
                        << ", temporary " << (tmp_left ? std::to_string(st.st_size) : std::string("absent"))
                        << " of " << big_size << " bytes");
        killed_mid_write = WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL && partial;
        if (!killed_mid_write) { // the child got further: put the previous checkpoint back
            write_bytes(path, previous_bytes);
            continue;
        }
        // The target is byte for byte the previous checkpoint, and it reads back as such.
        CHECK(read_bytes(path) == previous_bytes);
        const sphere::checkpoint_data<Real> back = sphere::read_checkpoint<Real>(path);
        require_identical(back.state, previous);
    }
    REQUIRE(killed_mid_write);
    // The next write replaces the stale temporary and succeeds.
    sphere::write_checkpoint(path, small);
    CHECK(read_bytes(path) == previous_bytes);
    CHECK_FALSE(fs::exists(tmp));
}

TEMPLATE_TEST_CASE("format version 7, 6, 5 and 4 checkpoints, from before the accumulated displacement, the "
                   "fluid section, the bonds and the contact-law interface, still load",
                   "[io][checkpoint]", float, double)
{
    // Version 7 is version 8 without the accumulated displacement's flag at the end of the
    // payload (a u32: 0 here, where the run keeps none: an older file restarts without one).
    // Version 6 is version 7 without the fluid section's flag at the end of the payload (a
    // u32; 0 for a simulation on its own), version 5 is version 6 without the bond section at
    // the end of the payload (for no bonds: settings.bond's 6 f64, the bond count and 11 empty
    // arrays, 144 bytes), and version 4 is version 5 without the law's name and history layout
    // at its start (docs/io.md): files made so from a version 8 one read back to the same
    // settings and state, and restart; a reader with another law's parameters refuses
    // version 4. (tests/test_fluid_restart.cpp: coupled restarts and the fluid section.)
    using Real = TestType;
    temp_folder dir;
    sphere::settings<Real> s = eventful_settings<Real>();
    s.accumulated_displacement = false;
    host_sim<Real> sim(s, eventful_particles<Real>());
    sim.run(100);
    const std::string v8 = dir / "v8.ck", v7 = dir / "v7.ck", v6 = dir / "v6.ck", v5 = dir / "v5.ck",
                      v4 = dir / "v4.ck";
    sphere::write_checkpoint(v8, sim);
    const std::string b8 = read_bytes(v8);
    const std::string b7 = sphere_test::as_version(b8, 7, b8.size() - 8 - 4, 4);
    write_bytes(v7, b7);
    const std::string b6 = sphere_test::as_version(b7, 6, b7.size() - 8 - 4, 4);
    write_bytes(v6, b6);
    const std::string b5 = sphere_test::as_version(b6, 5, b6.size() - 8 - 144, 144);
    write_bytes(v5, b5);
    const std::string name = sphere::contact::linear<>::name(), layout = sphere::contact::linear<>::history_layout;
    write_bytes(v4, sphere_test::as_version(b5, 4, 24, 16 + name.size() + layout.size()));
    const sphere::checkpoint_data<Real> now = sphere::read_checkpoint<Real>(v8);
    CHECK(now.version == 8);
    CHECK_FALSE(now.fluid.has_value());
    CHECK_FALSE(now.config.accumulated_displacement);
    require_identical(sphere::read_checkpoint<Real>(v7).state, now.state);
    require_identical(sphere::read_checkpoint<Real>(v6).state, now.state);
    require_identical(sphere::read_checkpoint<Real>(v5).state, now.state);
    host_sim<Real> b = sphere::restart<host_sim<Real>>(v5);
    b.run(50);

    const sphere::checkpoint_data<Real> old = sphere::read_checkpoint<Real>(v4);
    require_identical(old.state, now.state);
    CHECK(old.config.contact.k_n == now.config.contact.k_n);
    CHECK(old.config.contact.mu_d == now.config.contact.mu_d);
    CHECK(old.config.wall.gamma_t == now.config.wall.gamma_t);
    CHECK(old.config.wall.damping == now.config.wall.damping);
    host_sim<Real> a = sphere::restart<host_sim<Real>>(v4), c = sphere::restart<host_sim<Real>>(v8),
                   d = sphere::restart<host_sim<Real>>(v6), e = sphere::restart<host_sim<Real>>(v7);
    a.run(50);
    c.run(50);
    d.run(50);
    e.run(50);
    require_identical(e.state(), c.state());
    require_identical(a.state(), c.state());
    require_identical(b.state(), c.state());
    require_identical(d.state(), c.state());
    CHECK_THROWS_WITH((sphere::read_checkpoint<Real, sphere::contact::hertz_mindlin<>>(v4)),
                      Catch::Contains("format version 4, but this build reads versions 8, 7, 6 and 5, and 4 only for the "
                                      "linear contact law, which version 4 describes"));
}

// ---------------------------------------------------------------------------------------------
// (c) refused files
// ---------------------------------------------------------------------------------------------

TEMPLATE_TEST_CASE("broken checkpoints raise the documented errors", "[io][checkpoint]", float, double)
{
    using Real = TestType;
    temp_folder dir;
    host_sim<Real> sim = eventful_run<Real>(100);
    const std::string good = dir / "good.ck";
    sphere::write_checkpoint(good, sim);
    const std::string bytes = read_bytes(good);
    const std::size_t size = bytes.size();
    REQUIRE_NOTHROW(sphere::read_checkpoint<Real>(good));
    const std::string bad = dir / "bad.ck";
    const std::string where = "sphere: checkpoint '" + bad + "': ";

    SECTION("the layout of docs/io.md")
    {
        // Little-endian fields at the documented file offsets.
        auto u32_at = [&](std::size_t at) {
            std::uint32_t v = 0;
            for (int k = 0; k < 4; ++k) v |= std::uint32_t(static_cast<unsigned char>(bytes[at + k])) << (8 * k);
            return v;
        };
        auto u64_at = [&](std::size_t at) {
            std::uint64_t v = 0;
            for (int k = 0; k < 8; ++k) v |= std::uint64_t(static_cast<unsigned char>(bytes[at + k])) << (8 * k);
            return v;
        };
        auto f64_at = [&](std::size_t at) {
            const std::uint64_t v = u64_at(at);
            double d;
            std::memcpy(&d, &v, 8);
            return d;
        };
        const std::uint64_t n = 64, entries = sim.state().contacts.partner.size();
        // The payload starts with the contact law's name and history layout (texts: a u64
        // length, then the bytes), then the settings.
        const std::string name = sphere::contact::linear<>::name(), layout = sphere::contact::linear<>::history_layout;
        CHECK(u64_at(24) == name.size());
        CHECK(bytes.compare(32, name.size(), name) == 0);
        CHECK(u64_at(32 + name.size()) == layout.size());
        CHECK(bytes.compare(40 + name.size(), layout.size(), layout) == 0);
        const std::size_t law_bytes = 16 + name.size() + layout.size(), at = 24 + law_bytes;
        CHECK(bytes.compare(0, 8, "SPHERECK") == 0);
        CHECK(u32_at(8) == 8);
        CHECK(u32_at(12) == sizeof(Real));
        CHECK(u64_at(16) == size - 32);
        // no bonds, no fluid, the accumulated displacement (docs/io.md)
        CHECK(size == 1196 + law_bytes + 313 * n + 36 * entries);
        const std::size_t displacement = size - 8 - (8 + 24 * n); // its array
        CHECK(u32_at(displacement - 4) == 1); // settings.accumulated_displacement
        CHECK(u64_at(displacement) == n);
        CHECK(f64_at(displacement + 8 + 24 * 5 + 16) == double(sim.snapshot().displacement[5].z));
        CHECK(u32_at(displacement - 4 - 4) == 0); // the fluid section's flag: none
        CHECK(f64_at(at + 40) == double(sim.config().box.hi.z)); // box.hi = settings bytes 24-47
        CHECK(u32_at(at + 48) == 0); // box.axis[0]: wall
        CHECK(f64_at(at + 60) == double(sim.config().contact.k_n));
        CHECK(f64_at(at + 116 + 32) == double(sim.config().wall.mu_s));
        CHECK(f64_at(at + 172 + 16) == double(sim.config().gravity.z));
        CHECK(f64_at(at + 196) == double(sim.dt()));
        CHECK(f64_at(at + 204) == double(sim.config().skin));
        CHECK(u32_at(at + 212) == 1); // contact_forces
        CHECK(u32_at(at + 216) == 1); // energy_audit
        CHECK(u32_at(at + 220) == 1); // angular_position
        CHECK(u32_at(at + 232 + 5 * 52) == 2); // walls[5].mode: stress
        CHECK(f64_at(at + 232 + 5 * 52 + 4 + 16) == double(sim.config().walls[5].amplitude));
        CHECK(u64_at(at + 544) == n);
        CHECK(u64_at(at + 552) == 100); // steps
        CHECK(u64_at(at + 560) == sim.rebuilds());
        CHECK(u32_at(at + 572 + 5 * 36) == 1); // face 5 active
        CHECK(f64_at(at + 572 + 5 * 36 + 4) == double(sim.walls().face[5].position));
        CHECK(f64_at(at + 788 + 5 * 8) == double(sim.state().walls_at_build.face[5].position));
        CHECK(f64_at(at + 836) == sim.drive_work());
        CHECK(u64_at(at + 844) == n); // the positions' count
        CHECK(f64_at(at + 844 + 8 + 3 * 8) == double(sim.snapshot().x[0].w)); // particle 0's radius
    }
    SECTION("missing")
    {
        const std::string missing = dir / "missing.ck";
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(missing),
                            "sphere: checkpoint '" + missing + "': cannot open: No such file or directory");
    }
    SECTION("one flipped byte in the payload")
    {
        std::string b = bytes;
        b[size / 2] = static_cast<char>(b[size / 2] ^ 0x10);
        write_bytes(bad, b);
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                            Catch::StartsWith(where + "corrupt: checksum mismatch (stored 0x"));
        // The header alone is read only after the same checks of the whole file.
        REQUIRE_THROWS_WITH(sphere::read_checkpoint_header(bad),
                            Catch::StartsWith(where + "corrupt: checksum mismatch (stored 0x"));
    }
    SECTION("a flipped byte in the checksum")
    {
        std::string b = bytes;
        b[size - 1] = static_cast<char>(b[size - 1] ^ 0x01);
        write_bytes(bad, b);
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad), Catch::Contains("checksum mismatch"));
    }
    SECTION("truncated")
    {
        for (const std::size_t cut : {size - 1, size / 2, std::size_t(40)}) {
            write_bytes(bad, bytes.substr(0, cut));
            REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                                where + "truncated: the file has " + std::to_string(cut) +
                                    " bytes, a complete checkpoint has " + std::to_string(size));
            REQUIRE_THROWS_WITH(sphere::read_checkpoint_header(bad),
                                where + "truncated: the file has " + std::to_string(cut) +
                                    " bytes, a complete checkpoint has " + std::to_string(size));
        }
        write_bytes(bad, bytes.substr(0, 20));
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                            where + "truncated: the file has 20 bytes, fewer than the 32 of a header and checksum");
        write_bytes(bad, "");
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad), Catch::Contains("truncated: the file has 0 bytes"));
    }
    SECTION("trailing data")
    {
        write_bytes(bad, bytes + "x");
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                            where + "corrupt: the file has " + std::to_string(size + 1) +
                                " bytes, a complete checkpoint has " + std::to_string(size) + " (trailing data)");
    }
    SECTION("wrong magic")
    {
        write_bytes(bad, replace_once(bytes, "SPHERECK", "SPHEREXX"));
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                            where + "not a sphere checkpoint: the file does not start with \"SPHERECK\"");
        write_bytes(bad, "time,kinetic\n0,1\n");
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad), Catch::Contains("not a sphere checkpoint"));
    }
    SECTION("wrong version")
    {
        std::string b = bytes;
        REQUIRE(b[8] == 8); // the version, little-endian u32 at byte 8
        b[8] = 3;
        write_bytes(bad, b);
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                            where + "format version 3, but this build reads versions 8, 7, 6 and 5, and 4 for the linear contact law");
    }
    SECTION("sizes that do not fit the particle count")
    {
        // A well-formed, correctly checksummed file whose storage order misses one particle.
        sphere::simulation_state<Real> s = sim.state();
        s.storage.pop_back();
        write_bytes(bad, sphere::encode_checkpoint(sim.config(), sim.dt(), s));
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                            where + "inconsistent contents: the storage order: 63 entries, expected 64");
        s = sim.state();
        std::size_t i0 = 0;
        while (s.contacts.begin(i0) == s.contacts.end(i0)) ++i0; // the first particle with an entry
        s.contacts.partner[s.contacts.begin(i0)] = 64; // there is no particle 64
        write_bytes(bad, sphere::encode_checkpoint(sim.config(), sim.dt(), s));
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                            where + "inconsistent contents: particle " + std::to_string(i0) +
                                " lists partner 64 (64 particles, or an active wall face)");
        s = sim.state();
        s.storage[0] = s.storage[1];
        write_bytes(bad, sphere::encode_checkpoint(sim.config(), sim.dt(), s));
        REQUIRE_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                            where + "inconsistent contents: the storage order is not a permutation: slot 1 holds particle " +
                                std::to_string(s.storage[1]));
    }
}

// ---------------------------------------------------------------------------------------------
// (d) CSV
// ---------------------------------------------------------------------------------------------

namespace {
/// Splits a CSV file into its header names and rows of numbers (strtod, exact for 17 digits).
void parse_csv(const std::string& path, std::vector<std::string>& header, std::vector<std::vector<double>>& rows)
{
    std::istringstream in(read_bytes(path));
    std::string line;
    REQUIRE(std::getline(in, line));
    header.clear();
    std::stringstream h(line);
    for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
    rows.clear();
    while (std::getline(in, line)) {
        std::vector<double> row;
        std::stringstream r(line);
        for (std::string cell; std::getline(r, cell, ',');) row.push_back(std::strtod(cell.c_str(), nullptr));
        rows.push_back(row);
    }
}
} // namespace

TEST_CASE("CSV series read back exactly", "[io][csv]")
{
    temp_folder dir;
    const std::string path = dir / "series.csv";
    sphere::csv_series csv(path, {"time_s", "value_J", "other_m/s"});
    const std::vector<std::vector<double>> rows = {
        {0.0, 1.0 / 3.0, -2.5e17},
        {std::nextafter(1.0, 2.0), 5e-324, 1.7976931348623157e308},
        {3.141592653589793, -0.0, 1e-300},
    };
    csv.add_row(rows[0]);
    csv.flush();
    // After a flush the file holds the rows so far.
    std::vector<std::string> header;
    std::vector<std::vector<double>> back;
    parse_csv(path, header, back);
    CHECK(header == std::vector<std::string>{"time_s", "value_J", "other_m/s"});
    REQUIRE(back.size() == 1);
    csv.add_row(rows[1]);
    csv.add_row(rows[2]);
    csv.close();
    CHECK(csv.rows() == 3);
    parse_csv(path, header, back);
    REQUIRE(back.size() == rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r) CHECK(same_bits(back[r], rows[r])); // 17 digits round-trip exactly
    CHECK_FALSE(fs::exists(path + ".tmp"));

    REQUIRE_THROWS_WITH(csv.add_row({1, 2, 3}), "sphere: CSV '" + path + "': add_row after close()");
    sphere::csv_series other(dir / "other.csv", {"a_m", "b_m"});
    REQUIRE_THROWS_WITH(other.add_row({1, 2, 3}), "sphere: CSV '" + (dir / "other.csv") + "': row 0 has 3 values for 2 columns");
    REQUIRE_THROWS_WITH(sphere::csv_series(dir / "x.csv", {"a,b"}), Catch::Contains("column 0 name 'a,b'"));
}

TEST_CASE("a failed write throws naming the file and leaves no file", "[io][csv]")
{
    temp_folder dir;
    const std::string path = dir / "no_such_folder/series.csv";
    sphere::csv_series csv(path, {"time_s"});
    csv.add_row({1.0});
    REQUIRE_THROWS_WITH(csv.flush(), "sphere: cannot write '" + path + "': creating the temporary file '" + path +
                                         ".tmp' failed: No such file or directory");
    CHECK_FALSE(fs::exists(path));
    CHECK_FALSE(fs::exists(path + ".tmp"));
    // A folder that exists but is a file: the same, and the file is untouched.
    const std::string blocker = dir / "blocker";
    write_bytes(blocker, "keep");
    REQUIRE_THROWS_WITH(sphere::write_file_atomically(blocker + "/x.ck", "data"), Catch::Contains("Not a directory"));
    CHECK(read_bytes(blocker) == "keep");
    // Renaming over a folder fails after the temporary was written: the temporary is removed.
    const std::string folder = dir / "a_folder";
    fs::create_directory(folder);
    fs::create_directory(folder + "/inside");
    REQUIRE_THROWS_WITH(sphere::write_file_atomically(folder, "data"), Catch::Contains("renaming the temporary file"));
    CHECK_FALSE(fs::exists(folder + ".tmp"));
    CHECK(fs::is_directory(folder + "/inside"));
}

TEMPLATE_TEST_CASE("the diagnostics series records energies and walls", "[io][csv]", float, double)
{
    using Real = TestType;
    temp_folder dir;
    const std::string path = dir / "diagnostics.csv";
    host_sim<Real> sim(eventful_settings<Real>(), eventful_particles<Real>());
    sphere::csv_series csv = sphere::diagnostics_series(path, sim);
    std::vector<std::vector<double>> expected; // the same quantities, taken directly
    sim.add_observer(50, [&](const host_sim<Real>& s) {
        csv.add_row(sphere::diagnostics_row(s));
        const auto e = s.energy();
        std::vector<double> row = {s.time(),        double(e.kinetic),         double(e.rotational),
                                   double(e.potential), double(e.elastic),     double(e.dissipated_visc),
                                   double(e.dissipated_fric), double(e.boundary_work), double(e.total())};
        for (int f = 0; f < 6; ++f)
            for (double v : {double(s.walls().face[f].position), double(s.walls().face[f].velocity),
                             double(s.walls().face[f].force)})
                row.push_back(v);
        expected.push_back(row);
    });
    sim.run(400);
    csv.close();
    std::vector<std::string> header;
    std::vector<std::vector<double>> back;
    parse_csv(path, header, back);
    REQUIRE(header.size() == 9 + 6 * 3); // every face of a closed box is an active wall
    CHECK(header[0] == "time_s");
    CHECK(header[8] == "total_J");
    CHECK(header[9] == "wall_xlo_position_m");
    CHECK(header[25] == "wall_zhi_velocity_m/s");
    CHECK(header[26] == "wall_zhi_force_N");
    REQUIRE(back.size() == 8);
    for (std::size_t r = 0; r < back.size(); ++r) {
        INFO("row " << r);
        CHECK(same_bits(back[r], expected[r]));
        CHECK(back[r][0] == double(static_cast<double>((r + 1) * 50) * double(sim.dt()))); // t = steps dt
    }
    CHECK(back.back()[26] > 0); // the top wall carries the particles' force by the end
}

// ---------------------------------------------------------------------------------------------
// (e) VTK
// ---------------------------------------------------------------------------------------------

namespace {
/// The text between <DataArray ... Name="name" ...> and </DataArray>, split at white space.
std::vector<std::string> vtk_array(const std::string& xml, const std::string& name)
{
    const std::size_t at = xml.find("Name=\"" + name + "\"");
    REQUIRE(at != std::string::npos);
    const std::size_t begin = xml.find('>', at) + 1, end = xml.find("</DataArray>", begin);
    std::istringstream in(xml.substr(begin, end - begin));
    std::vector<std::string> out;
    for (std::string token; in >> token;) out.push_back(token);
    return out;
}

template <class Real>
Real parse_real(const std::string& s)
{
    if (sizeof(Real) == 4) return static_cast<Real>(std::strtof(s.c_str(), nullptr));
    return static_cast<Real>(std::strtod(s.c_str(), nullptr));
}

/// Checks a .vtu file against a snapshot: point count and every value, exactly.
template <class Real>
void check_vtu(const std::string& path, const sphere::particle_snapshot<Real>& s, double time)
{
    const std::string xml = read_bytes(path);
    const std::size_t n = s.size();
    CHECK(xml.find("<VTKFile type=\"UnstructuredGrid\"") != std::string::npos);
    CHECK(xml.find("NumberOfPoints=\"" + std::to_string(n) + "\" NumberOfCells=\"" + std::to_string(n) + "\"") !=
          std::string::npos);
    const std::vector<std::string> t = vtk_array(xml, "TimeValue");
    REQUIRE(t.size() == 1);
    CHECK(std::strtod(t[0].c_str(), nullptr) == time);
    CHECK(vtk_array(xml, "types") == std::vector<std::string>(n, "1"));
    const std::vector<std::string> offsets = vtk_array(xml, "offsets");
    REQUIRE(offsets.size() == n);
    CHECK(offsets.back() == std::to_string(n));
    auto vectors = [&](const std::string& name, const std::vector<vec3<Real>>& v) {
        const std::vector<std::string> a = vtk_array(xml, name);
        INFO(name);
        REQUIRE(a.size() == 3 * n);
        bool equal = true;
        for (std::size_t i = 0; i < n; ++i)
            for (int k = 0; k < 3; ++k) equal &= parse_real<Real>(a[3 * i + k]) == v[i][k];
        CHECK(equal);
    };
    auto scalars = [&](const std::string& name, const std::vector<Real>& v) {
        const std::vector<std::string> a = vtk_array(xml, name);
        INFO(name);
        REQUIRE(a.size() == n);
        bool equal = true;
        for (std::size_t i = 0; i < n; ++i) equal &= parse_real<Real>(a[i]) == v[i];
        CHECK(equal);
    };
    std::vector<vec3<Real>> position(n);
    std::vector<Real> radius(n);
    for (std::size_t i = 0; i < n; ++i) {
        position[i] = s.position(i);
        radius[i] = s.radius(i);
    }
    vectors("position", position);
    scalars("radius", radius);
    vectors("velocity", s.v_sync);
    vectors("angular_velocity", s.omega_sync);
    vectors("angular_position", s.angpos);
    vectors("force", s.force);
    vectors("torque", s.torque);
    scalars("mass", s.mass);
    scalars("pressure", s.pressure);
    scalars("dissipated_viscous", s.e_visc);
    scalars("dissipated_frictional", s.e_fric);
    vectors("accumulated_displacement", s.displacement);
    std::vector<std::string> kinds;
    for (const std::uint8_t k : s.kind) kinds.push_back(std::to_string(unsigned(k)));
    CHECK(vtk_array(xml, "kind") == kinds);
    CHECK(vtk_array(xml, "material") == std::vector<std::string>(s.size(), "0"));
}

struct pvd_entry {
    double time;
    std::string file;
};

/// The DataSet entries of a .pvd file, parsed with a regular expression.
std::vector<pvd_entry> parse_pvd(const std::string& path)
{
    const std::string xml = read_bytes(path);
    CHECK(xml.find("<VTKFile type=\"Collection\"") != std::string::npos);
    const std::regex dataset("<DataSet timestep=\"([^\"]*)\"[^>]*file=\"([^\"]*)\"");
    std::vector<pvd_entry> out;
    for (auto it = std::sregex_iterator(xml.begin(), xml.end(), dataset); it != std::sregex_iterator(); ++it)
        out.push_back({std::strtod((*it)[1].str().c_str(), nullptr), (*it)[2].str()});
    return out;
}
} // namespace

TEMPLATE_TEST_CASE("vtu frames and the pvd collection hold every particle and field", "[io][vtk]", float, double)
{
    using Real = TestType;
    temp_folder dir;
    host_sim<Real> sim(eventful_settings<Real>(), eventful_particles<Real>());
    sim.run(30);
    const std::string single = dir / "single.vtu";
    sphere::write_vtu(single, sim);
    check_vtu(single, sim.snapshot(), sim.time());

    // Frames at steps 0, 20, ..., 100 through the observer; the folder is created.
    const std::string folder = dir / "out";
    host_sim<Real> run(eventful_settings<Real>(), eventful_particles<Real>());
    std::vector<sphere::particle_snapshot<Real>> frames;
    frames.push_back(run.snapshot());
    auto writer = sphere::add_vtk_output(run, folder, 20, "grains");
    run.add_observer(20, [&](const host_sim<Real>& s) { frames.push_back(s.snapshot()); });
    run.run(100);
    const std::vector<pvd_entry> entries = parse_pvd(folder + "/grains.pvd");
    REQUIRE(entries.size() == 6);
    for (std::size_t k = 0; k < entries.size(); ++k) {
        char name[32];
        std::snprintf(name, sizeof name, "grains_%06zu.vtu", k);
        INFO("frame " << k);
        CHECK(entries[k].file == name);
        CHECK(entries[k].time == static_cast<double>(20 * k) * double(run.dt()));
        check_vtu(folder + "/" + name, frames[k], entries[k].time);
    }
    for (const auto& e : fs::directory_iterator(folder)) CHECK(e.path().extension() != ".tmp");

    // A run restarted at step 40 that resumes the collection keeps frames 0-2 (the one at
    // step 40 rewritten) and drops the stale frames 3-5 until it writes them again.
    const std::string ck = dir / "at40.ck";
    host_sim<Real> first(eventful_settings<Real>(), eventful_particles<Real>());
    first.run(40);
    sphere::write_checkpoint(ck, first);
    host_sim<Real> again = sphere::restart<host_sim<Real>>(ck);
    auto resumed = sphere::add_vtk_output(again, folder, 20, "grains", true);
    std::vector<pvd_entry> now = parse_pvd(folder + "/grains.pvd");
    REQUIRE(now.size() == 3);
    CHECK(now[2].file == "grains_000002.vtu");
    again.run(20);
    now = parse_pvd(folder + "/grains.pvd");
    REQUIRE(now.size() == 4);
    CHECK(now[3].file == "grains_000003.vtu");
    CHECK(now[3].time == entries[3].time);
    check_vtu(folder + "/grains_000003.vtu", frames[3], entries[3].time); // the restart continues bit-identically
    CHECK(resumed->collection().entries().size() == 4);

    REQUIRE_THROWS_WITH(sphere::vtk_writer(folder, "a/b"), Catch::Contains("prefix 'a/b'"));
    REQUIRE_THROWS_WITH(sphere::vtk_writer(folder, "p", 0), Catch::Contains("output interval 0"));
}

} // namespace test_io
