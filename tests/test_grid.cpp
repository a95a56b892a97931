// Neighbour grid and contact lists.
//
// 1. The lists built by the grid hold exactly the pairs of a brute-force O(N^2) search,
//    |x_i - x_j| < r_i + r_j + skin with the nearest periodic image, for 2400 polydisperse
//    particles at random (overlapping) positions, for walls on every axis, periodic x and
//    periodic x and y, with skin 0 and a positive skin.
// 2. A skin changes when the lists are rebuilt, never the physics: 400 steps of a dense,
//    frictional, damped polydisperse assembly with skin 0.2 r0 reproduce the skin-0 run, and
//    every pair that overlaps is listed in the step that evaluates it.
// 3. The tangential history of a contact is keyed by the partner's index: it survives
//    rebuilds that insert and remove other partners in front of it.
// 4. Reference positions (boundary/position_lattice.cuh): lattice points that encode to
//    themselves, within half a step of any position in the box, in the position's grid cell;
//    worlds the lattice cannot cover are refused; and the two margins they need (a pair that
//    touches is a near pair, a displacement counts the rounding) each fail without it.
#include <catch2/catch.hpp>

#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_grid {

namespace {

using sphere::boundary;
using sphere::vec3;

constexpr double r0 = 0.01; // mean particle radius (m)

/// 2400 particles, radii uniform in [0.5, 1.5] r0, uniform random centres in a 36 x 30 x 33 r0
/// box whose corner is not at the origin (solid fraction ~0.35, overlaps allowed). On wall
/// axes the centres lie in [lo, hi], a few exactly on lo or hi; on periodic axes a few lie
/// up to 0.4 r0 outside the box (the simulation wraps them) and many pairs straddle the
/// boundary.
template <class Real>
std::vector<sphere::particle<Real>> random_cloud(const sphere::world<Real>& box, std::uint32_t seed)
{
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const std::size_t n = 2400;
    std::vector<sphere::particle<Real>> ps(n);
    for (std::size_t i = 0; i < n; ++i) {
        sphere::particle<Real>& p = ps[i];
        p.radius = static_cast<Real>(r0 * (0.5 + unit(gen)));
        p.density = Real(2500);
        for (int a = 0; a < 3; ++a) {
            const double lo = box.lo[a], hi = box.hi[a];
            double c = lo + (hi - lo) * unit(gen);
            if (i % 97 == 0 && a == int(i / 97) % 3) c = (i / 97) % 2 == 0 ? lo : hi; // on a face
            if (i % 89 == 0 && box.periodic(a)) c = (i / 89) % 2 == 0 ? lo - 0.4 * r0 : hi + 0.3 * r0;
            p.position[a] = static_cast<Real>(c);
        }
        if (!box.periodic(0)) p.position.x = std::min(std::max(p.position.x, box.lo.x), box.hi.x);
        if (!box.periodic(1)) p.position.y = std::min(std::max(p.position.y, box.lo.y), box.hi.y);
        if (!box.periodic(2)) p.position.z = std::min(std::max(p.position.z, box.lo.z), box.hi.z);
    }
    return ps;
}

template <class Real>
sphere::world<Real> cloud_box(bool periodic_x, bool periodic_y)
{
    sphere::world<Real> w;
    w.lo = {Real(-0.13), Real(0.05), Real(-0.2)};
    w.hi = {w.lo.x + Real(36 * r0), w.lo.y + Real(30 * r0), w.lo.z + Real(33 * r0)};
    w.axis[0] = periodic_x ? boundary::periodic : boundary::wall;
    w.axis[1] = periodic_y ? boundary::periodic : boundary::wall;
    w.axis[2] = boundary::wall;
    return w;
}

/// The reference: every pair with |x_i - x_j| < r_i + r_j + skin, by an O(N^2) search in
/// double precision on the positions and radii the simulation holds (after wrapping), with
/// the nearest image d - L round(d / L) on periodic axes. Pairs whose squared distance lies
/// within a relative `band` of the squared reach are "ambiguous": the simulation compares in
/// Real, so round-off may put them on either side; they are kept apart and reported.
struct reference_pairs {
    std::vector<std::set<unsigned>> certain;   ///< per particle: partners surely within reach
    std::vector<std::set<unsigned>> ambiguous; ///< per particle: partners at the threshold
    std::size_t pairs = 0;                     ///< certain pairs (each counted once)
    std::size_t across_boundary = 0;           ///< certain pairs that touch through a periodic face
    std::size_t ambiguous_pairs = 0;
};

template <class Real>
reference_pairs brute_force(const sphere::particle_snapshot<Real>& s, const sphere::world<Real>& box, double skin,
                            double band)
{
    const std::size_t n = s.size();
    reference_pairs ref;
    ref.certain.resize(n);
    ref.ambiguous.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) {
            double d2 = 0;
            bool wrapped = false;
            for (int a = 0; a < 3; ++a) {
                double d = static_cast<double>(s.x[i].xyz()[a]) - static_cast<double>(s.x[j].xyz()[a]);
                if (box.periodic(a)) {
                    const double len = static_cast<double>(box.hi[a]) - static_cast<double>(box.lo[a]);
                    const double shift = len * std::round(d / len);
                    wrapped = wrapped || shift != 0;
                    d -= shift;
                }
                d2 += d * d;
            }
            const double reach = static_cast<double>(s.x[i].w) + static_cast<double>(s.x[j].w) + skin;
            const double q = d2 / (reach * reach) - 1;
            if (std::abs(q) <= band) {
                ref.ambiguous[i].insert(static_cast<unsigned>(j));
                ref.ambiguous[j].insert(static_cast<unsigned>(i));
                ++ref.ambiguous_pairs;
            } else if (q < 0) {
                ref.certain[i].insert(static_cast<unsigned>(j));
                ref.certain[j].insert(static_cast<unsigned>(i));
                ++ref.pairs;
                if (wrapped) ++ref.across_boundary;
            }
        }
    return ref;
}

/// Compares the simulation's contact lists with the reference; returns a description of every
/// discrepancy (empty when the lists are exact). Also checks the documented layout: entries of
/// particle i at [offset[i], offset[i + 1]), sorted by partner user index (walls last) with no
/// duplicates and no self-entry.
template <class Table>
std::vector<std::string> compare_lists(const Table& lists, const reference_pairs& ref)
{
    std::vector<std::string> bad;
    auto report = [&](std::size_t i, const std::string& what) {
        if (bad.size() < 20) {
            std::ostringstream o;
            o << "particle " << i << ": " << what;
            bad.push_back(o.str());
        } else if (bad.size() == 20) {
            bad.push_back("...");
        }
    };
    for (std::size_t i = 0; i < ref.certain.size(); ++i) {
        for (std::size_t e = lists.begin(i) + 1; e < lists.end(i); ++e)
            if (!(lists.partner[e - 1] < lists.partner[e]))
                report(i, "list not strictly ascending at entry " + std::to_string(e - lists.begin(i)));
        std::set<unsigned> listed;
        for (unsigned j : lists.partners_of(i)) {
            if (j == i) report(i, "lists itself");
            listed.insert(j);
        }
        for (unsigned j : ref.certain[i])
            if (!listed.count(j)) report(i, "misses partner " + std::to_string(j));
        for (unsigned j : listed)
            if (!ref.certain[i].count(j) && !ref.ambiguous[i].count(j))
                report(i, "lists " + std::to_string(j) + ", which is out of reach");
    }
    return bad;
}

} // namespace

