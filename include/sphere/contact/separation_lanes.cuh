#pragma once
/// \file
/// The row walk of the host's slab schedule (contact/interact.cuh) in AVX-512 lanes, for
/// positions in double (precisions double and mixed): eight consecutive entries at a time,
/// whatever rows they belong to, their partners' positions loaded as four registers of eight
/// values, separated from their owners' and tested as separate<Law> does (contact/evaluate.cuh),
/// the acting pairs moved into the tile's next lanes and the other entries into the list of
/// pairs apart. The bed's rows of 3-4 entries then cost less than half a block each, instead of
/// a scalar loop whose exit and counters stall on every entry (docs/performance.md, *The row
/// walk in lanes*).
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
};

/// The owners of eight lanes: their slots, and their centres and radii.
struct lane_owners {
    __m256i slot;
    __m512d x, y, z, r;
};

/// Owner i, at xi, in every lane.
inline lane_owners owner_everywhere(unsigned i, const vec4<double>& xi)
{
    return {_mm256_set1_epi32(int(i)), _mm512_set1_pd(xi.x), _mm512_set1_pd(xi.y), _mm512_set1_pd(xi.z),
            _mm512_set1_pd(xi.w)};
}

/// Owner i, at xi, in lanes [first, 8) of o.
inline void set_owner(lane_owners& o, int first, unsigned i, const vec4<double>& xi)
{
    const lane_owners b = owner_everywhere(i, xi);
    const __mmask8 lanes = _cvtu32_mask8(0xFFu << first);
    o.slot = _mm256_mask_blend_epi32(lanes, o.slot, b.slot);
    o.x = _mm512_mask_blend_pd(lanes, o.x, b.x);
    o.y = _mm512_mask_blend_pd(lanes, o.y, b.y);
    o.z = _mm512_mask_blend_pd(lanes, o.z, b.z);
    o.r = _mm512_mask_blend_pd(lanes, o.r, b.r);
}

