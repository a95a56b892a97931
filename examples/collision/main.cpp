// collision: two spheres collide head-on or obliquely, or one sphere hits the floor.
// Prints the measured restitution, contact duration and energy balance next to the analytic
// values of the linear contact model, and writes a CSV time series. With no options it runs
// an elastic-viscous head-on pair of the validation set P (docs/examples.md).
#include <sphere/dem.cuh>
#include <sphere/io/atomic_file.cuh>

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct options {
    std::string target = "pair"; // pair | wall
    double r1 = 0.01, r2 = 0.01, density = 2500, speed = 1, angle_deg = 0;
    double k_n = 1e5, k_t = 1e5 * 2.0 / 7.0, restitution = 0.5, gamma_n = -1, mu = 0.3, gamma_t = 0;
    double dt_factor = 1;
    bool tension = false;
    std::string precision = "double", backend = "host", csv = "collision.csv";
};

template <class Real, class Policy>
int run(const options& o)
{
    using namespace sphere;
    using v3 = vec3<Real>;
    const bool wall = o.target == "wall";
    const double m1 = sphere_mass(o.r1, o.density), m2 = sphere_mass(o.r2, o.density);
    const double m_eff = wall ? m1 : effective_mass(m1, m2);
    const double gamma_n = o.gamma_n >= 0 ? o.gamma_n : gamma_n_from_restitution(o.restitution, m_eff, o.k_n, o.tension);
    const double zeta = gamma_n / (2 * std::sqrt(m_eff * o.k_n));

    settings<Real> s;
    const double half = 20 * (o.r1 + o.r2);
    s.box.lo = {Real(-half), Real(-half), Real(-half)};
    s.box.hi = {Real(half), Real(half), Real(half)};
    s.contact = {Real(o.k_n), Real(o.k_t), Real(gamma_n), Real(o.gamma_t), Real(o.mu), Real(o.mu), o.tension};
    s.wall = s.contact;
    const double dt0 = 0.075 * std::sqrt(std::fmin(m1, wall ? m1 : m2) / std::fmax(o.k_n, o.k_t));
    s.dt = Real(dt0 * o.dt_factor);

    // The line of centres is z; the impact velocity makes angle_deg with it, tilted towards x.
    const double a = o.angle_deg * pi<double> / 180;
    const v3 v0{Real(o.speed * std::sin(a)), 0, Real(-o.speed * std::cos(a))};
    std::vector<particle<Real>> p(wall ? 1 : 2);
    if (wall) {
        p[0].position = {0, 0, Real(-half + o.r1)};
    } else {
        p[0].position = {0, 0, Real(o.r1 + o.r2)};
        p[1].position = {0, 0, 0};
        p[1].radius = Real(o.r2);
        p[1].density = Real(o.density);
    }
    p[0].radius = Real(o.r1);
    p[0].density = Real(o.density);
    p[0].velocity = v0;

    simulation<Real, Policy> sim(s, p);
    const energy_budget<Real> e0 = sim.energy();
    std::ostringstream csv; // written to the file only once the run has succeeded
    csv << "time_s,x1_m,z1_m,vx1_m_s,vz1_m_s,omegay1_rad_s,x2_m,z2_m,vx2_m_s,vz2_m_s,overlap_m,normal_force_N,"
           "kinetic_J,rotational_J,elastic_J,dissipated_visc_J,dissipated_fric_J,total_J\n";
    csv.precision(10);

    double t_first = -1, t_last = -1, min_gap = 0;
    const std::size_t max_steps = static_cast<std::size_t>(20 * pi<double> * std::sqrt(m_eff / o.k_n) / double(sim.dt()));
    for (std::size_t k = 0; k < max_steps; ++k) {
        sim.step();
        const particle_snapshot<Real> q = sim.snapshot();
        const energy_budget<Real> e = sim.energy();
        const double gap = wall ? double(q.x[0].z) - (-half) - o.r1
                                : norm(vec_cast<double>(q.position(0) - q.position(1))) - (o.r1 + o.r2);
        const double fn = double(q.pressure[0]) * 4 * pi<double> * o.r1 * o.r1;
        // The contact lasts while the force acts: without tension it ends when the clipped force
        // vanishes, before the spheres separate geometrically (Schwager & Poeschel 2007).
        const bool touching = o.tension ? gap < 0 : fn > 0;
        if (touching) {
            if (t_first < 0) t_first = sim.time() - double(sim.dt());
            t_last = sim.time();
        }
        min_gap = std::fmin(min_gap, gap);
        const std::size_t j = wall ? 0 : 1;
        csv << sim.time() << ',' << q.x[0].x << ',' << q.x[0].z << ',' << q.v[0].x << ',' << q.v[0].z << ','
            << q.omega[0].y << ',' << q.x[j].x << ',' << q.x[j].z << ',' << q.v[j].x << ',' << q.v[j].z << ','
            << (gap < 0 ? -gap : 0.0) << ',' << fn << ',' << e.kinetic << ',' << e.rotational << ',' << e.elastic
            << ',' << e.dissipated_visc << ',' << e.dissipated_fric << ',' << e.total() << '\n';
        if (t_last >= 0 && gap > 0) break; // flown apart
    }
    if (t_last < 0) throw error("the spheres never touched: check the angle and speed");

    const particle_snapshot<Real> q = sim.snapshot();
    const energy_budget<Real> e1 = sim.energy();
    const double vn_before = -o.speed * std::cos(a);
    const double vn_after = wall ? double(q.v[0].z) : double(q.v[0].z - q.v[1].z);
    const double e_measured = -vn_after / vn_before;
    const double e_analytic = restitution_from_damping_ratio(zeta, o.tension);
    const double tc_analytic = contact_duration(zeta, m_eff, o.k_n, o.tension);
    const double before = double(e0.kinetic + e0.rotational);
    const double after = double(e1.kinetic + e1.rotational);
    const double dissipated = double(e1.dissipated_visc + e1.dissipated_fric);

    std::printf("collision: %s, %s, %s backend, dt = %.6g s, zeta = %.6f, gamma_n = %.6g N s/m\n", o.target.c_str(),
                o.precision.c_str(), o.backend.c_str(), double(sim.dt()), zeta, gamma_n);
    std::printf("%-28s %14s %14s %10s\n", "quantity", "measured", "analytic", "rel. err");
    std::printf("%-28s %14.6f %14.6f %10.2e\n", "normal restitution e", e_measured, e_analytic,
                std::fabs(e_measured - e_analytic) / e_analytic);
    std::printf("%-28s %14.6e %14.6e %10.2e\n", "contact duration t_c (s)", t_last - t_first, tc_analytic,
                std::fabs(t_last - t_first - tc_analytic) / tc_analytic);
    std::printf("%-28s %14.6e\n", "max overlap (m)", -min_gap);
    std::printf("%-28s %14.6e\n", "kinetic+rotational before (J)", before);
    std::printf("%-28s %14.6e\n", "kinetic+rotational after (J)", after);
    std::printf("%-28s %14.6e  (viscous %.6e, friction %.6e)\n", "dissipated (J)", dissipated,
                double(e1.dissipated_visc), double(e1.dissipated_fric));
    std::printf("%-28s %14.6e %14s %10.2e\n", "energy balance error (J)", before - after - dissipated, "0",
                std::fabs(before - after - dissipated) / before);
    write_file_atomically(o.csv, csv.str()); // sphere::, through a temporary file and a rename
    std::printf("time series written to %s\n", o.csv.c_str());
    return 0;
}

