// Records of eight floats moved into and out of the host tiles' lanes (exec/lane_records.cuh):
// each function against the value-by-value loop it replaces, to the bit. The simulations'
// tests cover their use (in float and mixed the slab schedule's sums are these records:
// test_determinism compares them with the gather schedule, which does not use them).
#include <catch2/catch.hpp>

#include <sphere/dem.cuh>

#include <cstring>
#include <random>
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

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

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

#else

TEST_CASE("without AVX-512 the tiles move values one by one", "[lane_records]")
{
    // exec/lane_records.cuh defines its functions only for AVX-512; the slab schedule then
    // keeps the sums in force and torque in every precision
    STATIC_REQUIRE(!sphere::lane_records_native);
    STATIC_REQUIRE(!sphere::detail::sums_in_records<float>);
}

#endif

} // namespace test_lane_records