/// The entries [e, e + n) (0 < n <= 8), lane k holding entry e + k of a row of owner
/// o[k]: each particle partner j = partner[e + k] is separated from its owner as
/// separate<Law> does (the nearest image), the same bits; wall codes (which end a near row)
/// are skipped. A pair that the law acts on takes the tile's next lane (owner, partner, entry,
/// its sliding flag in hw, the separation d, r_i, r_j and, with `Wide` (positions wider than
/// Real), the excess); the entry of one it does not act on goes to apart[apart_count++]. Both
/// keep the entries' order. The tile's lane arrays and `apart` hold 8 values past t.count and
/// apart_count.
template <class Law, bool Wide, class Tile, class KernelParams>
SPHERE_HDI void separate_block(const KernelParams& params, const world<double>& box, const vec4<double>* x,
                               const unsigned* partner, const std::uint8_t* flags, const lane_owners& o, unsigned e,
                               int n, Tile& t, unsigned* apart, int& apart_count)
{
    using Real = std::remove_reference_t<decltype(t.dx[0])>;
    using store = lane_store<Real>;
    const __mmask8 listed_lanes = _cvtu32_mask8((1u << n) - 1);
    const __m256i listed = _mm256_maskz_loadu_epi32(listed_lanes, partner + e);
    const __mmask8 particle =
        _mm256_mask_cmplt_epu32_mask(listed_lanes, listed, _mm256_set1_epi32(int(wall_partner_base)));
    // lanes without a particle partner read their owner's position, and are dropped
    const __m256i j = _mm256_mask_blend_epi32(particle, o.slot, listed);
    alignas(32) unsigned slot[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(slot), j);
    // z[m]: the positions of lanes m (low half) and m + 4 (high half)
    __m512d z[4];
    for (int m = 0; m < 4; ++m)
        z[m] = _mm512_insertf64x4(_mm512_castpd256_pd512(_mm256_loadu_pd(&x[slot[m]].x)), _mm256_loadu_pd(&x[slot[m + 4]].x), 1);
    const __m512d low01 = _mm512_unpacklo_pd(z[0], z[1]), high01 = _mm512_unpackhi_pd(z[0], z[1]);
    const __m512d low23 = _mm512_unpacklo_pd(z[2], z[3]), high23 = _mm512_unpackhi_pd(z[2], z[3]);
    const __m512i first = _mm512_set_epi64(13, 12, 5, 4, 9, 8, 1, 0);
    const __m512i second = _mm512_set_epi64(15, 14, 7, 6, 11, 10, 3, 2);
    const __m512d xj = _mm512_permutex2var_pd(low01, first, low23);
    const __m512d yj = _mm512_permutex2var_pd(high01, first, high23);
    const __m512d zj = _mm512_permutex2var_pd(low01, second, low23);
    const __m512d rj = _mm512_permutex2var_pd(high01, second, high23);
    // as separate<Law>: d = x_i - x_j at the nearest image (world::nearest_image_inside),
    // dist2 = (dx dx + dy dy) + dz dz, reach = r_i + r_j
    __m512d d[3] = {_mm512_sub_pd(o.x, xj), _mm512_sub_pd(o.y, yj), _mm512_sub_pd(o.z, zj)};
    for (int a = 0; a < 3; ++a)
        if (box.periodic(a)) {
            const double l = box.hi[a] - box.lo[a], half = l / 2;
            const __mmask8 above = _mm512_cmp_pd_mask(d[a], _mm512_set1_pd(half), _CMP_GT_OQ);
            const __mmask8 below = _mm512_cmp_pd_mask(d[a], _mm512_set1_pd(-half), _CMP_LT_OQ) & ~above;
            d[a] = _mm512_mask_sub_pd(d[a], above, d[a], _mm512_set1_pd(l));
            d[a] = _mm512_mask_add_pd(d[a], below, d[a], _mm512_set1_pd(l));
        }
    const __m512d dist2 =
        _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(d[0], d[0]), _mm512_mul_pd(d[1], d[1])), _mm512_mul_pd(d[2], d[2]));
    const __m512d reach = _mm512_add_pd(o.r, rj);
    __m512d cut = reach;
    if constexpr (acts_apart<Law>::value) cut = _mm512_add_pd(reach, _mm512_set1_pd(law_range<Law, double>(params)));
    else (void)params;
    const __mmask8 acts = _mm512_mask_cmp_pd_mask(_mm512_cmp_pd_mask(dist2, _mm512_mul_pd(cut, cut), _CMP_LT_OQ), dist2,
                                                  _mm512_setzero_pd(), _CMP_GT_OQ) &
                          particle;
    const __mmask8 away = particle & ~acts;
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    // the acting lanes in order: one compression, then a permutation of each field
    const __m256i acting = _mm256_maskz_compress_epi32(acts, lane);
    const typename store::order_type order = store::order_of(acting);
    const int c = t.count;
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(t.owner + c), _mm256_permutexvar_epi32(acting, o.slot));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(t.partner + c), _mm256_permutexvar_epi32(acting, listed));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(t.entry + c), _mm256_add_epi32(_mm256_set1_epi32(int(e)), acting));
    store::put(t.hw + c, order, _mm256_cvtepu8_epi32(_mm_maskz_loadu_epi8(listed_lanes, flags + e)));
    store::put(t.dx + c, order, d[0]);
    store::put(t.dy + c, order, d[1]);
    store::put(t.dz + c, order, d[2]);
    store::put(t.r_i + c, order, o.r);
    store::put(t.r_j + c, order, rj);
    if constexpr (Wide) store::put(t.excess + c, order, _mm512_sub_pd(dist2, _mm512_mul_pd(reach, reach)));
    t.count = c + __builtin_popcount(acts);
    const __m256i entry = _mm256_add_epi32(_mm256_set1_epi32(int(e)), lane);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(apart + apart_count), _mm256_maskz_compress_epi32(away, entry));
    apart_count += __builtin_popcount(away);
}

/// The rows of ranks [first_rank, end_rank), row r holding the entries [row[r], row[r + 1])
/// (one after the other) of owner slot_of(r), eight entries at a time whatever rows they
/// belong to (separate_block), then `after_block()` (which flushes what is full).
template <class Law, bool Wide, class Tile, class KernelParams, class SlotOf, class AfterBlock>
SPHERE_HDI void separate_rows(const KernelParams& params, const world<double>& box, const vec4<double>* x,
                              const unsigned* partner, const std::uint8_t* flags, const unsigned* row,
                              unsigned first_rank, unsigned end_rank, const SlotOf& slot_of, Tile& t, unsigned* apart,
                              int& apart_count, const AfterBlock& after_block)
{
    unsigned r = first_rank;
    for (unsigned e = row[first_rank], end = row[end_rank]; e < end; e += 8) {
        const int n = end - e < 8 ? int(end - e) : 8;
        while (row[r + 1] <= e) ++r; // the row of entry e
        unsigned i = slot_of(r);
        lane_owners owners = owner_everywhere(i, x[i]);
        while (row[r + 1] < e + n) { // rows that begin inside the block
            ++r;
            i = slot_of(r);
            set_owner(owners, int(row[r] - e), i, x[i]);
        }
        separate_block<Law, Wide>(params, box, x, partner, flags, owners, e, n, t, apart, apart_count);
        after_block();
    }
}

} // namespace lanes
#ifdef SPHERE_SEPARATION_LANES_PRAGMAS
#pragma GCC diagnostic pop
#undef SPHERE_SEPARATION_LANES_PRAGMAS
#endif
#endif

} // namespace sphere