template <class Policy>
int run_precision(const options& o)
{
    return o.precision == "float" ? run<float, Policy>(o) : run<double, Policy>(o);
}

} // namespace

int main(int argc, char** argv)
{
    options o;
    CLI::App app{"collision: two spheres (or a sphere and the floor) collide; compares restitution, contact "
                 "duration and energy balance with the linear contact model's analytic values"};
    app.add_option("--target", o.target, "pair or wall")->check(CLI::IsMember({"pair", "wall"}))->capture_default_str();
    app.add_option("--r1", o.r1, "radius of the moving sphere (m)")->capture_default_str();
    app.add_option("--r2", o.r2, "radius of the sphere at rest (m)")->capture_default_str();
    app.add_option("--density", o.density, "density (kg/m^3)")->capture_default_str();
    app.add_option("--speed", o.speed, "impact speed (m/s)")->capture_default_str();
    app.add_option("--angle", o.angle_deg, "angle between the velocity and the line of centres (deg)")
        ->check(CLI::Range(0.0, 89.0))->capture_default_str();
    app.add_option("--kn", o.k_n, "normal stiffness k_n (N/m)")->capture_default_str();
    app.add_option("--kt", o.k_t, "tangential stiffness k_t (N/m)")->capture_default_str();
    auto* e_opt = app.add_option("--restitution", o.restitution, "restitution coefficient (sets gamma_n)")
                      ->capture_default_str();
    app.add_option("--gamma-n", o.gamma_n, "normal viscosity gamma_n (N s/m), instead of --restitution")
        ->excludes(e_opt);
    app.add_option("--mu", o.mu, "friction coefficient (static = dynamic)")->capture_default_str();
    app.add_option("--gamma-t", o.gamma_t, "tangential viscosity gamma_t (N s/m)")->capture_default_str();
    app.add_option("--dt-factor", o.dt_factor, "time step as a multiple of 0.075 sqrt(m/k)")->capture_default_str();
    app.add_flag("--tension", o.tension, "allow an attractive normal force (default: clipped at 0, as sphere)");
    app.add_option("--precision", o.precision, "float or double")
        ->check(CLI::IsMember({"float", "double"}))->capture_default_str();
    app.add_option("--backend", o.backend, "host or cuda")->check(CLI::IsMember({"host", "cuda"}))->capture_default_str();
    app.add_option("--csv", o.csv, "CSV time series output")->capture_default_str();
    CLI11_PARSE(app, argc, argv);

    try {
        if (o.backend == "cuda") {
#if defined(SPHERE_EXAMPLE_CUDA)
            return run_precision<sphere::cuda>(o);
#else
            throw sphere::error("--backend cuda: this binary was built without CUDA; run collision_cuda instead");
#endif
        }
        return run_precision<sphere::host>(o);
    } catch (const std::exception& ex) {
        std::cerr << ex.what() << '\n';
        return 1;
    }
}
