// Restarting a run coupled to the pore fluid (include/sphere/fluid/snapshot.cuh, the fluid
// section of io/checkpoint.cuh; docs/fluid.md, *Restarting a coupled run*; docs/io.md,
// *Checkpoints*), host backend, float and double:
// - N coupled steps, write_checkpoint(path, sim, coupling), a fresh simulation (restart) and a
//   fresh coupling restored from the file, N more steps: bit for bit the uninterrupted 2N
//   steps (particles, fluid pressure and face velocities, porosity, work_on_particles), with
//   the multigrid-preconditioned and the plain CG pressure solvers, and with the Darcy model;
//   without the fluid's state the same restart differs (the comparison can fail);
// - a navier_stokes on its own restores bit-identically;
// - checkpoints of format version 6 (no fluid section) and version 7 without one still load,
//   and a coupled restart from them is refused; a float file restores a double coupling;
// - a snapshot of another model or grid, with an entry missing, unknown or of another length,
//   or of another porosity method is refused with a message naming it, and nothing changes;
// - a truncated or corrupt fluid section is refused;
// - the coupling's setup (fluid/setup.cuh) is stored and read back; restore() ignores it, and
//   a snapshot without it has none to read; make_coupling (fluid/setup_coupling.cuh) builds the
//   coupling a setup names, with the typed coupling's bits, and names what it cannot build.
#include <catch2/catch.hpp>

#include "checkpoint_bytes.hpp"
#include "temp_folder.hpp"

#include <sphere/dem.cuh>
#include <sphere/fluid.cuh>
#include <sphere/io.cuh>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_fluid_restart {

namespace {

using sphere_test::as_version;
using sphere_test::read_bytes;
using sphere_test::same_bits;
using sphere_test::temp_folder;
using sphere_test::write_bytes;

template <class Real>
using sim_t = sphere::simulation<Real, sphere::host>;
template <class Real, class Poisson = sphere::mg_poisson<Real, sphere::host>>
using coupling_t = sphere::fluid_coupling<Real, sphere::host, sphere::drag::gidaspow, Poisson>;

/// 240 particles (6 x 5 x 8, radii 0.40-0.49 mm, 2600 kg/m^3) settling from the upper half of a
/// 20 x 20 x 40 mm column with periodic sides in water-like fluid of 0.01 Pa s; 4 x 4 x 8 fluid
/// cells, 5 DEM steps per fluid step. The top holds a pressure that oscillates in time (so the
/// fluid's time matters) and the projection keeps half the old pressure (beta = 0.5, so the
/// pressure carries over).
template <class Real>
sphere::settings<Real> column_settings()
{
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(0.02), Real(0.02), Real(0.04)};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.contact.k_n = s.wall.k_n = s.contact.k_t = s.wall.k_t = Real(100);
    s.gravity = {0, 0, Real(-9.81)};
    return s;
}

template <class Real>
std::vector<sphere::particle<Real>> column_particles()
{
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 8; ++k)
        for (int j = 0; j < 5; ++j)
            for (int i = 0; i < 6; ++i) {
                sphere::particle<Real> p;
                p.position = {Real((i + 0.5) * 0.02 / 6), Real((j + 0.5) * 4e-3), Real(0.022 + (k + 0.5) * 2.1e-3)};
                p.radius = Real(4e-4 + 1e-5 * ((i * 7 + j * 3 + k) % 10));
                p.density = 2600;
                p.velocity = {Real(1e-3 * ((i + 2 * k) % 5 - 2)), Real(0), Real(0)};
                ps.push_back(p);
            }
    return ps;
}

template <class Real>
sphere::fluid_params<Real> column_fluid()
{
    sphere::fluid_params<Real> prm;
    prm.density = 1000;
    prm.viscosity = Real(0.01);
    prm.beta = Real(0.5);
    prm.gravity = {0, 0, Real(-9.81)};
    prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(Real(0), Real(20), Real(40));
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-11 : 1e-5;
    return prm;
}

sphere::coupling_options column_options()
{
    sphere::coupling_options opt;
    opt.dem_steps = 5;
    return opt;
}

template <class Real, class Poisson = sphere::mg_poisson<Real, sphere::host>>
coupling_t<Real, Poisson> column_coupling(unsigned nz = 8)
{
    const sphere::settings<Real> s = column_settings<Real>();
    return coupling_t<Real, Poisson>(sphere::fluid_grid<Real>::make(s.box, 4, 4, nz), column_fluid<Real>(),
                                     column_options());
}

