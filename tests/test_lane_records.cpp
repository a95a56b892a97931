// Records of eight floats moved into and out of the host tiles' lanes (exec/lane_records.cuh),
// and the row walk in lanes (contact/separation_lanes.cuh): each function against the
// value-by-value loop it replaces, to the bit. The simulations' tests cover their use (in
// float and mixed the slab schedule's sums are these records, in double and mixed its walk is
// in lanes: test_determinism compares them with the gather schedule, which uses neither).
#include <catch2/catch.hpp>

#include <sphere/dem.cuh>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_lane_records {

#ifdef SPHERE_LANE_RECORDS

namespace {

constexpr int width = 64; // four registers of lanes

/// Values of many magnitudes and both signs, with zeros of both signs among them.
float any_value(std::mt19937& rng)
{
    std::uniform_real_distribution<float> mantissa(-1.0f, 1.0f);
    std::uniform_int_distribution<int> exponent(-30, 30), pick(0, 15);
    const int k = pick(rng);
    if (k == 0) return 0.0f;
    if (k == 1) return -0.0f;
    return std::ldexp(mantissa(rng), exponent(rng));
}

template <class T>
bool same_bits(T a, T b)
{
    return std::memcmp(&a, &b, sizeof a) == 0;
}

} // namespace

TEST_CASE("records move into lanes value by value", "[lane_records]")
{
    std::mt19937 rng(7);
    const int n = 101;
    std::vector<sphere::record8> records(n);
    std::vector<sphere::vec3<float>> triples(n);
    for (int i = 0; i < n; ++i) {
        for (float& v : records[i].value) v = any_value(rng);
        triples[i] = {any_value(rng), any_value(rng), any_value(rng)};
    }
    std::uniform_int_distribution<unsigned> slot(0, n - 1);
    unsigned index[width];
    for (unsigned& k : index) k = slot(rng);
    index[5] = index[4] = n - 1; // a repeated index, and the last record

    alignas(64) float lanes[8][width];
    sphere::lanes::gather_records(records.data(), index, lanes);
    int wrong = 0;
    for (int k = 0; k < width; ++k)
        for (int f = 0; f < 8; ++f) wrong += !same_bits(lanes[f][k], records[index[k]].value[f]);
    CHECK(wrong == 0);

    alignas(64) float coordinates[3][width];
    sphere::lanes::gather_vec3(triples.data(), index, coordinates);
    wrong = 0;
    for (int k = 0; k < width; ++k) {
        const sphere::vec3<float>& t = triples[index[k]];
        wrong += !same_bits(coordinates[0][k], t.x) + !same_bits(coordinates[1][k], t.y) +
                 !same_bits(coordinates[2][k], t.z);
    }
    CHECK(wrong == 0);

    sphere::record8 packed;
    sphere::lanes::pack(packed, triples[3], records[3].value[0], triples[8]);
    const float expected[8] = {triples[3].x, triples[3].y, triples[3].z, records[3].value[0],
                               triples[8].x, triples[8].y, triples[8].z, 0.0f};
    wrong = 0;
    for (int f = 0; f < 8; ++f) wrong += !same_bits(packed.value[f], expected[f]);
    CHECK(wrong == 0);
}

TEST_CASE("pair shares added as records are the scalar sums' bits, in lane order", "[lane_records]")
{
    std::mt19937 rng(11);
    const int n = 23; // few particles: owners repeat in runs and partners recur, as in a tile
    std::vector<sphere::record8> sums(n);
    for (auto& s : sums) {
        for (float& v : s.value) v = any_value(rng);
        s.value[6] = s.value[7] = 0.0f;
    }
    std::vector<sphere::record8> reference = sums;

    alignas(64) float fx[width], fy[width], fz[width], tix[width], tiy[width], tiz[width], tjx[width], tjy[width],
        tjz[width];
    float* fields[9] = {fx, fy, fz, tix, tiy, tiz, tjx, tjy, tjz};
    for (float* f : fields)
        for (int k = 0; k < width; ++k) f[k] = any_value(rng);
    unsigned owner[width], partner[width];
    std::uniform_int_distribution<unsigned> slot(0, n - 1);
    unsigned i = slot(rng);
    for (int k = 0; k < width; ++k) {
        if (k % 3 == 0) i = slot(rng); // runs of one owner
        owner[k] = i;
        do partner[k] = slot(rng);
        while (partner[k] == i);
    }
    const int count = 45; // not a whole number of registers: the lanes after it are not added

    sphere::lanes::add_pair_shares(sums.data(), owner, partner, {fx, fy, fz}, {tix, tiy, tiz}, {tjx, tjy, tjz}, count);
    // the slab schedule's loop before the records: force[i] += f, force[j] -= f, torque[i] += t_i, torque[j] += t_j
    for (int k = 0; k < count; ++k) {
        float* a = reference[owner[k]].value;
        float* b = reference[partner[k]].value;
        const float f[3] = {fx[k], fy[k], fz[k]};
        for (int c = 0; c < 3; ++c) a[c] += f[c];
        for (int c = 0; c < 3; ++c) b[c] -= f[c];
        a[3] += tix[k], a[4] += tiy[k], a[5] += tiz[k];
        b[3] += tjx[k], b[4] += tjy[k], b[5] += tjz[k];
    }
    int wrong = 0;
    for (int p = 0; p < n; ++p)
        for (int v = 0; v < 8; ++v) wrong += !same_bits(sums[p].value[v], reference[p].value[v]);
    CHECK(wrong == 0);
}