TEMPLATE_TEST_CASE("contact lists hold exactly the brute-force pairs within r_i + r_j + skin", "[grid][contacts]",
                   float, double)
{
    using Real = TestType;
    // Pairs within this relative distance of the threshold (in squared distance) may fall
    // either way in Real arithmetic: a few ulps of Real (float 6e-8, double 1e-16), with
    // a wide margin. With random positions none is expected (~1e-3 pairs for float).
    const double band = std::is_same<Real, float>::value ? 1e-5 : 1e-12;

    struct layout {
        const char* name;
        bool periodic_x, periodic_y;
    };
    const layout layouts[] = {{"walls on every axis", false, false},
                              {"periodic x", true, false},
                              {"periodic x and y", true, true}};
    struct search {
        const char* name;
        double skin;      // (m)
        double cell_size; // (m), 0 = automatic
    };
    // The grid's slow axis is x (the most cells, the first of equals): 12, 10, 7 and 3 layers,
    // so the pair ownership across the periodic face (contact/contact_lists.cuh) is seen with
    // even and odd layer counts and with the fewest a periodic axis allows.
    const search searches[] = {{"skin 0", 0.0, 0.0},
                               {"skin 0.3 r0", 0.3 * r0, 0.0},
                               {"skin 0.3 r0, cells 1.5x wider than needed", 0.3 * r0, 1.5 * (3 * r0 + 0.3 * r0)},
                               {"skin 0.3 r0, cells 9.9 r0 wide (three per axis)", 0.3 * r0, 9.9 * r0}};

    std::uint32_t seed = 20240601;
    for (const layout& l : layouts)
        for (const search& q : searches) {
            ++seed;
            DYNAMIC_SECTION(l.name << ", " << q.name)
            {
                sphere::settings<Real> s = sphere_test::box_settings<Real>();
                s.box = cloud_box<Real>(l.periodic_x, l.periodic_y);
                s.skin = static_cast<Real>(q.skin);
                s.cell_size = static_cast<Real>(q.cell_size);
                // the cloud overlaps at random (walls included): it tests the search, not physics
                s.max_initial_overlap = std::numeric_limits<Real>::infinity();
                sphere::simulation<Real> sim(s, random_cloud<Real>(s.box, seed));

                const sphere::particle_snapshot<Real> snap = sim.snapshot();
                // Wrapped positions: every coordinate on a periodic axis lies in [lo, hi),
                // up to the round-off of the wrap (hi - (hi - lo) may differ from lo by an ulp;
                // the tolerance is 4 ulps of the largest coordinate).
                for (std::size_t i = 0; i < snap.size(); ++i)
                    for (int a = 0; a < 3; ++a)
                        if (s.box.periodic(a)) {
                            const Real ulps = 4 * std::numeric_limits<Real>::epsilon() *
                                              std::max(std::abs(s.box.lo[a]), std::abs(s.box.hi[a]));
                            REQUIRE(snap.x[i].xyz()[a] >= s.box.lo[a] - ulps);
                            REQUIRE(snap.x[i].xyz()[a] < s.box.hi[a]);
                        }

                const reference_pairs ref = brute_force(snap, s.box, static_cast<double>(s.skin), band);
                INFO("reference: " << ref.pairs << " pairs, " << ref.across_boundary
                                   << " through a periodic face, " << ref.ambiguous_pairs << " at the threshold");
                // The case exercises what it claims: thousands of pairs, many of them across
                // the periodic faces when there are any.
                REQUIRE(ref.pairs > 2000);
                if (l.periodic_x) REQUIRE(ref.across_boundary > 50);
                else REQUIRE(ref.across_boundary == 0);

                const std::vector<std::string> bad = compare_lists(sim.contacts(), ref);
                std::ostringstream msg;
                for (const std::string& b : bad) msg << b << '\n';
                INFO(msg.str());
                REQUIRE(bad.empty());

                // The counts equal the reference's partner counts.
                const sphere::contact_table<Real> table = sim.contacts();
                std::vector<std::size_t> count(snap.size());
                for (std::size_t i = 0; i < snap.size(); ++i) count[i] = table.partners_of(i).size();
                std::size_t listed = 0, miscounted = 0;
                for (std::size_t i = 0; i < snap.size(); ++i) {
                    listed += count[i];
                    if (count[i] < ref.certain[i].size() ||
                        count[i] > ref.certain[i].size() + ref.ambiguous[i].size())
                        ++miscounted;
                }
                CHECK(miscounted == 0);
                CHECK(listed >= 2 * ref.pairs);
                CHECK(listed <= 2 * (ref.pairs + ref.ambiguous_pairs));
                CHECK(sim.rebuilds() == 1);
            }
        }
}

namespace {

/// A dense polydisperse assembly: 2000 particles, radii uniform in [0.5, 1.5] r0, placed by
/// random sequential addition (largest first, no overlaps, clear of the walls) in a closed
/// cube of side 30 r0 (solid fraction 0.39), with random velocities N(0, 1 m/s) and angular
/// velocities N(0, 100 rad/s), under gravity. Particle indices are shuffled, so that index
/// and position are unrelated and the grid must reorder.
template <class Real>
std::pair<sphere::settings<Real>, std::vector<sphere::particle<Real>>> dense_assembly(std::uint32_t seed)
{
    const std::size_t n = 2000;
    const double half = 15 * r0;
    sphere::settings<Real> s = sphere_test::frictional_box<Real>(half);

    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::vector<double> radii(n);
    for (double& r : radii) r = r0 * (0.5 + unit(gen));
    std::sort(radii.rbegin(), radii.rend());

    // Random sequential addition with a cell list of 3 r0 cells (the largest diameter).
    const int cells = static_cast<int>(2 * half / (3 * r0));
    const double width = 2 * half / cells;
    std::vector<std::vector<std::size_t>> cell(static_cast<std::size_t>(cells * cells * cells));
    std::vector<vec3<double>> centre;
    auto cell_coord = [&](double c) { return std::min(cells - 1, std::max(0, static_cast<int>((c + half) / width))); };
    for (const double r : radii) {
        for (;;) {
            const vec3<double> c{-half + r + (2 * (half - r)) * unit(gen), -half + r + (2 * (half - r)) * unit(gen),
                                 -half + r + (2 * (half - r)) * unit(gen)};
            const int ix = cell_coord(c.x), iy = cell_coord(c.y), iz = cell_coord(c.z);
            bool free = true;
            for (int z = std::max(0, iz - 1); free && z <= std::min(cells - 1, iz + 1); ++z)
                for (int y = std::max(0, iy - 1); free && y <= std::min(cells - 1, iy + 1); ++y)
                    for (int x = std::max(0, ix - 1); free && x <= std::min(cells - 1, ix + 1); ++x)
                        for (std::size_t j : cell[static_cast<std::size_t>((z * cells + y) * cells + x)]) {
                            const vec3<double> d = c - centre[j];
                            const double reach = r + radii[j];
                            if (sphere::norm2(d) < reach * reach * 1.0001) {
                                free = false;
                                break;
                            }
                        }
            if (!free) continue;
            cell[static_cast<std::size_t>((iz * cells + iy) * cells + ix)].push_back(centre.size());
            centre.push_back(c);
            break;
        }
    }

    std::vector<sphere::particle<Real>> ps(n);
    for (std::size_t i = 0; i < n; ++i) {
        sphere::particle<Real>& p = ps[i];
        p.radius = static_cast<Real>(radii[i]);
        p.density = Real(2500);
        p.position = sphere::vec_cast<Real>(centre[i]);
        for (int a = 0; a < 3; ++a) {
            p.velocity[a] = static_cast<Real>(normal(gen));
            p.angular_velocity[a] = static_cast<Real>(100 * normal(gen));
        }
    }
    std::shuffle(ps.begin(), ps.end(), gen);
    return {s, ps};
}

/// Largest |a - b| over a field, relative to the largest |b| (0 when both are zero).
template <class V>
double max_rel_diff3(const std::vector<V>& a, const std::vector<V>& b)
{
    double diff = 0, scale = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            diff = std::max(diff, std::abs(static_cast<double>(a[i][c]) - static_cast<double>(b[i][c])));
            scale = std::max(scale, std::abs(static_cast<double>(b[i][c])));
        }
    return scale > 0 ? diff / scale : diff;
}