/// Whether a fluid model has face velocities (navier_stokes; darcy_flow has none).
template <class F, class = void>
struct has_face_velocity : std::false_type {};
template <class F>
struct has_face_velocity<F, std::void_t<decltype(std::declval<const F&>().face_velocity(0))>> : std::true_type {};

/// Everything the comparison looks at, after a run.
template <class Real>
struct observed {
    sphere::particle_snapshot<Real> particles;
    std::vector<Real> p, u[3], phi_fluid, phi_estimator;
    sphere::fluid_snapshot<Real> state; ///< the coupling's whole snapshot
    double work;
    std::size_t steps;
    double time;
};

template <class Real, class Coupling>
observed<Real> observe(sim_t<Real>& sim, Coupling& c)
{
    observed<Real> o;
    o.particles = sim.snapshot();
    o.p = c.fluid().pressure();
    if constexpr (has_face_velocity<typename Coupling::model_type>::value)
        for (int a = 0; a < 3; ++a) o.u[a] = c.fluid().face_velocity(a);
    o.phi_fluid = c.fluid().porosity();
    o.phi_estimator = c.porosity().fields().phi;
    o.state = c.snapshot();
    o.work = c.work_on_particles();
    o.steps = sim.steps();
    o.time = c.fluid().time();
    return o;
}

/// Whether two runs ended bit for bit alike (CHECKs each part, so that a failure says which).
template <class Real>
bool identical(const observed<Real>& a, const observed<Real>& b)
{
    bool all = true;
    const auto check = [&all](bool same, const std::string& what) {
        INFO(what);
        CHECK(same);
        all = all && same;
    };
    check(a.particles.size() == b.particles.size(), "particle count");
    check(same_bits(a.particles.x, b.particles.x), "positions (user order)");
    check(same_bits(a.particles.v, b.particles.v), "velocities");
    check(same_bits(a.particles.omega, b.particles.omega), "angular velocities");
    check(same_bits(a.particles.force, b.particles.force), "forces");
    check(same_bits(a.p, b.p), "fluid pressure");
    for (int k = 0; k < 3; ++k) check(same_bits(a.u[k], b.u[k]), "fluid face velocities");
    check(same_bits(a.phi_fluid, b.phi_fluid), "the fluid's porosity");
    check(same_bits(a.phi_estimator, b.phi_estimator), "the estimator's porosity");
    check(same_bits(a.work, b.work), "work_on_particles()");
    check(a.steps == b.steps, "DEM steps");
    check(same_bits(a.time, b.time), "fluid time");
    check(a.state.arrays.size() == b.state.arrays.size(), "the snapshots' array count");
    for (std::size_t k = 0; k < a.state.arrays.size() && k < b.state.arrays.size(); ++k)
        check(a.state.arrays[k].name == b.state.arrays[k].name &&
                  same_bits(a.state.arrays[k].values, b.state.arrays[k].values),
              "the snapshots' array " + a.state.arrays[k].name);
    return all;
}

/// N coupled steps of the column with the coupling `make()` builds, a checkpoint, a restart
/// with a fresh coupling, N more steps against the uninterrupted 2N steps. Some pressure solve
/// must take more than `iterations_above` iterations.
template <class Real, class Make>
void check_coupled_restart(Make make, unsigned iterations_above)
{
    using coupling = decltype(make());
    constexpr int N = 12;
    temp_folder dir("sphere_fluid_restart");
    const std::string path = dir / "coupled.ck";

    sim_t<Real> straight(column_settings<Real>(), column_particles<Real>());
    coupling straight_fluid = make();
    unsigned most_iterations = 0;
    for (int n = 0; n < N; ++n) {
        straight_fluid.step(straight);
        most_iterations = std::max(most_iterations, straight_fluid.fluid().last_solve().iterations);
    }
    sphere::write_checkpoint(path, straight, straight_fluid);
    const auto at_checkpoint = straight_fluid.snapshot();
    for (int n = 0; n < N; ++n) {
        straight_fluid.step(straight);
        most_iterations = std::max(most_iterations, straight_fluid.fluid().last_solve().iterations);
    }
    const observed<Real> expected = observe(straight, straight_fluid);

    coupling fluid = make();
    sim_t<Real> sim = sphere::restart<sim_t<Real>>(path, fluid);
    // The restored coupling is the checkpointed one, entry for entry.
    const auto restored = fluid.snapshot();
    REQUIRE(restored.arrays.size() == at_checkpoint.arrays.size());
    for (std::size_t k = 0; k < restored.arrays.size(); ++k) {
        INFO("array " << restored.arrays[k].name);
        CHECK(restored.arrays[k].name == at_checkpoint.arrays[k].name);
        CHECK(same_bits(restored.arrays[k].values, at_checkpoint.arrays[k].values));
    }
    for (int n = 0; n < N; ++n) fluid.step(sim);
    CHECK(identical(observe(sim, fluid), expected));

    // The comparison means something: the particles fell, the fluid flows (where the model
    // has a velocity), the fluid did work, and the same restart with a fresh coupling that is
    // not restored ends elsewhere.
    INFO("most pressure-solve iterations in a step: " << most_iterations);
    CHECK(double(expected.particles.v[0].z) < -1e-3);
    if constexpr (has_face_velocity<typename coupling::model_type>::value) {
        double fastest = 0;
        for (const Real w : expected.u[2]) fastest = std::max(fastest, std::abs(double(w)));
        CHECK(fastest > 1e-4);
    }
    CHECK(expected.work < 0);
    CHECK(most_iterations > iterations_above);
    coupling forgetful = make();
    sim_t<Real> again = sphere::restart<sim_t<Real>>(path);
    for (int n = 0; n < N; ++n) forgetful.step(again);
    const observed<Real> without = observe(again, forgetful);
    CHECK_FALSE(same_bits(without.particles.x, expected.particles.x));
    CHECK_FALSE(same_bits(without.p, expected.p));
}

} // namespace