namespace {

/// A law that acts up to `gap` apart (as a liquid bridge does), and one that acts in contact.
struct bridge_law {
    static constexpr bool acts_apart = true;
    template <class Params>
    static double range(const Params& p)
    {
        return p.gap;
    }
};
struct contact_law {};
struct gap_params {
    double gap;
};

/// Rows of 0 to 17 entries of random partners among particles in a box periodic in x and y
/// (many near its faces, some at the same place as the owner, some rows ending with wall
/// codes), one after the other, walked by lanes::separate_rows (blocks of eight entries across
/// rows) and by separate<Law> entry by entry: the same lanes, apart entries and counts, to the
/// bit, across tile flushes.
template <class Law, class Real>
void check_row_walk(const gap_params& params, std::uint32_t seed)
{
    std::mt19937 rng(seed);
    sphere::world<double> box;
    box.lo = {-0.01, 0.0, 0.0};
    box.hi = {0.04, 0.05, 0.03};
    box.axis[0] = box.axis[1] = sphere::boundary::periodic;
    constexpr int n = 300;
    std::vector<sphere::vec4<double>> x(n);
    std::uniform_real_distribution<double> unit(0.0, 1.0), radius(0.0009, 0.0011);
    for (auto& p : x) {
        for (int a = 0; a < 3; ++a) {
            // a third of the coordinates within two diameters of a face
            const double u = unit(rng), l = box.hi[a] - box.lo[a];
            const double f = u < 1.0 / 6 ? u * 0.0024 / l * 6 : (u > 5.0 / 6 ? 1 - (1 - u) * 0.0024 / l * 6 : u);
            (a == 0 ? p.x : a == 1 ? p.y : p.z) = box.lo[a] + f * l;
        }
        p.w = radius(rng);
    }
    // rows of random owners; partners near their owners, so that many pairs touch or nearly do
    std::vector<unsigned> partner, owner_of_row, row{0};
    std::vector<std::uint8_t> flags;
    std::uniform_int_distribution<int> length(0, 17), walls(0, 3), any(0, n - 1), flag(0, 255);
    for (int r = 0; r < 1500; ++r) {
        const unsigned i = unsigned(any(rng));
        owner_of_row.push_back(i);
        const int len = length(rng) < 3 ? 0 : length(rng), wall_count = walls(rng) == 0 ? 2 : 0;
        for (int k = 0; k < len; ++k) {
            const unsigned j = unsigned(any(rng));
            if (k % 3 != 0) { // place j touching i (its image across a face, where i lies near one)
                const double gap = (unit(rng) - 0.7) * 0.0003, reach = x[i].w + x[j].w + gap;
                sphere::vec3<double> dir{unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5};
                dir = dir * (reach / sphere::norm(dir));
                x[j] = {box.wrap(x[i].x + dir.x, 0), box.wrap(x[i].y + dir.y, 1), x[i].z + dir.z, x[j].w};
            }
            if (k == 4) x[j] = {x[i].x, x[i].y, x[i].z, x[j].w}; // coincident centres: never a pair
            partner.push_back(j);
            flags.push_back(std::uint8_t(flag(rng)));
        }
        for (int f = 0; f < wall_count; ++f) {
            partner.push_back(sphere::wall_partner_base + unsigned(f));
            flags.push_back(0);
        }
        row.push_back(unsigned(partner.size()));
    }
    const unsigned rows = unsigned(owner_of_row.size());

    // the reference: entry by entry, as the scalar walk fills the tile
    constexpr bool wide = !std::is_same_v<Real, double>;
    std::vector<unsigned> ref_entry, ref_apart;
    std::vector<Real> ref_values;
    for (unsigned r = 0; r < rows; ++r) {
        const unsigned i = owner_of_row[r];
        for (unsigned e = row[r]; e < row[r + 1]; ++e) {
            const unsigned j = partner[e];
            if (j >= sphere::wall_partner_base) break;
            sphere::detail::pair_separation<Real> s;
            if (sphere::detail::separate<Law, true>(params, box, x[i], x[j], s)) {
                ref_entry.insert(ref_entry.end(), {i, j, e});
                ref_values.insert(ref_values.end(), {Real(flags[e]), s.d.x, s.d.y, s.d.z, s.r_i, s.r_j});
                if (wide) ref_values.push_back(s.excess);
            } else ref_apart.push_back(e);
        }
    }

    // the lanes, emptied as the slab schedule flushes them, in two calls (a task's ranges)
    using tile = sphere::detail::pair_tile<Real, 0>;
    tile t;
    std::vector<unsigned> apart(tile::width + tile::overflow), got_entry, got_apart;
    std::vector<Real> got_values;
    int apart_count = 0;
    const auto take_tile = [&](int count) {
        for (int k = 0; k < count; ++k) {
            got_entry.insert(got_entry.end(), {t.owner[k], t.partner[k], t.entry[k]});
            got_values.insert(got_values.end(), {t.hw[k], t.dx[k], t.dy[k], t.dz[k], t.r_i[k], t.r_j[k]});
            if (wide) got_values.push_back(t.excess[k]);
        }
    };
    const auto after_block = [&] {
        if (apart_count >= tile::width) {
            got_apart.insert(got_apart.end(), apart.begin(), apart.begin() + apart_count);
            apart_count = 0;
        }
        if (t.count >= tile::width) {
            take_tile(tile::width);
            const int over = t.count - tile::width;
            for (int k = 0; k < over; ++k) {
                const int from = tile::width + k;
                t.owner[k] = t.owner[from], t.partner[k] = t.partner[from], t.entry[k] = t.entry[from];
                t.hw[k] = t.hw[from], t.dx[k] = t.dx[from], t.dy[k] = t.dy[from], t.dz[k] = t.dz[from];
                t.r_i[k] = t.r_i[from], t.r_j[k] = t.r_j[from], t.excess[k] = t.excess[from];
            }
            t.count = over;
        }
    };
    const auto slot_of = [&](unsigned r) { return owner_of_row[r]; };
    for (const auto& [first, end] : {std::pair<unsigned, unsigned>{0, rows / 3}, {rows / 3, rows}})
        sphere::lanes::separate_rows<Law, wide>(params, box, x.data(), partner.data(), flags.data(), row.data(), first,
                                                end, slot_of, t, apart.data(), apart_count, after_block);
    take_tile(t.count);
    got_apart.insert(got_apart.end(), apart.begin(), apart.begin() + apart_count);
    // both outcomes are common, and the lists are long enough to flush several tiles
    CHECK(ref_entry.size() / 3 > std::size_t(2 * tile::width));
    CHECK(ref_apart.size() > std::size_t(2 * tile::width));
    CHECK(got_entry == ref_entry);
    CHECK(got_apart == ref_apart);
    REQUIRE(got_values.size() == ref_values.size());
    int wrong = 0;
    for (std::size_t k = 0; k < ref_values.size(); ++k) wrong += !same_bits(got_values[k], ref_values[k]);
    CHECK(wrong == 0);
}

} // namespace

TEST_CASE("the row walk in lanes gives the scalar walk's lanes to the bit", "[lane_records]")
{
    STATIC_REQUIRE(sphere::row_walk_in_lanes<double>);
    STATIC_REQUIRE(!sphere::row_walk_in_lanes<float>);
    SECTION("double") { check_row_walk<contact_law, double>({0.0}, 11); }
    SECTION("mixed") { check_row_walk<contact_law, float>({0.0}, 12); }
    SECTION("a law that acts apart, mixed") { check_row_walk<bridge_law, float>({0.0002}, 13); }
}

#else

TEST_CASE("without AVX-512 the tiles move values one by one", "[lane_records]")
{
    // exec/lane_records.cuh defines its functions only for AVX-512; the slab schedule then
    // keeps the sums in force and torque in every precision
    STATIC_REQUIRE(!sphere::lane_records_native);
    STATIC_REQUIRE(!sphere::detail::sums_in_records<float>);
    STATIC_REQUIRE(!sphere::row_walk_in_lanes<double>);
}

#endif

} // namespace test_lane_records
