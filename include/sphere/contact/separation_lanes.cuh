#pragma once
/// \file
/// The row walk of the host's slab schedule (contact/interact.cuh) eight entries at a time in
/// AVX-512 lanes, for positions in double (precisions double and mixed): the partners'
/// positions are loaded as four registers of eight values, separated from the owner's and
/// tested as separate<Law, false> does (contact/evaluate.cuh), and the touching pairs are
/// compressed into the tile's next lanes, the others' entries into the list of pairs apart. A
/// row of 3-4 entries then costs one block of vector instructions instead of a scalar loop
/// whose exit and counters stall on every entry (docs/performance.md, *The row walk in lanes*).
#include <cstdint>
#include <type_traits>

#include "../boundary/world.cuh"
#include "../core/vec.cuh"
#include "../exec/lane_records.cuh"
#include "contact_lists.cuh"
#include "law.cuh"

namespace sphere {

/// Whether the row walk runs in lanes: positions in double on a host compiled for AVX-512.
template <class Coord>
inline constexpr bool row_walk_in_lanes = std::is_same_v<Coord, double> && lane_records_native;

#ifdef SPHERE_LANE_RECORDS
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ < 13
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#define SPHERE_SEPARATION_LANES_PRAGMAS 1
#endif
namespace lanes {

/// Stores lanes `order[0], order[1], ...` of eight values (doubles, or int32 as Real) at `to`
/// as Real: the same rounding as Real(v) lane by lane. `order` holds lane numbers as int32
/// (float) or int64 (double); all eight lanes are written.
template <class Real>
struct lane_store;
template <>
struct lane_store<double> {
    using order_type = __m512i;
    static order_type order_of(__m256i lanes) { return _mm512_cvtepu32_epi64(lanes); }
    static void put(double* to, order_type order, __m512d v) { _mm512_storeu_pd(to, _mm512_permutexvar_pd(order, v)); }
    static void put(double* to, order_type order, __m256i v) { put(to, order, _mm512_cvtepi32_pd(v)); }
    static void put_all(double* to, double v) { _mm512_storeu_pd(to, _mm512_set1_pd(v)); }
};
template <>
struct lane_store<float> {
    using order_type = __m256i;
    static order_type order_of(__m256i lanes) { return lanes; }
    static void put(float* to, order_type order, __m512d v)
    {
        _mm256_storeu_ps(to, _mm256_permutexvar_ps(order, _mm512_cvtpd_ps(v)));
    }
    static void put(float* to, order_type order, __m256i v)
    {
        _mm256_storeu_ps(to, _mm256_permutexvar_ps(order, _mm256_cvtepi32_ps(v)));
    }
    static void put_all(float* to, double v) { _mm256_storeu_ps(to, _mm256_set1_ps(float(v))); }
};

/// The entries [e, e + n) (0 < n <= 8) of a row of owner i, at xi (centre, radius), whose
/// partners lie within no periodic face's reach (pair_contact::images_inside): each particle
/// partner j = partner[e'] is separated from i as separate<Law, false> does, the same bits;
/// wall codes (which end a near row) are skipped. A pair that the law acts on takes the tile's
/// next lane (owner, partner, entry, its sliding flag in hw, the separation d, r_i, r_j and,
/// with `Wide` (positions wider than Real), the excess); the entry of one it does not act on
/// goes to apart[apart_count++]. Both keep the entries' order. The tile's lane arrays and
/// `apart` hold 8 values past t.count and apart_count.
template <class Law, bool Wide, class Tile, class KernelParams>
SPHERE_HDI void separate_block(const KernelParams& params, const world<double>& box, const vec4<double>* x,
                               const unsigned* partner, const std::uint8_t* flags, unsigned i, const vec4<double>& xi,
                               unsigned e, int n, Tile& t, unsigned* apart, int& apart_count)
{
    using Real = std::remove_reference_t<decltype(t.dx[0])>;
    using store = lane_store<Real>;
    const __mmask8 in_row = _cvtu32_mask8((1u << n) - 1);
    const __m256i listed = _mm256_maskz_loadu_epi32(in_row, partner + e);
    const __mmask8 particle = _mm256_mask_cmplt_epu32_mask(in_row, listed, _mm256_set1_epi32(int(wall_partner_base)));
    // z[m]: the positions of lanes m (low half) and m + 4 (high half), read one by one (scalar
    // reads keep the shuffle unit free); lanes without a particle partner read the owner's own
    // position, and are dropped
    __m512d z[4];
    const auto position = [&](int k) {
        const unsigned listed_k = partner[e + (k < n ? k : n - 1)];
        return _mm256_loadu_pd(&x[listed_k < wall_partner_base ? listed_k : i].x);
    };
    for (int m = 0; m < 4; ++m) z[m] = _mm512_insertf64x4(_mm512_castpd256_pd512(position(m)), position(m + 4), 1);
    const __m512d low01 = _mm512_unpacklo_pd(z[0], z[1]), high01 = _mm512_unpackhi_pd(z[0], z[1]);
    const __m512d low23 = _mm512_unpacklo_pd(z[2], z[3]), high23 = _mm512_unpackhi_pd(z[2], z[3]);
    const __m512i first = _mm512_set_epi64(13, 12, 5, 4, 9, 8, 1, 0);
    const __m512i second = _mm512_set_epi64(15, 14, 7, 6, 11, 10, 3, 2);
    const __m512d xj = _mm512_permutex2var_pd(low01, first, low23);
    const __m512d yj = _mm512_permutex2var_pd(high01, first, high23);
    const __m512d zj = _mm512_permutex2var_pd(low01, second, low23);
    const __m512d rj = _mm512_permutex2var_pd(high01, second, high23);
    // as separate<Law, false>: d = x_i - x_j, dist2 = (dx dx + dy dy) + dz dz, reach = r_i + r_j
    __m512d d[3] = {_mm512_sub_pd(_mm512_set1_pd(xi.x), xj), _mm512_sub_pd(_mm512_set1_pd(xi.y), yj),
                    _mm512_sub_pd(_mm512_set1_pd(xi.z), zj)};
    for (int a = 0; a < 3; ++a) // the nearest image, as world::nearest_image_inside
            if (box.periodic(a)) {
                const double l = box.hi[a] - box.lo[a], half = l / 2;
                const __mmask8 above = _mm512_cmp_pd_mask(d[a], _mm512_set1_pd(half), _CMP_GT_OQ);
                const __mmask8 below = _mm512_cmp_pd_mask(d[a], _mm512_set1_pd(-half), _CMP_LT_OQ) & ~above;
                d[a] = _mm512_mask_sub_pd(d[a], above, d[a], _mm512_set1_pd(l));
                d[a] = _mm512_mask_add_pd(d[a], below, d[a], _mm512_set1_pd(l));
            }
    const __m512d dx = d[0], dy = d[1], dz = d[2];
    const __m512d dist2 = _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)), _mm512_mul_pd(dz, dz));
    const __m512d reach = _mm512_add_pd(_mm512_set1_pd(xi.w), rj);
    __m512d cut = reach;
    if constexpr (acts_apart<Law>::value) cut = _mm512_add_pd(reach, _mm512_set1_pd(law_range<Law, double>(params)));
    else (void)params;
    const __mmask8 acts = _mm512_mask_cmp_pd_mask(_mm512_cmp_pd_mask(dist2, _mm512_mul_pd(cut, cut), _CMP_LT_OQ), dist2,
                                                  _mm512_setzero_pd(), _CMP_GT_OQ) &
                          particle;
    const __mmask8 away = particle & ~acts;
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const __m256i entry = _mm256_add_epi32(_mm256_set1_epi32(int(e)), lane);
    // the acting lanes in order: one compression, then a permutation of each field
    const __m256i acting = _mm256_maskz_compress_epi32(acts, lane);
    const typename store::order_type order = store::order_of(acting);
    const int c = t.count;
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(t.owner + c), _mm256_set1_epi32(int(i)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(t.partner + c), _mm256_permutexvar_epi32(acting, listed));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(t.entry + c), _mm256_add_epi32(_mm256_set1_epi32(int(e)), acting));
    store::put(t.hw + c, order, _mm256_cvtepu8_epi32(_mm_maskz_loadu_epi8(in_row, flags + e)));
    store::put(t.dx + c, order, dx);
    store::put(t.dy + c, order, dy);
    store::put(t.dz + c, order, dz);
    store::put_all(t.r_i + c, xi.w);
    store::put(t.r_j + c, order, rj);
    if constexpr (Wide) store::put(t.excess + c, order, _mm512_sub_pd(dist2, _mm512_mul_pd(reach, reach)));
    t.count = c + __builtin_popcount(acts);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(apart + apart_count), _mm256_maskz_compress_epi32(away, entry));
    apart_count += __builtin_popcount(away);
}

} // namespace lanes
#ifdef SPHERE_SEPARATION_LANES_PRAGMAS
#pragma GCC diagnostic pop
#undef SPHERE_SEPARATION_LANES_PRAGMAS
#endif
#endif

} // namespace sphere