TEMPLATE_TEST_CASE("a coupled run restarts bit-identically from a checkpoint (mg_poisson)", "[fluid][restart][checkpoint]",
                   float, double)
{
    check_coupled_restart<TestType>([] { return column_coupling<TestType>(); }, 0);
}

TEMPLATE_TEST_CASE("a coupled run restarts bit-identically from a checkpoint (cg_poisson)", "[fluid][restart][checkpoint]",
                   float, double)
{
    // Plain CG needs more iterations (24 in float, 32 in double) than the 16 passes a fresh
    // solver launches before it first reads back: the restored solver's pass budget (not
    // stored) differs from the uninterrupted one's, which learnt from its last solves, and
    // the bits must not.
    check_coupled_restart<TestType>([] { return column_coupling<TestType, sphere::cg_poisson<TestType, sphere::host>>(); },
                                    16);
}

TEMPLATE_TEST_CASE("a coupled run with the Darcy model restarts bit-identically from a checkpoint",
                   "[fluid][restart][checkpoint][darcy]", float, double)
{
    // The same column with the Darcy model (Carman's k_c for 0.9 mm spheres, water's
    // compressibility): the pressure and the porosity's history carry over.
    using Real = TestType;
    check_coupled_restart<Real>(
        [] {
            const sphere::settings<Real> s = column_settings<Real>();
            sphere::darcy_params<Real> prm;
            prm.fluid = column_fluid<Real>();
            prm.permeability_prefactor = Real(0.9e-3 * 0.9e-3 / 180);
            return sphere::fluid_coupling<Real, sphere::host, sphere::drag::gidaspow, sphere::cg_poisson<Real, sphere::host>,
                                          sphere::darcy_flow>(sphere::fluid_grid<Real>::make(s.box, 4, 4, 8), prm,
                                                              column_options());
        },
        0);
}

TEMPLATE_TEST_CASE("a navier_stokes on its own restores bit-identically", "[fluid][restart]", float, double)
{
    // The porosity, its rate and the interaction force given once are read by every later step
    // of a fluid on its own: the snapshot holds them.
    using Real = TestType;
    const sphere::settings<Real> s = column_settings<Real>();
    const auto grid = sphere::fluid_grid<Real>::make(s.box, 4, 4, 8);
    using fluid_t = sphere::navier_stokes<Real, sphere::host>;
    fluid_t a(grid, column_fluid<Real>());
    sphere::porosity_estimator<Real, sphere::host> estimator(grid);
    sphere::particle_snapshot<Real> particles = sim_t<Real>(s, column_particles<Real>()).snapshot();
    estimator.update(particles, Real(1e-3));
    for (auto& x : particles.x) x.z -= Real(2e-4); // a porosity rate
    estimator.update(particles, Real(1e-3));
    a.set_porosity(estimator.view());
    sphere::vec3<Real>* force = a.interaction_force();
    for (std::size_t c = 0; c < grid.field_size(); ++c) force[c] = {Real(0.5) * Real(c % 7), Real(0), Real(-2)};
    const Real dt = Real(1e-3);
    for (int n = 0; n < 5; ++n) a.step(dt);
    const sphere::fluid_snapshot<Real> saved = a.snapshot();
    fluid_t b(grid, column_fluid<Real>());
    b.restore(saved);
    // c gets the velocities, pressures and time but a fresh fluid's porosity, rate and force.
    fluid_t c(grid, column_fluid<Real>());
    sphere::fluid_snapshot<Real> partial = saved;
    const sphere::fluid_snapshot<Real> fresh = c.snapshot();
    for (auto& entry : partial.arrays)
        if (entry.name == "phi" || entry.name == "dphi_dt" || entry.name == "force")
            for (const auto& f : fresh.arrays)
                if (f.name == entry.name) entry.values = f.values;
    c.restore(partial);
    for (int n = 0; n < 5; ++n) {
        a.step(dt);
        b.step(dt);
        c.step(dt);
    }
    CHECK(same_bits(a.pressure(), b.pressure()));
    for (int k = 0; k < 3; ++k) CHECK(same_bits(a.face_velocity(k), b.face_velocity(k)));
    CHECK(same_bits(a.time(), b.time()));
    CHECK(a.last_solve().iterations == b.last_solve().iterations);
    CHECK_FALSE(same_bits(a.pressure(), c.pressure()));
    CHECK_FALSE(same_bits(a.face_velocity(2), c.face_velocity(2)));
}