template <class T>
double max_rel_diff1(const std::vector<T>& a, const std::vector<T>& b)
{
    double diff = 0, scale = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        diff = std::max(diff, std::abs(static_cast<double>(a[i]) - static_cast<double>(b[i])));
        scale = std::max(scale, std::abs(static_cast<double>(b[i])));
    }
    return scale > 0 ? diff / scale : diff;
}

/// Pairs (i < j) that overlap, |x_i - x_j| < r_i + r_j, in double: an exhaustive search
/// over the pairs whose x coordinates differ by less than the largest diameter (sort and
/// sweep along x; no pair farther apart in x can overlap).
template <class Real>
std::vector<std::pair<unsigned, unsigned>> overlapping_pairs(const sphere::particle_snapshot<Real>& s)
{
    std::vector<unsigned> order(s.size());
    double largest = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        order[i] = static_cast<unsigned>(i);
        largest = std::max(largest, 2 * static_cast<double>(s.x[i].w));
    }
    std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) { return s.x[a].x < s.x[b].x; });
    std::vector<std::pair<unsigned, unsigned>> out;
    for (std::size_t u = 0; u < order.size(); ++u)
        for (std::size_t v = u + 1; v < order.size(); ++v) {
            const unsigned i = order[u], j = order[v];
            if (static_cast<double>(s.x[j].x) - static_cast<double>(s.x[i].x) > largest) break;
            double d2 = 0;
            for (int a = 0; a < 3; ++a) {
                const double d = static_cast<double>(s.x[i].xyz()[a]) - static_cast<double>(s.x[j].xyz()[a]);
                d2 += d * d;
            }
            const double reach = static_cast<double>(s.x[i].w) + static_cast<double>(s.x[j].w);
            if (d2 < reach * reach) out.emplace_back(std::min(i, j), std::max(i, j));
        }
    return out;
}

} // namespace

TEMPLATE_TEST_CASE("a skin skips rebuilds without changing the dynamics of a dense frictional assembly",
                   "[grid][contacts][history]", float, double)
{
    using Real = TestType;
    const std::size_t steps = 400;
    auto setup = dense_assembly<Real>(7);
    sphere::settings<Real> s0 = setup.first, s1 = setup.first;
    s0.skin = 0;
    s1.skin = static_cast<Real>(0.2 * r0);
    sphere::simulation<Real> no_skin(s0, setup.second);
    sphere::simulation<Real> skin(s1, setup.second);
    REQUIRE(no_skin.dt() == skin.dt());

    // Verlet-list safety, checked in the skin run at every step: every pair that overlaps
    // after step k is listed during step k + 1 (the lists read after step k + 1 are the
    // ones step k + 1 evaluated: lists are only rebuilt at the start of a step).
    std::vector<std::pair<unsigned, unsigned>> overlapping = overlapping_pairs(skin.snapshot());
    std::size_t missed = 0, checked = 0, max_overlapping = 0;
    for (std::size_t k = 0; k < steps; ++k) {
        no_skin.step();
        skin.step();
        const sphere::contact_table<Real> lists = skin.contacts();
        for (const auto& pr : overlapping) {
            ++checked;
            if (lists.find(pr.first, pr.second) == ~std::size_t(0) || lists.find(pr.second, pr.first) == ~std::size_t(0))
                ++missed;
        }
        overlapping = overlapping_pairs(skin.snapshot());
        max_overlapping = std::max(max_overlapping, overlapping.size());
    }
    INFO("rebuilds with skin 0: " << no_skin.rebuilds() << ", with skin 0.2 r0: " << skin.rebuilds() << " in "
                                  << steps << " steps; up to " << max_overlapping << " overlapping pairs");
    CHECK(missed == 0);
    CHECK(checked > 100000); // the assembly is in contact most of the time

    // Skin 0 rebuilds before every step but the first (the lists built at setup serve it);
    // the skin run rebuilds only when some particle moved more than skin / 2, here every
    // ~20-30 steps (the fastest particles move ~4 m/s, 0.1 r0 in ~30 steps of 8.6e-6 s).
    CHECK(no_skin.rebuilds() == steps);
    CHECK(skin.rebuilds() < steps / 4);
    CHECK(skin.rebuilds() > 3); // history was carried over more than once

    // Same physics. Listed partners that do not overlap contribute nothing, so both runs sum
    // the same forces, but in orders that follow the lists (each pair is owned by one of its
    // particles, by the grid layers and ranks at the rebuild: contact/contact_lists.cuh), which
    // the two runs rebuild at different steps: the sums round differently, and the dense
    // assembly amplifies the round-off over 400 steps. The bound is 1e-10 relative (of the
    // largest value of each field) in double; in float (eps 6e-8) the runs differ by up to
    // 2.4e-5 in the fields and 1.7e-4 in the tangential histories, and the bound is 1e-3. A
    // missed contact would change the forces of its particles by their own size.
    const double tol = std::is_same_v<Real, float> ? 1e-3 : 1e-10;
    const sphere::particle_snapshot<Real> a = skin.snapshot(), b = no_skin.snapshot();
    std::vector<vec3<Real>> xa(a.size()), xb(b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        xa[i] = a.position(i);
        xb[i] = b.position(i);
    }
    // Positions: relative to r0 (the box is centred on the origin, so coordinates themselves
    // pass through zero).
    double dx = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (int c = 0; c < 3; ++c) dx = std::max(dx, std::abs(double(xa[i][c]) - double(xb[i][c])) / r0);
    CHECK(dx <= tol);
    CHECK(max_rel_diff3(a.v, b.v) <= tol);
    CHECK(max_rel_diff3(a.omega, b.omega) <= tol);
    CHECK(max_rel_diff3(a.v_sync, b.v_sync) <= tol);
    CHECK(max_rel_diff3(a.omega_sync, b.omega_sync) <= tol);
    CHECK(max_rel_diff3(a.force, b.force) <= tol);
    CHECK(max_rel_diff3(a.torque, b.torque) <= tol);
    CHECK(max_rel_diff1(a.e_visc, b.e_visc) <= tol);
    CHECK(max_rel_diff1(a.e_fric, b.e_fric) <= tol);

    // The tangential histories of the overlapping pairs agree too (the skin run carried them
    // over ~15 rebuilds, the skin-0 run over 400), and there are plenty of them: sticking
    // and sliding contacts with non-zero tangential displacement.
    const sphere::contact_table<Real> t0 = no_skin.contacts(), t1 = skin.contacts();
    double hdiff = 0, hscale = 0;
    std::size_t sliding = 0, sticking = 0, unmatched = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        for (std::size_t e0 = t0.begin(i); e0 < t0.end(i); ++e0) {
            const std::size_t e1 = t1.find(i, t0.partner[e0]);
            if (e1 == ~std::size_t(0)) {
                ++unmatched;
                continue;
            }
            const sphere::vec4<Real> u = t0.history[e0], w = t1.history[e1];
            const double du[4] = {double(u.x) - w.x, double(u.y) - w.y, double(u.z) - w.z, double(u.w) - w.w};
            for (double d : du) hdiff = std::max(hdiff, std::abs(d));
            hscale = std::max({hscale, std::abs(double(u.x)), std::abs(double(u.y)), std::abs(double(u.z))});
            const bool moved = u.x != 0 || u.y != 0 || u.z != 0;
            if (moved && u.w != 0) ++sliding;
            if (moved && u.w == 0) ++sticking;
        }
    INFO("contacts: " << sticking << " sticking, " << sliding << " sliding; largest |delta_t| " << hscale << " m");
    CHECK(unmatched == 0); // every skin-0 partner (all within r_i + r_j) is in the skin lists
    CHECK(sliding > 100);
    CHECK(sticking > 100);
    CHECK(hdiff <= tol * hscale);
}

