// bed: the dense-bed throughput benchmark of ../shared/bench/bed (README there): N polydisperse
// spheres settled on a floor, periodic in x and y, ~5.7 persistent contacts each. Reads
// bed_N.csv, runs 200 untimed steps, counts the contacts, times 2000 steps, counts again, and
// prints the counts and particle-steps per second (docs/performance.md, "Dense bed").
//
//   build/bench/bed --csv bed_10000.csv [--precision double|float|mixed] [--threads 1] [--order file|shuffled]
//                   [--tile 4 5]   (the periodic bed repeated 4 x 5 times in x and y: 1e6 particles from 50k)
//                   [--rebuild]    (one rebuild of the contact lists after the untimed steps, for its memory)
//                   [--summation automatic|slabs|gather]   (the pair sums' schedule; gather is CUDA's)
//
// Memory: the resident set (VmRSS, /proc/self/status) of the program with its input file, after the
// untimed steps, and the whole process's peak (VmHWM), per particle (host backend only).
//
// bed_cuda is this file compiled by nvcc with SPHERE_BED_POLICY=sphere::cuda (bench/CMakeLists.txt):
// the same scenario on the GPU, its line naming the backend instead of the threads.
#include <sphere/dem.cuh>

#include <CLI/CLI.hpp>

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#ifndef SPHERE_BED_POLICY
#define SPHERE_BED_POLICY sphere::host
#endif

namespace {

using policy = SPHERE_BED_POLICY;
constexpr bool on_host = std::is_same_v<policy, sphere::host>;

struct options {
    std::string csv;
    std::string precision = "double";
    std::string order = "file"; // file | shuffled
    int threads = 1;
    bool audit = false;
    bool rebuild = false;
    std::string summation = "automatic"; // automatic | slabs | gather
    std::size_t pre = 200, steps = 2000;
    std::vector<unsigned> tile{1, 1}; ///< copies of the periodic bed along x and y
};

/// A field of /proc/self/status in bytes (VmRSS, VmHWM), 0 where there is none.
double status_bytes(const char* field)
{
    std::ifstream in("/proc/self/status");
    std::string line;
    const std::string key = std::string(field) + ":";
    while (std::getline(in, line))
        if (line.compare(0, key.size(), key) == 0) return 1024.0 * std::stod(line.substr(key.size())); // kB
    return 0;
}

/// The scenario's constants (README section 2-4).
constexpr double density = 2600, gravity = 9.81, k_n = 1e4, k_t = 1e4, mu = 0.4;
constexpr double gamma_n = 18465.79868, gamma_t = 9232.89934;      // 1/s, times m_eff
constexpr double gamma_n_wall = 13057.29147, gamma_t_wall = 6528.645733;
constexpr double dt = 2.113274955e-6, skin = 4e-4;
constexpr double mgd = 2.1367857e-7; // m_ref g d_ref (J)

struct bed_file {
    double length = 0, top = 0; ///< period L and the box height zhi (m)
    std::vector<double> x, y, z, r;
};

bed_file read_bed(const std::string& path)
{
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot open " + path);
    bed_file b;
    std::string line;
    std::getline(in, line);
    if (line != "id,x,y,z,radius") throw std::runtime_error(path + ": header is not id,x,y,z,radius");
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        std::istringstream row(line);
        std::string cell[5];
        for (auto& c : cell) std::getline(row, c, ',');
        b.x.push_back(std::stod(cell[1]));
        b.y.push_back(std::stod(cell[2]));
        b.z.push_back(std::stod(cell[3]));
        b.r.push_back(std::stod(cell[4]));
    }
    // The README's boxes, chosen by N.
    if (b.x.size() == 10000) { b.length = 0.0552; b.top = 0.034; }
    else if (b.x.size() == 50000) { b.length = 0.0943; b.top = 0.050; }
    else throw std::runtime_error(path + ": " + std::to_string(b.x.size()) + " particles; the scenario has 10000 or 50000");
    return b;
}