TEMPLATE_TEST_CASE("checkpoints without a fluid section still load, and a coupled restart needs one",
                   "[fluid][restart][checkpoint]", float, double)
{
    // Version 7 is version 8 without the accumulated displacement at the end of the payload (a
    // u32 flag and, with it, the array: a u64 count and n vec3 of f64), version 6 is version 7
    // without the fluid section's flag (a u32 at the end of its payload).
    using Real = TestType;
    temp_folder dir("sphere_fluid_restart");
    sim_t<Real> sim(column_settings<Real>(), column_particles<Real>());
    coupling_t<Real> fluid = column_coupling<Real>();
    for (int n = 0; n < 3; ++n) fluid.step(sim);
    const std::string plain = dir / "plain.ck", v6 = dir / "v6.ck", coupled = dir / "coupled.ck";
    sphere::write_checkpoint(plain, sim);
    sphere::write_checkpoint(coupled, sim, fluid);
    const std::string b8 = read_bytes(plain);
    REQUIRE(b8[8] == 8);
    const std::size_t moved = 4 + (sim.config().accumulated_displacement ? 8 + 24 * sim.size() : 0);
    const std::string b7 = as_version(b8, 7, b8.size() - 8 - moved, moved);
    write_bytes(v6, as_version(b7, 6, b7.size() - 8 - 4, 4));

    const sphere::checkpoint_data<Real> d8 = sphere::read_checkpoint<Real>(plain), d6 = sphere::read_checkpoint<Real>(v6),
                                        dc = sphere::read_checkpoint<Real>(coupled);
    CHECK(d8.version == 8);
    CHECK_FALSE(d8.fluid.has_value());
    CHECK(d6.version == 6);
    CHECK_FALSE(d6.fluid.has_value());
    REQUIRE(dc.fluid.has_value());
    CHECK(dc.fluid->model == "navier_stokes");
    CHECK(same_bits(d6.state.particles.x, dc.state.particles.x));
    // The coupled file is the plain one with the fluid section after the flag.
    const std::string bc = read_bytes(coupled);
    CHECK(bc.compare(24, b7.size() - 36, b8, 24, b7.size() - 36) == 0);

    // Both restart a simulation on its own, to the same state.
    sim_t<Real> from6 = sphere::restart<sim_t<Real>>(v6), from7 = sphere::restart<sim_t<Real>>(plain);
    CHECK(same_bits(from6.snapshot().x, from7.snapshot().x));
    CHECK(same_bits(from6.snapshot().v, sim.snapshot().v));
    // A coupled restart refuses them.
    coupling_t<Real> other = column_coupling<Real>();
    CHECK_THROWS_WITH(sphere::restart<sim_t<Real>>(v6, other),
                      "sphere: checkpoint '" + v6 +
                          "': no fluid section (format version 6, which has none); a coupled run is written by "
                          "write_checkpoint(path, sim, coupling)");
    CHECK_THROWS_WITH(sphere::restart<sim_t<Real>>(plain, other),
                      "sphere: checkpoint '" + plain +
                          "': no fluid section (format version 8, written without a coupling); a coupled run is "
                          "written by write_checkpoint(path, sim, coupling)");

    // A file of the other precision restores a coupling of this one (values converted).
    using Other = std::conditional_t<std::is_same_v<Real, float>, double, float>;
    coupling_t<Other> converted = column_coupling<Other>();
    sim_t<Other> continued = sphere::restart<sim_t<Other>>(coupled, converted);
    CHECK(converted.work_on_particles() == Approx(fluid.work_on_particles()).epsilon(1e-5));
    CHECK(double(converted.fluid().pressure()[200]) == Approx(double(fluid.fluid().pressure()[200])).epsilon(1e-5));
    CHECK(continued.steps() == sim.steps());
}