namespace {

/// Where `j` sits in particle i's list (its entry index k), or -1.
template <class Sim>
int entry_of(const Sim& sim, unsigned i, unsigned j)
{
    const auto t = sim.contacts();
    const std::size_t e = t.find(i, j);
    return e == ~std::size_t(0) ? -1 : static_cast<int>(e - t.begin(i));
}

} // namespace

TEMPLATE_TEST_CASE("the tangential history of a contact survives rebuilds that reorder its list",
                   "[grid][contacts][history]", float, double)
{
    using Real = TestType;
    using P = sphere_test::set_p<Real>;
    // A sliding pair with known kinematics: A (prescribed) sits at the origin and spins at
    // omega_z = w; B (fixed) touches it on +x with overlap delta = 1e-4 m. The contact point
    // of A moves at v_t = (r - delta / 2) w along +y relative to B, the normal overlap never
    // changes, so (docs/physics.md, "Tangential force"; VALIDATION D9):
    //   sticking (|k_t delta_t| < mu_s f_n): delta_t = n_steps dt v_t y_hat;
    //   sliding: delta_t = mu_d f_n / k_t y_hat (f_t = -k_t delta_t = -mu_d f_n y_hat), and
    //   B's entry holds the opposite displacement.
    // Meanwhile 10 other particles sweep through A's surface, entering and leaving A's list
    // in front of and behind the A-B entry, while the grid re-sorts them at every rebuild
    // (they cross cells). The A-B contact does not depend on them: its history must follow
    // the analytic values exactly as if nothing else were there.
    const Real r = P::radius;
    const double delta = 1e-4;
    const double w = 1.0; // rad/s: v_t = 0.00995 m/s

    sphere::settings<Real> s = sphere_test::box_settings<Real>(Real(0.1));
    s.contact.mu_s = Real(0.4);
    s.contact.mu_d = Real(0.3);
    s.wall.mu_s = Real(0.3);
    s.wall.mu_d = Real(0.3);
    s.max_initial_overlap = std::numeric_limits<Real>::infinity(); // prescribed passers cross each other

    // 10 prescribed passers sweep through A's surface along straight lines parallel to y
    // (even k) or z (odd k), at closest distances 0.012-0.0192 m from A's centre (A's contact
    // reach is 0.02 m), on the -x side, at staggered times and speeds, so that none, some or
    // all of them touch A at a time. All kinematics are prescribed: no force changes any motion.
    std::vector<sphere::particle<Real>> passers;
    for (int k = 0; k < 10; ++k) {
        const double rho = 0.012 + 0.0008 * k;             // closest distance to A's centre (m)
        const double theta = (-60.0 + 13.0 * k) * 3.14159265358979 / 180; // around the -x axis
        const double start = -0.03 - 0.002 * k;            // m along the line
        const double speed = 0.6 + 0.05 * k;               // m/s
        vec3<double> x{-rho * std::cos(theta), 0, 0}, v{0, 0, 0};
        if (k % 2 == 0) { x.z = rho * std::sin(theta); x.y = start; v.y = speed; }
        else { x.y = rho * std::sin(theta); x.z = start; v.z = speed; }
        sphere::particle<Real> p = sphere_test::ball<Real>(sphere::vec_cast<Real>(x), sphere::vec_cast<Real>(v));
        p.kind = sphere::motion::prescribed;
        passers.push_back(p);
    }
    sphere::particle<Real> a = sphere_test::ball<Real>({0, 0, 0});
    a.kind = sphere::motion::prescribed;
    a.angular_velocity = {0, 0, Real(w)};
    sphere::particle<Real> b = sphere_test::ball<Real>({static_cast<Real>(2 * r - delta), 0, 0});
    b.kind = sphere::motion::fixed;
    // Indices: passers 0-4, A = 5, B = 6, passers 7-11: passers enter the lists of A and B
    // both in front of and behind the A-B entry.
    std::vector<sphere::particle<Real>> ps(passers.begin(), passers.begin() + 5);
    const unsigned ia = 5, ib = 6;
    ps.push_back(a);
    ps.push_back(b);
    ps.insert(ps.end(), passers.begin() + 5, passers.end());

    SECTION("skin 0")
    {
        s.skin = 0;
    }
    SECTION("skin 0.5 r")
    {
        s.skin = Real(0.5) * r;
    }
    sphere::simulation<Real> sim(s, ps);

    // Expected values from the positions the simulation holds.
    const auto snap0 = sim.snapshot();
    const double dist_ab = static_cast<double>(snap0.x[ib].x) - static_cast<double>(snap0.x[ia].x);
    const double overlap = 2 * static_cast<double>(r) - dist_ab;
    const double fn = static_cast<double>(s.contact.k_n) * overlap;
    const double kt = static_cast<double>(s.contact.k_t);
    const double vt = (static_cast<double>(r) - overlap / 2) * w;
    const double dt = static_cast<double>(sim.dt());
    const double slip = static_cast<double>(s.contact.mu_s) * fn / kt; // 1.4e-4 m
    const std::size_t stick_steps = static_cast<std::size_t>(slip / (vt * dt)); // ~580
    const std::size_t steps = 2000;

    // Float: the displacement is a sum of ~500 float increments (relative error ~n eps/2
    // ~1e-5) and f_n depends on an overlap 1e-4 m resolved from coordinates 0.02 m
    // (float ulp 1.9e-9 m): 1e-4 relative. Double: 1e-9.
    const double tol = std::is_same<Real, float>::value ? 1e-4 : 1e-9;

    std::set<int> entries_of_b; // the entry index of B in A's list over the run
    std::size_t rebuilds_before = sim.rebuilds();
    std::size_t others_listed = 0, steps_with_others = 0;
    for (std::size_t n = 1; n <= steps; ++n) {
        sim.step();
        const int kb = entry_of(sim, ia, ib);
        REQUIRE(kb >= 0);
        entries_of_b.insert(kb);
        const std::size_t others = sim.contacts().partners_of(ia).size() - 1;
        others_listed = std::max(others_listed, others);
        if (others > 0) ++steps_with_others;
        const int ka = entry_of(sim, ib, ia);
        REQUIRE(ka >= 0);
        const auto t = sim.contacts();
        const sphere::vec4<Real> ha = t.history[t.begin(ia) + kb], hb = t.history[t.begin(ib) + ka];
        if (n + 20 < stick_steps) {
            // Sticking: delta_t = n dt v_t along +y on A, -y on B.
            const double expect = static_cast<double>(n) * dt * vt;
            INFO("step " << n << " (sticking)");
            REQUIRE(ha.w == 0);
            CHECK(sphere_test::rel_err(ha.y, expect) < tol);
            CHECK(sphere_test::rel_err(hb.y, -expect) < tol);
            CHECK(std::abs(double(ha.x)) < tol * expect);
            CHECK(std::abs(double(ha.z)) < tol * expect);
        } else if (n > stick_steps + 20) {
            // Sliding: delta_t = mu_d f_n / k_t along +y (VALIDATION pitfall 4).
            const double expect = static_cast<double>(s.contact.mu_d) * fn / kt;
            INFO("step " << n << " (sliding)");
            REQUIRE(ha.w == 1);
            REQUIRE(hb.w == 1);
            CHECK(sphere_test::rel_err(ha.y, expect) < tol);
            CHECK(sphere_test::rel_err(hb.y, -expect) < tol);
            CHECK(std::abs(double(ha.x)) < tol * expect);
            CHECK(std::abs(double(ha.z)) < tol * expect);
        }
    }
    INFO("rebuilds: " << sim.rebuilds() - rebuilds_before << "; entries of B in A's list: " << entries_of_b.size()
                      << "; up to " << others_listed << " other partners of A, in " << steps_with_others
                      << " steps; sticking for " << stick_steps << " steps");
    // The run did what it claims: many rebuilds (every step with skin 0; with the skin
    // whenever a passer has moved 0.25 r, i.e. every ~170 steps at the fastest 1.05 m/s),
    // and B's entry moved within A's list.
    CHECK(sim.rebuilds() - rebuilds_before >= (s.skin > 0 ? 10 : steps - 1));
    CHECK(entries_of_b.size() >= 3);
    CHECK(stick_steps > 300);
    CHECK(stick_steps + 200 < steps);
}