struct counts {
    double pair_contacts_per_particle;
    std::size_t wall_contacts;
    double kinetic; ///< KE_tr / (N m_ref g d_ref)
};

template <class Sim>
counts count(const Sim& sim)
{
    using Real = typename Sim::real_type;
    const auto s = sim.snapshot();
    const auto& box = sim.config().box;
    const std::size_t n = s.size();
    std::size_t pairs = 0, walls = 0;
    double ke = 0;
    // Candidate partners: the contact lists hold every pair within r_i + r_j + skin.
    const sphere::contact_table<Real> lists = sim.contacts();
    for (std::size_t i = 0; i < n; ++i) {
        for (unsigned j : lists.partners_of(i)) {
            if (j <= i) continue;
            const auto d = box.nearest_image(s.position(i) - s.position(j));
            if (double(sphere::norm(d)) < double(s.radius(i)) + double(s.radius(j))) ++pairs;
        }
        if (double(s.x[i].z) < double(s.radius(i))) ++walls;
        const sphere::vec3<double> v = sphere::vec_cast<double>(s.v_sync[i]);
        ke += 0.5 * double(s.mass[i]) * sphere::dot(v, v);
    }
    return {2.0 * double(pairs) / double(n), walls, ke / (double(n) * mgd)};
}

/// The particles of tile[0] x tile[1] copies of the periodic bed, in the file's order or
/// shuffled (the order of the copies' indices is freed on return: it is not the simulation's).
template <class Real>
std::vector<sphere::particle<Real>> bed_particles(const options& o, const bed_file& b)
{
    const std::size_t per_tile = b.x.size(), tx = o.tile[0], ty = o.tile[1];
    std::vector<std::size_t> order(per_tile * tx * ty);
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    if (o.order == "shuffled") std::shuffle(order.begin(), order.end(), std::mt19937(12345));
    std::vector<sphere::particle<Real>> ps(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
        const std::size_t i = order[k] % per_tile, t = order[k] / per_tile;
        const double dx = double(t % tx) * b.length, dy = double(t / tx) * b.length;
        ps[k].position = {Real(b.x[i] + dx), Real(b.y[i] + dy), Real(b.z[i])};
        ps[k].radius = Real(b.r[i]);
        ps[k].density = Real(density);
    }
    return ps;
}