TEMPLATE_TEST_CASE("a snapshot of another model, grid or layout is refused, and nothing changes", "[fluid][restart]",
                   float, double)
{
    using Real = TestType;
    temp_folder dir("sphere_fluid_restart");
    sim_t<Real> sim(column_settings<Real>(), column_particles<Real>());
    coupling_t<Real> fluid = column_coupling<Real>();
    for (int n = 0; n < 3; ++n) fluid.step(sim);
    const sphere::fluid_snapshot<Real> good = fluid.snapshot();
    const std::size_t size = fluid.fluid().grid().field_size(); // 6 x 6 x 10

    coupling_t<Real> target = column_coupling<Real>();
    const auto before = target.snapshot();
    const auto unchanged = [&] {
        const auto now = target.snapshot();
        for (std::size_t k = 0; k < now.arrays.size(); ++k) CHECK(same_bits(now.arrays[k].values, before.arrays[k].values));
        CHECK(target.work_on_particles() == 0);
    };
    auto bad = good;
    SECTION("another model")
    {
        bad.model = "darcy";
        CHECK_THROWS_WITH(target.restore(bad),
                          "sphere: navier_stokes::restore: the snapshot is of the model \"darcy\", this one is "
                          "\"navier_stokes\"");
    }
    SECTION("another grid")
    {
        coupling_t<Real> taller = column_coupling<Real>(10);
        CHECK_THROWS_WITH(taller.restore(good),
                          "sphere: fluid_coupling::restore: the snapshot's grid has 4 x 4 x 8 cells, this one 4 x 4 x 10");
        bad.hi[2] = 0.05;
        CHECK_THROWS_WITH(target.restore(bad),
                          "sphere: fluid_coupling::restore: the snapshot's grid spans [0, 0.050000000000000003] m along z, "
                          "this one [0, " + sphere::detail::text(double(Real(0.04))) + "] m");
    }
    SECTION("an array of another length")
    {
        for (auto& a : bad.arrays)
            if (a.name == "p") a.values.pop_back();
        CHECK_THROWS_WITH(target.restore(bad), "sphere: navier_stokes::restore: the snapshot's array \"p\" holds " +
                                                   std::to_string(size - 1) + " values, expected " +
                                                   std::to_string(size) +
                                                   " (the grid's field size, ghost nodes included)");
    }
    SECTION("an entry missing or unknown")
    {
        bad.arrays.erase(bad.arrays.begin()); // u_x
        CHECK_THROWS_WITH(target.restore(bad),
                          "sphere: navier_stokes::restore: the snapshot of the model \"navier_stokes\" has no array \"u_x\"");
        bad = good;
        bad.add_number("viscosity", 1);
        CHECK_THROWS_WITH(target.restore(bad), "sphere: navier_stokes::restore: the snapshot holds a number \"viscosity\" "
                                               "that the model \"navier_stokes\" does not have");
        bad = good;
        bad.numbers.pop_back(); // coupling.work_total
        CHECK_THROWS_WITH(target.restore(bad),
                          "sphere: fluid_coupling::restore: the snapshot of the model \"coupling\" has no number \"work_total\"");
    }
    SECTION("the porosity estimator's part, checked before the fluid changes")
    {
        for (auto& c : bad.counts)
            if (c.name == "porosity.method") c.value = 1;
        CHECK_THROWS_WITH(target.restore(bad), "sphere: porosity_estimator::restore: the snapshot's porosity method is "
                                               "cell_sphere, this estimator's cell_volume");
        bad = good;
        for (auto& a : bad.arrays)
            if (a.name == "porosity.v_p") a.values.resize(size);
        CHECK_THROWS_WITH(target.restore(bad), "sphere: porosity_estimator::restore: the snapshot's array \"v_p\" holds " +
                                                   std::to_string(size) + " values, expected " +
                                                   std::to_string(3 * size) + " (3 per node of the grid's fields)");
    }
    SECTION("through a checkpoint, naming the file")
    {
        const std::string path = dir / "coupled.ck";
        sphere::write_checkpoint(path, sim, fluid);
        coupling_t<Real> taller = column_coupling<Real>(10);
        CHECK_THROWS_WITH(sphere::restart<sim_t<Real>>(path, taller),
                          "sphere: checkpoint '" + path +
                              "': fluid_coupling::restore: the snapshot's grid has 4 x 4 x 8 cells, this one 4 x 4 x 10");
        coupling_t<Real, sphere::cg_poisson<Real, sphere::host>> other_solver = column_coupling<Real, sphere::cg_poisson<Real, sphere::host>>();
        CHECK_NOTHROW(sphere::restart<sim_t<Real>>(path, other_solver)); // the solver is the caller's choice
    }
    unchanged();
}