TEMPLATE_TEST_CASE("a particle given more than one period outside a periodic axis is wrapped or rejected",
                   "[grid][contacts][world]", float, double)
{
    // A centre given two periods outside a periodic axis must be wrapped fully into [lo, hi)
    // (or rejected), never left outside where the grid would clamp it and miss its contacts
    // (a wrap of one period did exactly that). Either answer below is correct.
    using Real = TestType;
    sphere::settings<Real> s = sphere_test::box_settings<Real>(); // [-0.1, 0.1]^3
    s.box.axis[0] = sphere::boundary::periodic;
    const Real L = s.box.hi.x - s.box.lo.x;
    // Particle 1 sits 0.019 m from particle 0 (radii 0.01: overlap 1 mm) through its image
    // two periods away.
    std::vector<sphere::particle<Real>> ps = {sphere_test::ball<Real>({0, 0, 0}),
                                              sphere_test::ball<Real>({Real(0.019) + 2 * L, 0, 0})};
    try {
        sphere::simulation<Real> sim(s, ps);
        const auto snap = sim.snapshot();
        CHECK(snap.x[1].x >= s.box.lo.x);
        CHECK(snap.x[1].x < s.box.hi.x);
        REQUIRE(sim.contacts().partners_of(0) == std::vector<unsigned>{1});
        sim.step();
        // The overlap pushes particle 0 towards -x: f = k_n 1e-3 m = 100 N.
        CHECK(sim.snapshot().force[0].x == Approx(-100).epsilon(1e-3));
    } catch (const sphere::error& e) {
        CHECK_THAT(e.what(), Catch::Contains("particle 1"));
    }
}

TEMPLATE_TEST_CASE("the grid numbers the axis with the most cells slowest", "[grid]", float, double)
{
    using Real = TestType;
    sphere::world<Real> box;
    box.lo = {0, 0, 0};
    SECTION("a bed periodic in x and y: x slowest, the wall axis z fastest")
    {
        box.hi = {Real(0.0552), Real(0.0552), Real(0.034)};
        box.axis[0] = box.axis[1] = boundary::periodic;
        const auto g = sphere::grid_geometry<Real>::make(box, Real(0.0026), Real(0));
        // 21 cells of at least 2.6 mm fit along x and y; the slow axis's count is rounded
        // down to a multiple of 4 (even shares of the slab schedule's phases)
        CHECK(g.n[0] == 20);
        CHECK(g.n[1] == 21);
        CHECK(g.n[2] == 13);
        CHECK(g.width[0] == Approx(0.0552 / 20));
        CHECK(g.slow == 0);
        CHECK(g.mid == 1);
        CHECK(g.fast == 2);
        CHECK(g.layers() == 20);
        CHECK(g.cells_per_layer() == 21 * 13);
        // a requested cell width is kept as it is
        const auto exact = sphere::grid_geometry<Real>::make(box, Real(0.0026), Real(0.0026));
        CHECK(exact.n[0] == 21);
        CHECK(exact.layers() == 21);
        // fewer than 16 cells are not rounded: a world of 15 x 10 cells keeps 15 along its
        // slow axis (rounded to a multiple of 4, it would hold 12)
        box.hi.x = Real(0.0026 * 15.5);
        box.hi.y = Real(0.0026 * 10.5);
        const auto small = sphere::grid_geometry<Real>::make(box, Real(0.0026), Real(0));
        CHECK(small.slow == 0);
        CHECK(small.n[0] == 15);
    }
    SECTION("a tall closed column: z slowest")
    {
        box.hi = {Real(0.01), Real(0.02), Real(0.1)};
        const auto g = sphere::grid_geometry<Real>::make(box, Real(0.001), Real(0));
        CHECK(g.slow == 2);
        CHECK(g.fast == 0);
        CHECK(g.mid == 1);
    }
    // Every cell gets a different number, and cells of one layer (one coordinate along the
    // slow axis) are numbered consecutively.
    box.hi = {Real(0.03), Real(0.05), Real(0.04)};
    box.axis[2] = boundary::periodic;
    const auto g = sphere::grid_geometry<Real>::make(box, Real(0.01), Real(0));
    REQUIRE(g.slow == 1);
    std::vector<int> seen(g.cell_count(), 0);
    for (int i = 0; i < int(g.n[0]); ++i)
        for (int j = 0; j < int(g.n[1]); ++j)
            for (int k = 0; k < int(g.n[2]); ++k) {
                const unsigned c = g.index(i, j, k);
                REQUIRE(c < g.cell_count());
                ++seen[c];
                CHECK(c / g.cells_per_layer() == unsigned(j));
            }
    CHECK(std::count(seen.begin(), seen.end(), 1) == std::ptrdiff_t(g.cell_count()));
}

