// Host and CUDA run the same scene and must agree (part of the CUDA test binary, tests.cu).
//
// What may differ, and so the tolerances. Both backends sum the pair forces by the gather
// schedule (settings.pair_summation; the host's default is slabs), so each particle adds the
// same contacts in the same order, and the grid and the contact lists are built alike (stable
// sorts on both). The arithmetic is not bit-identical: nvcc contracts a * b + c into fused
// multiply-adds in device code (the host code is compiled with -ffp-contract=off), which rounds
// such expressions differently by up to half an ulp, and the diagnostics' reductions
// (energy()) associate differently (CUB's tree against the host's fixed chunks). Collisions
// amplify a difference step by step: measured on the host, this scene compiled with the CPU's
// FMAs (-ffp-contract=fast) against without differs after 1000 steps by 6e-13 of the mean
// radius in position, 2e-13 of the largest speed and 3e-13 of the largest spin; after 2000
// steps by 6e-12, 2e-11 and 4e-11; after 4000 steps by 0.15 of the radius: ~100-fold more per
// 1000 steps, until some contact starts a step earlier on one side. So: 1000 steps, and 1e-9
// relative (of the mean radius for positions, of the largest speed and spin for velocities, of
// the energy turned over for the energy budget), over 1000 times the CPU measurement because
// nvcc fuses other expressions than g++. The integer results must be equal: rebuilds, contact
// lists and contacts in touch (a contact could begin in one and not the other only at a gap
// within ~1e-15 m of zero at the end of a step).
#include <catch2/catch.hpp>

#include "../support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <utility>
#include <vector>

namespace {

/// 343 spheres (radii 3-4 mm) on a jittered 7^3 lattice with gaps of about 1-3 mm, with random
/// velocities (0.5 m/s rms per axis), in support.hpp's damped, frictional closed box with
/// gravity, its stiffness lowered to k_n = 1e3 N/m (dt = 4e-5 s): they collide with each other
/// and the walls from the first steps and settle; with a 1 mm skin the lists are rebuilt
/// every ~11 steps.
std::pair<sphere::settings<double>, std::vector<sphere::particle<double>>> backend_scene()
{
    sphere::settings<double> s = sphere_test::frictional_box<double>(0.0335);
    s.contact.k_n = s.wall.k_n = 1e3;
    s.contact.k_t = s.wall.k_t = 1e3 * 2 / 7;
    s.skin = 1e-3;
    s.pair_summation = sphere::pair_summation::gather; // CUDA's schedule, on both
    std::mt19937 gen(5);
    std::uniform_real_distribution<double> u(-1, 1);
    std::normal_distribution<double> normal(0, 1);
    const double spacing = 0.009;
    std::vector<sphere::particle<double>> ps;
    for (int k = 0; k < 7; ++k)
        for (int j = 0; j < 7; ++j)
            for (int i = 0; i < 7; ++i) {
                sphere::particle<double> p;
                p.radius = 0.0035 + 0.0005 * u(gen);
                p.density = 2500;
                p.position = {(i - 3) * spacing + 2e-4 * u(gen), (j - 3) * spacing + 2e-4 * u(gen),
                              (k - 3) * spacing + 2e-4 * u(gen)};
                p.velocity = {0.5 * normal(gen), 0.5 * normal(gen), 0.5 * normal(gen)};
                ps.push_back(p);
            }
    return {s, ps};
}

/// The contact lists' entries (partners and walls), each particle's sorted: the comparison
/// asks for the same contacts, not the same order within a list.
std::vector<unsigned> sorted_entries(const sphere::contact_table<double>& t)
{
    std::vector<unsigned> out = t.partner;
    for (std::size_t i = 0; i < t.particles(); ++i) std::sort(out.begin() + t.begin(i), out.begin() + t.end(i));
    return out;
}

/// The largest |a_i - b_i|.
double largest_difference(const std::vector<sphere::vec3<double>>& a, const std::vector<sphere::vec3<double>>& b)
{
    double m = 0;
    for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, sphere::norm(a[i] - b[i]));
    return m;
}

/// The largest |a_i|.
double largest(const std::vector<sphere::vec3<double>>& a)
{
    double m = 0;
    for (const auto& v : a) m = std::max(m, sphere::norm(v));
    return m;
}

/// Particles that feel a contact force.
std::size_t touching(const sphere::particle_snapshot<double>& s)
{
    std::size_t n = 0;
    for (const double p : s.pressure) n += p > 0;
    return n;
}

} // namespace

TEST_CASE("host and CUDA agree on a colliding, settling bed to round-off", "[backends]")
{
    const auto [s, ps] = backend_scene();
    sphere::simulation<double, sphere::host> host(s, ps);
    sphere::simulation<double, sphere::cuda> cuda(s, ps);
    const std::size_t steps = 1000;
    host.run(steps);
    cuda.run(steps);

    const auto a = host.snapshot(), b = cuda.snapshot();
    std::vector<sphere::vec3<double>> xa(a.size()), xb(b.size());
    double radius = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        xa[i] = a.position(i);
        xb[i] = b.position(i);
        radius += a.radius(i) / double(a.size());
    }
    const double dx = largest_difference(xa, xb) / radius;
    const double dv = largest_difference(a.v, b.v) / largest(a.v);
    const double dw = largest_difference(a.omega, b.omega) / largest(a.omega);
    const auto ea = host.energy(), eb = cuda.energy();
    const double turned_over = ea.kinetic + ea.rotational + ea.elastic + ea.dissipated_visc + ea.dissipated_fric;
    const double de = std::abs(ea.total() - eb.total()) / turned_over;
    std::printf("host vs CUDA, double, %zu particles, %zu steps (%zu and %zu rebuilds, %zu and %zu particles in "
                "contact): largest difference in position %.1e of the mean radius, velocity %.1e of the largest, "
                "angular velocity %.1e of the largest, energy budget %.1e of the energy turned over (tolerance 1e-9)\n",
                a.size(), steps, host.rebuilds(), cuda.rebuilds(), touching(a), touching(b), dx, dv, dw, de);

    REQUIRE(host.rebuilds() >= 20); // the scene rebuilds again and again (31 times on 2026-12-04),
    REQUIRE(touching(a) > 20);     // and its particles touch
    CHECK(host.rebuilds() == cuda.rebuilds());
    CHECK(touching(a) == touching(b));
    const auto ca = host.contacts(), cb = cuda.contacts();
    CHECK(ca.offset == cb.offset);
    CHECK(sorted_entries(ca) == sorted_entries(cb));
    CHECK(dx <= 1e-9);
    CHECK(dv <= 1e-9);
    CHECK(dw <= 1e-9);
    CHECK(de <= 1e-9);
}