TEMPLATE_TEST_CASE("a truncated or corrupt fluid section is refused", "[fluid][restart][checkpoint]", float, double)
{
    using Real = TestType;
    temp_folder dir("sphere_fluid_restart");
    sim_t<Real> sim(column_settings<Real>(), column_particles<Real>());
    coupling_t<Real> fluid = column_coupling<Real>();
    fluid.step(sim);
    const std::string plain = dir / "plain.ck", coupled = dir / "coupled.ck", bad = dir / "bad.ck";
    sphere::write_checkpoint(plain, sim);
    sphere::write_checkpoint(coupled, sim, fluid);
    // Both as format version 7, without the accumulated displacement that follows the fluid
    // section in version 8: the fluid section then ends the payload.
    const std::size_t moved = 4 + (sim.config().accumulated_displacement ? 8 + 24 * sim.size() : 0);
    const auto as_7 = [&](const std::string& bytes) { return as_version(bytes, 7, bytes.size() - 8 - moved, moved); };
    const std::string b = as_7(read_bytes(coupled));
    const std::string where = "sphere: checkpoint '" + bad + "': ";
    const std::size_t field = fluid.fluid().grid().field_size();
    // The fluid section begins with its flag, where the plain file's last 4 payload bytes are.
    const std::size_t flag = as_7(read_bytes(plain)).size() - 8 - 4;
    REQUIRE(b[flag] == 1);
    const std::string model = "navier_stokes";
    // flag, model, 3 cell counts, the box, the array count, then the first array: its name
    // "u_x", its value count, its values.
    const std::size_t first_values = flag + 4 + 8 + model.size() + 12 + 48 + 8 + 8 + 3 + 8;

    // A well-formed file whose fluid section ends two values into its first array: too short
    // for the entries it announces.
    write_bytes(bad, as_version(b, 7, first_values + 16, b.size() - 8 - (first_values + 16)));
    CHECK_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                      where + "inconsistent contents: the fluid array count is 12, but " +
                          std::to_string(first_values + 16 - (flag + 4 + 8 + model.size() + 12 + 48 + 8)) +
                          " bytes are left");
    // An array longer than what is left (its value count raised to 10^6).
    std::string longer = b;
    REQUIRE(static_cast<unsigned char>(longer[first_values - 8]) == field % 256);
    const std::uint64_t million = 1000000;
    for (int k = 0; k < 8; ++k) longer[first_values - 8 + k] = static_cast<char>((million >> (8 * k)) & 0xffu);
    write_bytes(bad, as_version(longer, 7, 0, 0));
    CHECK_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                      where + "inconsistent contents: the fluid array \"u_x\": 1000000 values of 8 bytes do not fit in the " +
                          std::to_string(b.size() - 8 - first_values) + " bytes left");
    // ... and one that ends 4 bytes early, inside the last count's value.
    write_bytes(bad, as_version(b, 7, b.size() - 8 - 4, 4));
    CHECK_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                      where + "inconsistent contents: the payload ends before the fluid count \"setup.drag\"");
    // A file cut short, and a flipped byte in the fluid section.
    write_bytes(bad, b.substr(0, first_values + 100));
    CHECK_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                      where + "truncated: the file has " + std::to_string(first_values + 100) +
                          " bytes, a complete checkpoint has " + std::to_string(b.size()));
    std::string flipped = b;
    flipped[first_values + 20] = static_cast<char>(flipped[first_values + 20] ^ 0x04);
    write_bytes(bad, flipped);
    CHECK_THROWS_WITH(sphere::read_checkpoint<Real>(bad), Catch::StartsWith(where + "corrupt: checksum mismatch"));
    // A flag that is neither 0 nor 1, and a grid without cells.
    std::string odd = b;
    odd[flag] = 2;
    write_bytes(bad, as_version(odd, 7, 0, 0));
    CHECK_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                      where + "inconsistent contents: the fluid section's flag = 2, at most 1 is valid");
    std::string empty = b;
    const std::size_t nz_at = flag + 4 + 8 + model.size() + 8;
    REQUIRE(empty[nz_at] == 8);
    empty[nz_at] = 0;
    write_bytes(bad, as_version(empty, 7, 0, 0));
    CHECK_THROWS_WITH(sphere::read_checkpoint<Real>(bad),
                      where + "inconsistent contents: the fluid grid has 0 cells along axis 2, at least 1 is valid");
    // The intact file reads.
    CHECK_NOTHROW(sphere::read_checkpoint<Real>(coupled));
}