TEST_CASE("the slab phases let no two tasks of a phase write the same layer", "[grid][summation]")
{
    // The owners of layer l write the particles of layers l and l + 1 (the next layer is the
    // first one after the last on a periodic axis). Within a phase the tasks run in parallel:
    // the layers they write must be disjoint, and every layer must be some task's owner once.
    for (unsigned layers = 1; layers <= 9; ++layers)
        for (bool periodic : {false, true}) {
            if (periodic && layers < 3) continue; // a periodic axis has at least 3 cells
            // uneven weights, and no entries at all in the first and last two layers (a bed in
            // a tall box): those layers' particles still need a thread
            std::vector<unsigned> entries(layers + 1, 0);
            for (unsigned l = 0; l < layers; ++l) {
                const bool empty = l == 0 || l + 2 >= layers;
                entries[l + 1] = entries[l] + (empty ? 0 : 10 + l);
            }
            const sphere::detail::slab_phases phases(entries, periodic);
            INFO(layers << " layers, periodic " << periodic);
            // The threads' blocks of layers partition all layers, in order.
            for (int threads = 1; threads <= 5; ++threads) {
                unsigned next = 0;
                for (int t = 0; t < threads; ++t) {
                    unsigned first, end;
                    phases.block(t, threads, first, end);
                    if (first >= end) continue;
                    CHECK(first == next);
                    next = end;
                }
                CHECK(next == layers);
            }
            std::vector<int> owned(layers, 0);
            for (int ph = 0; ph < 2; ++ph) {
                for (const auto& task : phases.phase[ph])
                    for (unsigned m = 0; m < task.layers; ++m) ++owned[task.layer[m]];
                // How many tasks of the phase write layer l: at most one.
                for (unsigned l = 0; l < layers; ++l) {
                    int tasks = 0;
                    for (const auto& task : phases.phase[ph]) {
                        bool writes = false;
                        for (unsigned m = 0; m < task.layers; ++m) {
                            const unsigned o = task.layer[m];
                            writes = writes || o == l || (o + 1 < layers ? o + 1 == l : periodic && l == 0);
                        }
                        tasks += writes;
                    }
                    CHECK(tasks <= 1);
                }
                // Each thread's share is a contiguous range, the shares cover the phase, and
                // each holds its part of the phase's entries to within one task's.
                double total = 0, largest = 0;
                for (const auto& task : phases.phase[ph]) {
                    total += phases.work(task);
                    largest = std::max(largest, phases.work(task));
                }
                for (int threads = 1; threads <= 5; ++threads) {
                    std::size_t next = 0;
                    for (int t = 0; t < threads; ++t) {
                        std::size_t first, end;
                        phases.share(ph, t, threads, first, end);
                        double mine = 0;
                        for (std::size_t k = first; k < end; ++k) mine += phases.work(phases.phase[ph][k]);
                        CHECK(std::abs(mine - total / threads) <= largest);
                        if (first >= end) continue;
                        CHECK(first == next);
                        next = end;
                    }
                    CHECK(next == phases.phase[ph].size());
                }
            }
            for (unsigned l = 0; l < layers; ++l) CHECK(owned[l] == 1);
        }
}

TEMPLATE_TEST_CASE("every cell's start is the number of particles in lower cells, also in a tall, mostly empty box, "
                   "and a cell's particles follow their user indices (their slots without)",
                   "[grid]", float, double)
{
    using Real = TestType;
    // A column 4 x 4 x 2000 cells of 1 mm with particles in its lowest 20 layers (a sample
    // settled in a tall box): cells above the last particle all start at n, and so do none
    // of the cells below it except the empty ones after the last occupied cell of a layer.
    sphere::world<Real> box;
    box.lo = {0, 0, 0};
    box.hi = {Real(0.004), Real(0.004), Real(2.0)};
    const auto g = sphere::grid_geometry<Real>::make(box, Real(0.001), Real(0));
    REQUIRE(g.cell_count() >= 4u * 4u * 1996u); // 1999 layers in float (rounded to 1996), 2000 in double
    std::size_t n = 0;
    SECTION("no particles") { n = 0; }
    SECTION("a settled sample") { n = 300; }
    std::mt19937 gen(12);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<sphere::vec4<Real>> x(n);
    std::vector<unsigned> user(n);
    for (std::size_t i = 0; i < n; ++i) {
        x[i] = {Real(0.004 * u(gen)), Real(0.004 * u(gen)), Real(0.02 * u(gen)), Real(2e-4)};
        user[i] = static_cast<unsigned>(n - 1 - i);
    }
    sphere::particle_view<Real> p{};
    p.n = n;
    p.x = x.data();
    p.user = user.data();
    sphere::neighbor_grid<Real, sphere::host> grid(g);
    sphere::execution_context<sphere::host> context;
    grid.build(context, p);
    const sphere::grid_view<Real> v = grid.view();

    std::vector<unsigned> below(g.cell_count() + 1, 0); // particles in cells lower than c
    for (std::size_t i = 0; i < n; ++i) ++below[g.cell_of(x[i].xyz()) + 1];
    for (std::size_t c = 1; c <= g.cell_count(); ++c) below[c] += below[c - 1];
    std::size_t wrong = 0;
    for (std::size_t c = 0; c <= g.cell_count(); ++c) wrong += v.cell_start[c] != below[c];
    CHECK(wrong == 0);
    CHECK(v.cell_start[g.cell_count()] == n);
    // The sorted positions follow the order; in a cell, the user indices rise (they fall with
    // the slots, so the order within a cell is the ties' and not the slots').
    std::size_t shared = 0; // pairs of particles in one cell
    for (std::size_t k = 0; k < n; ++k) {
        CHECK(v.sorted_x.x[k].z == x[v.order[k]].z);
        if (k == 0) continue;
        const unsigned before = g.cell_of(v.sorted_x.x[k - 1].xyz()), here = g.cell_of(v.sorted_x.x[k].xyz());
        CHECK(before <= here);
        if (before == here) {
            ++shared;
            CHECK(user[v.order[k - 1]] < user[v.order[k]]);
        }
    }
    CHECK((n == 0 || shared > 10));
    // Without user indices the ties go by slot.
    p.user = nullptr;
    grid.build(context, p);
    for (std::size_t k = 1; k < n; ++k)
        if (g.cell_of(x[v.order[k - 1]].xyz()) == g.cell_of(x[v.order[k]].xyz())) CHECK(v.order[k - 1] < v.order[k]);
    // One cell for the whole box (cells as wide as the box): the order is the user indices'
    // alone, n - 1 .. 0 down the slots.
    const auto one = sphere::grid_geometry<Real>::make(box, Real(0.001), Real(2.0));
    REQUIRE(one.cell_count() == 1u);
    p.user = user.data();
    sphere::neighbor_grid<Real, sphere::host> whole(one);
    whole.build(context, p);
    const sphere::grid_view<Real> w = whole.view();
    CHECK(w.cell_start[0] == 0);
    CHECK(w.cell_start[1] == n);
    std::size_t misplaced = 0;
    for (std::size_t k = 0; k < n; ++k) misplaced += w.order[k] != n - 1 - k;
    CHECK(misplaced == 0);
}