template <class Precision>
int run(const options& o, const bed_file& b)
{
    using namespace sphere;
    using Real = coord_t<Precision>; // the user-facing type: double for mixed
    settings<Real> s;
    s.box.lo = {0, 0, 0};
    const unsigned tx = o.tile[0], ty = o.tile[1];
    s.box.hi = {Real(b.length * tx), Real(b.length * ty), Real(b.top)};
    s.box.axis[0] = s.box.axis[1] = boundary::periodic;
    s.contact = {Real(k_n), Real(k_t), Real(gamma_n), Real(gamma_t), Real(mu), Real(mu), true};
    s.contact.damping = damping_convention::mass_scaled;
    s.wall = {Real(k_n), Real(k_t), Real(gamma_n_wall), Real(gamma_t_wall), Real(mu), Real(mu), true};
    s.wall.damping = damping_convention::mass_scaled;
    s.gravity = {0, 0, Real(-gravity)};
    s.dt = Real(dt);
    s.skin = Real(skin);
    s.pair_summation = o.summation == "gather" ? pair_summation::gather
                       : o.summation == "slabs" ? pair_summation::slabs : pair_summation::automatic;
    s.contact_forces = o.audit; // the scenario reads neither the contact forces nor the dissipation
    s.energy_audit = o.audit;
    s.angular_position = false; // nor the rotation angles
    s.accumulated_displacement = false; // nor the displacements

    const double rss_program = status_bytes("VmRSS"); // the program and the input file, before any particle
    std::vector<particle<Real>> ps = bed_particles<Real>(o, b);

    using law = contact::linear<tangential::elastic_viscous_frictional, tangential::elastic_viscous_frictional>;
    simulation<Precision, policy, law, integrate::velocity_verlet> sim(s, std::move(ps)); // no second copy
    const std::size_t n = sim.size();
    sim.run(o.pre);
    if (o.rebuild) { // the floor stays where it is, but the lists are rebuilt at the next step
        sim.set_wall_position(4, 0.0);
        sim.step();
    }
    // the simulation's own memory: measured before the counts make host copies
    const double rss_sim = status_bytes("VmRSS"), peak_sim = status_bytes("VmHWM");
    const counts c0 = count(sim);
    const std::size_t rebuilds0 = sim.rebuilds(), near0 = sim.near_walks();
    const auto t0 = std::chrono::steady_clock::now();
    sim.run(o.steps);
    const auto t1 = std::chrono::steady_clock::now();
    const counts c1 = count(sim);
    const double seconds = std::chrono::duration<double>(t1 - t0).count();
    const std::string where = on_host ? "threads=" + std::to_string(o.threads) : "backend=cuda";
    std::printf("sphere   N=%zu %s precision=%s order=%s loop=%.3f s  %.3e particle-steps/s  contacts "
                "%.4f -> %.4f  wall %zu -> %zu  KE/(N m g d) %.2e -> %.2e  rebuilds %zu  near walks %zu\n",
                n, where.c_str(), o.precision.c_str(), o.order.c_str(), seconds, double(n) * double(o.steps) / seconds,
                c0.pair_contacts_per_particle, c1.pair_contacts_per_particle, c0.wall_contacts, c1.wall_contacts,
                c0.kinetic, c1.kinetic, sim.rebuilds() - rebuilds0, sim.near_walks() - near0);
    if (on_host) // the CUDA backend's particles are not in the resident set
        std::printf("memory   N=%zu precision=%s  RSS of the program and input %.0f MB; after %zu steps %.0f MB: "
                    "simulation +%.0f B/particle; peak %.0f B/particle for the whole process (set-up, particle "
                    "descriptions and rebuilds included)\n",
                    n, o.precision.c_str(), rss_program / 1e6, o.pre, rss_sim / 1e6,
                    (rss_sim - rss_program) / double(n), peak_sim / double(n));
    return 0;
}

} // namespace

int main(int argc, char** argv)
{
    options o;
    CLI::App app{"Dense-bed benchmark (../shared/bench/bed): counts and particle-steps per second"};
    app.add_option("--csv", o.csv, "bed_N.csv (unpacked from ../shared/bench/bed/data)")->required();
    app.add_option("--precision", o.precision, "double, float or mixed")->check(CLI::IsMember({"double", "float", "mixed"}));
    app.add_option("--threads", o.threads, "OpenMP threads")->check(CLI::Range(1, 256));
    app.add_option("--order", o.order, "hand the particles over in the file's order or shuffled")
        ->check(CLI::IsMember({"file", "shuffled"}));
    app.add_flag("--audit", o.audit, "record the contact forces and book the energy audit (as the defaults do)");
    app.add_flag("--rebuild", o.rebuild, "rebuild the contact lists once after the untimed steps (peak memory of a rebuild)");
    app.add_option("--summation", o.summation, "the pair sums' schedule: automatic (the backend's), slabs or gather")
        ->check(CLI::IsMember({"automatic", "slabs", "gather"}));
    app.add_option("--pre", o.pre, "untimed steps before the first count");
    app.add_option("--steps", o.steps, "timed steps");
    app.add_option("--tile", o.tile, "copies of the periodic bed along x and y (e.g. 4 5: 1e6 particles from 50k)")
        ->expected(2)
        ->check(CLI::Range(1u, 100u));
    CLI11_PARSE(app, argc, argv);
    try {
        omp_set_num_threads(o.threads);
        const bed_file b = read_bed(o.csv);
        if (o.precision == "float") return run<float>(o, b);
        return o.precision == "mixed" ? run<sphere::mixed>(o, b) : run<double>(o, b);
    } catch (const std::exception& e) {
        std::cerr << "bed: " << e.what() << "\n";
        return 1;
    }
}