TEMPLATE_TEST_CASE("a coupled checkpoint stores the setup it was built from, and restores without it",
                   "[fluid][restart][checkpoint][setup]", float, double)
{
    // fluid/setup.cuh: the "setup." entries of the coupling's snapshot give back the model, the
    // solver and drag law by name, every fluid parameter and the coupling's options; restore()
    // does not read them; a snapshot without them (an older file) has no setup to build from.
    using Real = TestType;
    temp_folder dir("sphere_fluid_setup");
    sim_t<Real> sim(column_settings<Real>(), column_particles<Real>());
    coupling_t<Real, sphere::cg_poisson<Real, sphere::host>> fluid =
        column_coupling<Real, sphere::cg_poisson<Real, sphere::host>>();
    fluid.step(sim);
    const std::string path = dir / "coupled.ck";
    sphere::write_checkpoint(path, sim, fluid);
    const sphere::checkpoint_data<Real> d = sphere::read_checkpoint<Real>(path);
    REQUIRE(d.fluid.has_value());
    const sphere::coupling_setup<Real> got = sphere::coupling_setup<Real>::read(*d.fluid, "test");
    CHECK(got.model == "navier_stokes");
    CHECK(got.solver == "cg");
    CHECK(got.drag == "gidaspow");
    const sphere::fluid_params<Real> want = column_fluid<Real>();
    CHECK(got.params.fluid.density == want.density);
    CHECK(got.params.fluid.viscosity == want.viscosity);
    CHECK(got.params.fluid.beta == want.beta);
    CHECK(got.params.fluid.gravity.z == want.gravity.z);
    CHECK(got.params.fluid.bottom.kind == sphere::fluid_boundary_kind::no_flow);
    CHECK(got.params.fluid.top.kind == sphere::fluid_boundary_kind::pressure);
    CHECK(got.params.fluid.top.amplitude == Real(20));
    CHECK(got.params.fluid.top.frequency == Real(40));
    CHECK(got.params.fluid.poisson.tolerance == want.poisson.tolerance);
    CHECK(got.params.fluid.poisson.max_iterations == want.poisson.max_iterations);
    CHECK(got.options.dem_steps == 5);
    CHECK(got.options.pressure_force);
    CHECK(got.options.porosity == sphere::porosity_method::cell_volume);

    // The Darcy model's own parameters too.
    const sphere::settings<Real> s = column_settings<Real>();
    sphere::darcy_params<Real> prm;
    prm.fluid = column_fluid<Real>();
    prm.permeability_prefactor = Real(1e-9);
    prm.max_porosity = Real(0.8);
    sphere::fluid_coupling<Real, sphere::host, sphere::drag::ergun, sphere::mg_poisson<Real, sphere::host>, sphere::darcy_flow>
        darcy(sphere::fluid_grid<Real>::make(s.box, 4, 4, 8), prm, column_options());
    const sphere::coupling_setup<Real> d_got = sphere::coupling_setup<Real>::read(darcy.snapshot(), "test");
    CHECK(d_got.model == "darcy");
    CHECK(d_got.solver == "mg");
    CHECK(d_got.drag == "ergun");
    CHECK(d_got.params.permeability_prefactor == Real(1e-9));
    CHECK(d_got.params.max_porosity == Real(0.8));
    CHECK(d_got.params.compressibility == prm.compressibility);

    // Without the setup entries (an older file): restore() still works, the setup is refused.
    const sphere::fluid_snapshot<Real> older = d.fluid->other_than({"setup."});
    coupling_t<Real, sphere::cg_poisson<Real, sphere::host>> target =
        column_coupling<Real, sphere::cg_poisson<Real, sphere::host>>();
    CHECK_NOTHROW(target.restore(older));
    CHECK_THROWS_WITH(sphere::coupling_setup<Real>::read(older, "checkpoint 'x'"),
                      "sphere: checkpoint 'x': the fluid section holds no setup (it was written before setups were "
                      "stored): the coupling cannot be built from it");
}