TEMPLATE_TEST_CASE("contact lists give histories to their near rows only, until a step must walk the far rows",
                   "[grid][contacts]", float, double)
{
    using Real = TestType;
    // Three spheres of radius 1 mm in a row on the floor of a box with walls: a touches b; c
    // lies 0.5 skin beyond b, within the skin but not within the near skin (an eighth of it),
    // so the lists hold a near pair {a, b}, the three floor contacts and a far pair {b, c}.
    // A resting bed never walks its far rows: their histories take no memory
    // (docs/architecture.md, *Near partners*) until a step must walk them.
    const Real r = Real(0.001), skin = Real(0.0004);
    sphere::world<Real> box;
    box.lo = {0, 0, 0};
    box.hi = {Real(0.01), Real(0.01), Real(0.01)};
    std::vector<sphere::vec4<Real>> x{{Real(0.003), Real(0.005), r, r},
                                      {Real(0.003) + 2 * r - Real(1e-6), Real(0.005), r, r},
                                      {Real(0.003) + 4 * r - Real(1e-6) + skin / 2, Real(0.005), r, r}};
    std::vector<unsigned> user{0, 1, 2};
    sphere::particle_view<Real> p{};
    p.n = x.size();
    p.x = x.data();
    p.user = user.data();
    sphere::neighbor_grid<Real, sphere::host> grid(sphere::grid_geometry<Real>::make(box, 2 * r + skin, Real(0)));
    sphere::execution_context<sphere::host> context;
    sphere::contact_lists<Real, sphere::host> lists(x.size(), false);
    const auto rebuild = [&] {
        grid.build(context, p);
        sphere::list_totals t;
        do lists.rebuild(context, grid.view(), sphere::wall_set<Real>::from_world(box), skin, skin / 8, true, &t);
        while (!lists.settle(t, false));
    };
    rebuild();
    CHECK(lists.entries() == 5);
    CHECK(lists.near_entries() == 4); // {a, b} and the floor's
    CHECK(lists.history_capacity() == 4);
    CHECK_FALSE(lists.far_histories());
    const unsigned far = lists.view().offset[x.size()]; // the first far row's entry
    CHECK_FALSE(lists.view().has_history(far));
    const sphere::contact_table<Real> table = lists.table(user);
    const std::size_t bc = table.find(1, 2);
    REQUIRE(bc != ~std::size_t(0)); // the far pair is listed, without a history
    CHECK(sphere::norm2(table.history[bc].xyz()) == 0);
    CHECK(table.history[bc].w == 0);

    CHECK(lists.open_far_rows());
    CHECK(lists.far_histories());
    CHECK(lists.history_capacity() >= 5);
    CHECK_FALSE(lists.open_far_rows()); // once per lists
    CHECK(lists.view().has_history(far));
    CHECK_FALSE(lists.view().history.has(far)); // opened clear

    rebuild(); // new lists: their far rows have no histories again; the arrays keep their size
    CHECK_FALSE(lists.far_histories());
    CHECK(lists.history_capacity() >= 5);
}

TEST_CASE("reference positions lie on a lattice whose points encode to themselves and which covers the world", "[grid]")
{
    struct box_case {
        const char* name;
        vec3<double> lo, hi;
    };
    const box_case boxes[] = {{"a unit box at the origin", {0, 0, 0}, {1, 1, 1}},
                              {"a box around the origin", {-0.2, -0.3, -0.1}, {0.2, 0.3, 0.5}},
                              {"a box far from the origin", {1000, -5e4, 7}, {1000.4, -4.9999e4, 7.001}},
                              {"a box whose lengths are powers of two", {0, 0, 0}, {0.25, 4, 1024}}};
    constexpr double last = 4294967295.0; // the last point's number of steps, 2^32 - 1
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> u(0, 1);
    for (const box_case& c : boxes)
        DYNAMIC_SECTION(c.name)
        {
            sphere::world<double> box;
            box.lo = c.lo;
            box.hi = c.hi;
            const sphere::position_lattice<double> l = sphere::position_lattice<double>::over(box);
            for (int a = 0; a < 3; ++a) {
                const double length = box.hi[a] - box.lo[a], step = l.step[a];
                int e = 0;
                CHECK(std::frexp(step, &e) == 0.5);  // a power of two
                CHECK(step * (last - 1) >= length);   // 2^32 - 2 steps span the box
                CHECK(step * (last - 1) < 2 * length); // and no coarser than that needs
                CHECK(l.origin[a] <= box.lo[a]);
                CHECK(l.origin[a] > box.lo[a] - step);
                CHECK(l.origin[a] + last * step >= box.hi[a]);
            }
            // Any position in the box: its point lies within half a step (and the round-off of
            // its distance to the origin) on each axis, and encodes to itself.
            std::size_t far = 0, moved = 0;
            for (int k = 0; k < 100000; ++k) {
                vec3<double> x;
                for (int a = 0; a < 3; ++a) x[a] = k == 0 ? box.lo[a] : (k == 1 ? box.hi[a] : box.lo[a] + u(rng) * (box.hi[a] - box.lo[a]));
                const sphere::lattice_point q = l.encode(x);
                const vec3<double> at = l.decode(q);
                for (int a = 0; a < 3; ++a)
                    if (std::fabs(at[a] - x[a]) > 0.5 * l.step[a] + 2 * std::numeric_limits<double>::epsilon() * std::fabs(x[a]))
                        ++far;
                const sphere::lattice_point back = l.encode(at);
                moved += back.x != q.x || back.y != q.y || back.z != q.z;
            }
            CHECK(far == 0);
            CHECK(moved == 0);
            // the lattice's ends and middle encode to themselves
            for (const std::uint32_t n : {0u, 1u, 2147483648u, 4294967294u, 4294967295u}) {
                const sphere::lattice_point back = l.encode(l.decode({n, n, n}));
                CHECK((back.x == n && back.y == n && back.z == n));
            }
            // positions beyond the lattice clamp to its ends, a NaN to its first point
            const vec3<double> length = box.hi - box.lo;
            const sphere::lattice_point below = l.encode(box.lo - length * 10.0), above = l.encode(box.hi + length * 10.0),
                                        nan = l.encode({std::nan(""), std::nan(""), std::nan("")});
            CHECK((below.x == 0u && below.y == 0u && below.z == 0u));
            CHECK((above.x == 4294967295u && above.y == 4294967295u && above.z == 4294967295u));
            CHECK((nan.x == 0u && nan.y == 0u && nan.z == 0u));
        }
    // float positions are stored as they are
    static_assert(std::is_same_v<sphere::position_lattice<float>::stored, vec3<float>>);
    const sphere::position_lattice<float> f = sphere::position_lattice<float>::over(sphere::world<float>{});
    const vec3<float> x{0.1f, 0.7f, 0.3f};
    CHECK(f.decode(f.encode(x)) == x);
}

TEST_CASE("a world that the reference positions' lattice cannot cover exactly is refused, with the axis", "[grid][errors]")
{
    sphere::world<double> flat;
    flat.hi = {1, 1, 1};
    flat.lo = {0, 1, 0};
    REQUIRE_THROWS_WITH(sphere::position_lattice<double>::over(flat),
                        Catch::Contains("the world's axis 1 from 1 to 1 m has no finite length"));
    // a millimetre at 10^9 m: its steps (2^-41 m) number about 2^71 from the origin
    sphere::world<double> far;
    far.lo = {0, 0, 1e9};
    far.hi = {1, 1, 1e9 + 1e-3};
    REQUIRE_THROWS_WITH(sphere::position_lattice<double>::over(far),
                        Catch::Contains("the world's axis 2 from 1000000000 to 1000000000.001 m lies too far from the origin"));
    // a simulation in such a world: 0.25 m at 10^9 m (steps of 2^-33 m, 2^63 of them from the origin)
    sphere::settings<double> s = sphere_test::box_settings<double>();
    s.box.lo.z = 1e9;
    s.box.hi.z = 1e9 + 0.25;
    REQUIRE_THROWS_WITH(sphere::simulation<double>(s, {sphere_test::ball<double>({0, 0, 1e9 + 0.125})}),
                        Catch::Contains("the world's axis 2 from 1000000000 to 1000000000.25 m lies too far from the origin"));
}

