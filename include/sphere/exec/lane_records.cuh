#pragma once
/// \file
/// Records of eight floats (32 B, one 256-bit register) moved between per-particle arrays and
/// the lanes of the host's SIMD tiles by AVX-512 shuffles, where a loop the compiler vectorises
/// would load or add each value on its own: 16 lanes' records take 16 loads and 32 shuffles
/// for their 128 values instead of 128 loads and 128 inserts
/// (docs/performance.md, *Records in float*). They exist only where the host compiler targets
/// AVX-512 (`lane_records_native`, SPHERE_LANE_RECORDS); elsewhere the tiles move value by
/// value (contact/interact.cuh).
#include "../core/vec.cuh"

#if defined(__AVX512F__) && defined(__AVX512BW__) && defined(__AVX512DQ__) && defined(__AVX512VL__) && \
    !defined(__CUDA_ARCH__)
#define SPHERE_LANE_RECORDS 1
#include <immintrin.h>
#endif

namespace sphere {

/// Eight floats, aligned as one 256-bit register.
struct alignas(32) record8 {
    float value[8];
};

#ifdef SPHERE_LANE_RECORDS
inline constexpr bool lane_records_native = true;
#else
inline constexpr bool lane_records_native = false;
#endif

#ifdef SPHERE_LANE_RECORDS
// g++ 12's AVX-512 intrinsics leave a result's unused operand uninitialised on purpose and then
// warn about it where they are inlined (GCC bug 105593, fixed in g++ 13).
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ < 13
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#define SPHERE_LANE_RECORDS_PRAGMAS 1
#endif
namespace lanes {

/// The lanes of a tile hold 16 floats per AVX-512 register: W (the tile's width) is a multiple.
inline constexpr int block = 16;

/// A 4x4 transposition inside each 128-bit lane q of four registers: position r of out[c]'s
/// lane q is position c of in[r]'s lane q.
inline void transpose_in_lanes(const __m512 (&in)[4], __m512 (&out)[4])
{
    const __m512 low01 = _mm512_unpacklo_ps(in[0], in[1]), high01 = _mm512_unpackhi_ps(in[0], in[1]);
    const __m512 low23 = _mm512_unpacklo_ps(in[2], in[3]), high23 = _mm512_unpackhi_ps(in[2], in[3]);
    out[0] = _mm512_shuffle_ps(low01, low23, 0x44);
    out[1] = _mm512_shuffle_ps(low01, low23, 0xEE);
    out[2] = _mm512_shuffle_ps(high01, high23, 0x44);
    out[3] = _mm512_shuffle_ps(high01, high23, 0xEE);
}

/// lanes[f][k] = records[index[k]].value[f] for f < 8 and k < W.
template <int W>
void gather_records(const record8* records, const unsigned* index, float (*lanes)[W])
{
    static_assert(W % block == 0, "a tile is whole registers of 16 lanes");
    for (int k0 = 0; k0 < W; k0 += block) {
        const unsigned* ix = index + k0;
        // z[h][m] holds the records of lanes 8 h + m and 8 h + m + 4, so that the
        // transposition below leaves lane k in position k of each field's register
        __m512 z[2][4];
        for (int m = 0; m < 8; ++m) {
            const int lo = m < 4 ? m : m + 4;
            z[m / 4][m % 4] = _mm512_insertf32x8(_mm512_castps256_ps512(_mm256_load_ps(records[ix[lo]].value)),
                                                 _mm256_load_ps(records[ix[lo + 4]].value), 1);
        }
        __m512 b[2][4]; // b[h][f]: value f (128-bit lanes 0, 2) and f + 4 (1, 3)
        transpose_in_lanes(z[0], b[0]);
        transpose_in_lanes(z[1], b[1]);
        for (int f = 0; f < 4; ++f) {
            _mm512_storeu_ps(&lanes[f][k0], _mm512_shuffle_f32x4(b[0][f], b[1][f], 0x88));
            _mm512_storeu_ps(&lanes[f + 4][k0], _mm512_shuffle_f32x4(b[0][f], b[1][f], 0xDD));
        }
    }
}

/// lanes[c][k] = coordinate c (x, y, z) of from[index[k]] for k < W.
template <int W>
void gather_vec3(const vec3<float>* from, const unsigned* index, float (*lanes)[W])
{
    static_assert(W % block == 0, "a tile is whole registers of 16 lanes");
    for (int k0 = 0; k0 < W; k0 += block) {
        const unsigned* ix = index + k0;
        __m512 z[4]; // z[m]: lanes m, m + 4, m + 8, m + 12, each x, y, z and a zero
        for (int m = 0; m < 4; ++m) {
            __m512 v = _mm512_castps128_ps512(_mm_maskz_loadu_ps(0x7, &from[ix[m]].x));
            v = _mm512_insertf32x4(v, _mm_maskz_loadu_ps(0x7, &from[ix[m + 4]].x), 1);
            v = _mm512_insertf32x4(v, _mm_maskz_loadu_ps(0x7, &from[ix[m + 8]].x), 2);
            z[m] = _mm512_insertf32x4(v, _mm_maskz_loadu_ps(0x7, &from[ix[m + 12]].x), 3);
        }
        __m512 xyz[4];
        transpose_in_lanes(z, xyz);
        for (int c = 0; c < 3; ++c) _mm512_storeu_ps(&lanes[c][k0], xyz[c]);
    }
}

/// Lanes [k0, k0 + 16) of six lane arrays (then two zeros) as 16 records, lane k0 + l in
/// out[l]; `negate`: the first three values negated.
inline void lanes_to_records(const float* const (&from)[6], int k0, bool negate, __m256 (&out)[block])
{
    __m512 v[2][4];
    for (int m = 0; m < 6; ++m) v[m / 4][m % 4] = _mm512_loadu_ps(from[m] + k0);
    if (negate) // by the sign bit, as unary minus: -0 stays distinct from 0
        for (int m = 0; m < 3; ++m) v[0][m] = _mm512_xor_ps(v[0][m], _mm512_set1_ps(-0.0f));
    v[1][2] = v[1][3] = _mm512_setzero_ps();
    __m512 c[2][4]; // c[h][r], 128-bit lane q: values 4 h .. 4 h + 3 of lane 4 q + r
    transpose_in_lanes(v[0], c[0]);
    transpose_in_lanes(v[1], c[1]);
    const __m512i first = _mm512_set_epi32(23, 22, 21, 20, 7, 6, 5, 4, 19, 18, 17, 16, 3, 2, 1, 0);
    const __m512i second = _mm512_set_epi32(31, 30, 29, 28, 15, 14, 13, 12, 27, 26, 25, 24, 11, 10, 9, 8);
    for (int r = 0; r < 4; ++r) {
        const __m512 lanes_r = _mm512_permutex2var_ps(c[0][r], first, c[1][r]);   // lanes r, r + 4
        const __m512 lanes_r8 = _mm512_permutex2var_ps(c[0][r], second, c[1][r]); // lanes r + 8, r + 12
        out[r] = _mm512_castps512_ps256(lanes_r);
        out[r + 4] = _mm512_extractf32x8_ps(lanes_r, 1);
        out[r + 8] = _mm512_castps512_ps256(lanes_r8);
        out[r + 12] = _mm512_extractf32x8_ps(lanes_r8, 1);
    }
}

/// The shares of `count` pairs added to both particles' sums, lane by lane in order: for lane
/// k, sums[first[k]] += (f, t_first) and then sums[second[k]] += (-f, t_second), each a
/// record (x, y, z of f, then of the torque, then two zeros) added value by value, so that
/// every sum is the same bits as with scalar additions in that order (a - b is a + (-b)).
/// The lane arrays hold at least `count` rounded up to 16 lanes.
inline void add_pair_shares(record8* sums, const unsigned* first, const unsigned* second, const float* const (&f)[3],
                            const float* const (&t_first)[3], const float* const (&t_second)[3], int count)
{
    const float* const of_first[6] = {f[0], f[1], f[2], t_first[0], t_first[1], t_first[2]};
    const float* const of_second[6] = {f[0], f[1], f[2], t_second[0], t_second[1], t_second[2]};
    for (int k0 = 0; k0 < count; k0 += block) {
        __m256 a[block], b[block];
        lanes_to_records(of_first, k0, false, a);
        lanes_to_records(of_second, k0, true, b);
        const int n = count - k0 < block ? count - k0 : block;
        for (int l = 0; l < n; ++l) {
            float* s = sums[first[k0 + l]].value;
            _mm256_store_ps(s, _mm256_add_ps(_mm256_load_ps(s), a[l]));
            s = sums[second[k0 + l]].value;
            _mm256_store_ps(s, _mm256_add_ps(_mm256_load_ps(s), b[l]));
        }
    }
}

/// out = (a.x, a.y, a.z, a_w, b.x, b.y, b.z, 0).
inline void pack(record8& out, const vec3<float>& a, float a_w, const vec3<float>& b)
{
    const __m128 low = _mm_insert_ps(_mm_maskz_loadu_ps(0x7, &a.x), _mm_set_ss(a_w), 0x30);
    const __m128 high = _mm_maskz_loadu_ps(0x7, &b.x);
    _mm256_store_ps(out.value, _mm256_insertf128_ps(_mm256_castps128_ps256(low), high, 1));
}

} // namespace lanes
#ifdef SPHERE_LANE_RECORDS_PRAGMAS
#pragma GCC diagnostic pop
#undef SPHERE_LANE_RECORDS_PRAGMAS
#endif
#endif

} // namespace sphere