TEMPLATE_TEST_CASE("make_coupling builds the coupling a setup names: the typed coupling's bits, and names what it "
                   "cannot build",
                   "[fluid][setup]", float, double)
{
    // fluid/setup_coupling.cuh: from the setup() of each of the four couplings it builds
    // (Navier-Stokes and Darcy, mg and cg, Gidaspow), make_coupling gives that coupling's type,
    // the same setup, and after two coupled steps of the column the same bits as the coupling
    // built by its type.
    using Real = TestType;
    using gidaspow = sphere::drag::gidaspow;
    using mg = sphere::mg_poisson<Real, sphere::host>;
    using cg = sphere::cg_poisson<Real, sphere::host>;
    const sphere::settings<Real> s = column_settings<Real>();
    const sphere::fluid_grid<Real> grid = sphere::fluid_grid<Real>::make(s.box, 4, 4, 8);
    sphere::darcy_params<Real> darcy;
    darcy.fluid = column_fluid<Real>();
    darcy.permeability_prefactor = Real(0.9e-3 * 0.9e-3 / 180);
    const auto compare = [&](auto* type, const auto& params, std::size_t index) {
        using Coupling = std::remove_pointer_t<decltype(type)>;
        Coupling typed(grid, params, column_options());
        const sphere::coupling_setup<Real> setup = typed.setup();
        INFO(setup.model << " with " << setup.solver);
        sphere::setup_coupling<Real, sphere::host> built = sphere::make_coupling<Real, sphere::host>(setup, grid, "test");
        REQUIRE(built.index() == index);
        Coupling& same = *std::get<std::unique_ptr<Coupling>>(built);
        CHECK(same.setup().snapshot(grid).numbers.size() == setup.snapshot(grid).numbers.size());
        const sphere::fluid_snapshot<Real> want = setup.snapshot(grid), got = same.setup().snapshot(grid);
        for (std::size_t k = 0; k < want.numbers.size() && k < got.numbers.size(); ++k)
            CHECK((want.numbers[k].name == got.numbers[k].name && same_bits(want.numbers[k].value, got.numbers[k].value)));
        for (std::size_t k = 0; k < want.counts.size() && k < got.counts.size(); ++k)
            CHECK((want.counts[k].name == got.counts[k].name && want.counts[k].value == got.counts[k].value));
        sim_t<Real> a(column_settings<Real>(), column_particles<Real>()), b(column_settings<Real>(), column_particles<Real>());
        for (int k = 0; k < 2; ++k) {
            typed.step(a);
            same.step(b);
        }
        CHECK(identical(observe(a, typed), observe(b, same)));
    };
    compare(static_cast<sphere::fluid_coupling<Real, sphere::host, gidaspow, mg, sphere::navier_stokes>*>(nullptr),
            column_fluid<Real>(), 0);
    compare(static_cast<sphere::fluid_coupling<Real, sphere::host, gidaspow, cg, sphere::navier_stokes>*>(nullptr),
            column_fluid<Real>(), 1);
    compare(static_cast<sphere::fluid_coupling<Real, sphere::host, gidaspow, mg, sphere::darcy_flow>*>(nullptr), darcy, 2);
    compare(static_cast<sphere::fluid_coupling<Real, sphere::host, gidaspow, cg, sphere::darcy_flow>*>(nullptr), darcy, 3);

    // What it does not build is named, with where the setup came from.
    const sphere::coupling_setup<Real> good = column_coupling<Real>().setup();
    const auto refused = [&](void (*change)(sphere::coupling_setup<Real>&), const std::string& message) {
        sphere::coupling_setup<Real> bad = good;
        change(bad);
        CHECK_THROWS_WITH((sphere::make_coupling<Real, sphere::host>(bad, grid, "checkpoint 'x': setup")),
                          "sphere: checkpoint 'x': setup." + message);
    };
    refused([](sphere::coupling_setup<Real>& c) { c.model = "lattice_boltzmann"; },
            "model = 'lattice_boltzmann': not one of 'navier_stokes', 'darcy'");
    refused([](sphere::coupling_setup<Real>& c) { c.solver = "jacobi"; }, "solver = 'jacobi': not one of 'mg', 'cg'");
    refused([](sphere::coupling_setup<Real>& c) { c.drag = "ergun"; },
            "drag = 'ergun': couplings built from a setup use 'gidaspow' (others: build the fluid_coupling type in C++)");
    // The model's own checks follow: a Darcy setup without a permeability.
    sphere::coupling_setup<Real> no_permeability = good;
    no_permeability.model = "darcy";
    CHECK_THROWS_WITH((sphere::make_coupling<Real, sphere::host>(no_permeability, grid, "test")),
                      Catch::Contains("permeability_prefactor = 0"));
}

} // namespace test_fluid_restart