TEMPLATE_TEST_CASE("the positions of the last rebuild are lattice points near the particles", "[grid]", double,
                   sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    sphere::settings<Real> s = sphere_test::box_settings<Real>();
    s.box = cloud_box<Real>(true, false);
    s.skin = Real(0.3 * r0);
    s.max_initial_overlap = std::numeric_limits<Real>::infinity();
    sphere::simulation<P> sim(s, random_cloud<Real>(s.box, 7));
    const sphere::position_lattice<double> l = sphere::position_lattice<double>::over(s.box);
    const sphere::simulation_state<Real> st = sim.state();
    const sphere::particle_snapshot<Real> snap = sim.snapshot();
    std::size_t off_lattice = 0, far = 0;
    for (std::size_t i = 0; i < snap.size(); ++i) {
        const vec3<double> at = st.x_at_build[i].xyz();
        off_lattice += !(l.decode(l.encode(at)) == at);
        for (int a = 0; a < 3; ++a)
            far += std::fabs(at[a] - snap.x[i].xyz()[a]) > 0.5 * l.step[a] * (1 + 1e-6);
        CHECK(st.x_at_build[i].w == snap.x[i].w);
    }
    CHECK(off_lattice == 0);
    CHECK(far == 0);
}

TEMPLATE_TEST_CASE("a pair that touches at a rebuild is a near pair, also where its reference positions lie apart",
                   "[grid][contacts]", double, sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    sphere::settings<Real> s = sphere_test::box_settings<Real>();
    s.skin = 0; // every step rebuilds and walks the near rows alone
    s.max_initial_overlap = std::numeric_limits<Real>::infinity();
    const sphere::position_lattice<double> l = sphere::position_lattice<double>::over(s.box);
    const double step = l.step.x, apart = double(1 << 24); // 2^24 steps of 2^-34 m: about 1 mm
    // A 0.49 steps above a lattice point (its reference position rounds down), B 0.51 steps
    // above another (it rounds up), 1e-13 m closer than their radii: they touch, and their
    // reference positions lie 0.98 steps farther apart than the particles, beyond the radii.
    const vec3<double> o = l.decode({2147483648u, 2147483648u, 2147483648u});
    const vec3<double> a{o.x + 0.49 * step, o.y, o.z}, b{o.x + (apart + 0.51) * step, o.y, o.z};
    const double r = (b.x - a.x + 1e-13) / 2;
    REQUIRE(l.decode(l.encode(b)).x - l.decode(l.encode(a)).x > 2 * r);
    sphere::simulation<P> sim(s, {sphere_test::ball<Real>(a, {0, 0, 0}, Real(r)), sphere_test::ball<Real>(b, {0, 0, 0}, Real(r))});
    REQUIRE(sim.contacts().partners_of(0).size() == 1);
    // The steps after the first rebuild and walk the near rows alone: they find the contact
    // (without the near rows' margin its force was zero from the second step on).
    for (int k = 0; k < 3; ++k) sim.step();
    CHECK(sim.rebuilds() == 3);
    CHECK(sim.near_walks() == 2);
    const sphere::particle_snapshot<Real> snap = sim.snapshot();
    CHECK(snap.force[0].x < 0);
    CHECK(snap.force[1].x > 0);
}

TEST_CASE("reference positions place every particle in the grid cell of its position", "[grid]")
{
    sphere::world<double> box;
    box.lo = {-0.13, 0.05, -0.2};
    box.hi = {0.23, 0.35, 0.13};
    box.axis[0] = boundary::periodic;
    const sphere::grid_geometry<double> g = sphere::grid_geometry<double>::make(box, 0.031, 0);
    const sphere::position_lattice<double> l = sphere::position_lattice<double>::over(box);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0, 1);
    // positions a fraction of a step from a cell face (and at random elsewhere)
    const double offsets[] = {-1.5, -0.51, -0.49, -0.2, 0.0, 0.2, 0.49, 0.51, 1.5};
    std::size_t moved = 0, other_cell = 0, far = 0, tried = 0;
    for (int a = 0; a < 3; ++a)
        for (unsigned c = 1; c < g.n[a]; ++c)
            for (const double t : offsets) {
                vec3<double> x;
                for (int b = 0; b < 3; ++b) x[b] = box.lo[b] + u(rng) * (box.hi[b] - box.lo[b]);
                x[a] = box.lo[a] + c * g.width[a] + t * l.step[a];
                const sphere::lattice_point q = sphere::reference_in_cell(g, l, x), nearest = l.encode(x);
                const vec3<double> p = l.decode(q);
                ++tried;
                moved += q.x != nearest.x || q.y != nearest.y || q.z != nearest.z;
                other_cell += g.cell_of(p) != g.cell_of(x);
                for (int b = 0; b < 3; ++b) far += std::fabs(p[b] - x[b]) > l.step[b];
            }
    INFO(tried << " positions, " << moved << " a step back from the nearest point");
    CHECK(moved > 0); // the case is exercised: the nearest point of some lies across the face
    CHECK(other_cell == 0);
    CHECK(far == 0);
}

TEMPLATE_TEST_CASE("the particle check counts the reference positions' rounding as displacement", "[grid]", double,
                   sphere::mixed)
{
    using P = TestType;
    using Real = sphere_test::user_real<P>;
    sphere::settings<Real> s = sphere_test::box_settings<Real>();
    s.gravity = {0, 0, 0};
    const sphere::position_lattice<double> l = sphere::position_lattice<double>::over(s.box);
    // A skin of the rounding e: the particles rest, a displacement d from their reference
    // positions below e / 2, but from the positions of the rebuild up to d + e, more than e / 2:
    // the check cannot rule out a pair that came closer than the skin, and rebuilds every step.
    s.skin = Real(l.rounding());
    std::vector<sphere::particle<Real>> ps;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            ps.push_back(sphere_test::ball<Real>({Real(-0.05 + 0.031 * i + 1e-4 * j), Real(-0.05 + 0.029 * j), Real(0.01 * i)}));
    sphere::simulation<P> sim(s, ps);
    const sphere::simulation_state<Real> st = sim.state();
    double d = 0;
    for (std::size_t i = 0; i < ps.size(); ++i)
        d = std::max(d, norm(sphere_test::to_double(st.particles.position(i)) - st.x_at_build[i].xyz()));
    REQUIRE(2 * d < double(s.skin));
    for (int k = 0; k < 3; ++k) sim.step();
    const sphere::particle_snapshot<Real> snap = sim.snapshot();
    for (std::size_t i = 0; i < ps.size(); ++i) REQUIRE(snap.position(i) == ps[i].position); // at rest
    CHECK(sim.rebuilds() == 3); // the constructor's, then every step's check asks the next step for one
}

} // namespace test_grid
