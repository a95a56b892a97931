#pragma once
/// \file
/// The interaction: every listed pair contact evaluated once (contact/evaluate.cuh) and its
/// force and torques summed into both particles, by one of two schedules
/// (contact/summation.cuh). Each particle's sum follows an order fixed by the contact lists
/// (ranks and grid layers, contact/contact_lists.cuh), so results are bit-identical for any
/// thread count and storage order. Walls are evaluated afterwards, per particle, with the
/// integration (simulation.cuh).
#include <cstddef>
#include <type_traits>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "../core/error.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/collectives.cuh"
#include "../exec/context.cuh"
#include "../exec/for_each.cuh"
#include "../exec/host_team.cuh"
#include "../exec/lane_records.cuh"
#include "../exec/policy.cuh"
#include "contact_lists.cuh"
#include "evaluate.cuh"
#include "separation_lanes.cuh"
#include "summation.cuh"

namespace sphere {
namespace detail {

/// Whether the slab schedule keeps each particle's motion (v_sync, mass, omega_sync: stored_motion)
/// and its sums of force and torque as records of eight floats, which its tiles move as
/// vectors (exec/lane_records.cuh): a law in float on a host compiled for AVX-512. 64 B per
/// particle more (docs/performance.md, *Records in float*).
template <class Real>
inline constexpr bool sums_in_records = std::is_same_v<Real, float> && lane_records_native;

/// Zeroes what the pair sums accumulate into: force, torque and, with Book, the audit sums;
/// with sums_in_records, the sums' records instead of force and torque, and the motion's
/// records are written.
template <class P, bool Book>
struct zero_pair_sums {
    particle_view<P> p;
    record8* motion; ///< with sums_in_records
    record8* sums;   ///< with sums_in_records
    SPHERE_HDI void operator()(std::size_t i) const
    {
        using Real = real_t<P>;
        if constexpr (sums_in_records<Real>) {
#ifdef SPHERE_LANE_RECORDS
            lanes::pack(motion[i], p.v_sync[i], p.mass[i], p.omega_sync[i]);
            sums[i] = record8{};
#endif
        } else {
            p.force[i] = vec3<Real>{0, 0, 0};
            p.torque[i] = vec3<Real>{0, 0, 0};
        }
        if (Book) {
            p.pressure[i] = 0;
            p.p_visc[i] = 0;
            p.p_fric[i] = 0;
        }
    }
};

/// A tile of pair contacts evaluated together in SIMD lanes: lanes [0, count) hold pairs,
/// the rest repeat lane 0 and are discarded. The row walk fills in each pair's separation and
/// radii, which it has read to sort out pairs apart, so that the SIMD loop does not gather the
/// positions again. `Lanes`: the contact law's history lanes
/// (contact/history.cuh). With sums_in_records, the flush moves both particles' motion records
/// and the entries' tangential displacements into lanes before the SIMD loop.
template <class Real, unsigned Lanes>
struct pair_tile {
    /// 64 doubles or 128 floats: eight AVX-512 vectors. On the dense bed, tiles of eight
    /// vectors were 0-5% faster than tiles of two, and in mixed two were 7% faster than one
    /// (docs/performance.md).
    static constexpr int width = 512 / sizeof(Real);
    /// Lanes past width that the row walk in lanes may fill before the flush
    /// (contact/separation_lanes.cuh), which then moves them to the front.
    static constexpr int overflow = 8;
    int count = 0;
    unsigned owner[width + overflow], partner[width + overflow], entry[width + overflow];
    Real hw[width + overflow]; ///< the sliding flag, then the flags after the step
    Real dx[width + overflow], dy[width + overflow], dz[width + overflow]; ///< pair_separation
    Real r_i[width + overflow], r_j[width + overflow], excess[width + overflow];
    Real fx[width], fy[width], fz[width];
    Real tix[width], tiy[width], tiz[width], tjx[width], tjy[width], tjz[width];
    Real hx[width], hy[width], hz[width];
    Real hl[Lanes > 0 ? Lanes : 1][width];
    Real fn[width], visc[width], fric[width];
    Real rx[width], ry[width], rz[width], rw[width];
    static constexpr int record_width = sums_in_records<Real> ? width : 1;
    float motion_i[8][record_width], motion_j[8][record_width]; ///< motion records, value by value
    float shift[3][record_width];                               ///< tangential displacements
};

/// The pair sums of the host's slab schedule, for the owners of a range of ranks: pairs are
/// gathered into tiles in row order, evaluated lane-parallel, then added to both particles in
/// tile order (so each particle's sum has a fixed order), each owner's near row first, then
/// its far row. `near_only`: walk the near rows alone (contact/contact_lists.cuh; the caller
/// knows that the far partners are apart and without history, so the sums and histories are
/// the same bits either way).
template <class P, class Law, bool Book, bool Record, bool OneVelocity>
struct slab_pairs {
    using Real = real_t<P>;
    pair_contact<P, Law, OneVelocity> eval;
    contact_view<Real> c;
    const record8* motion; ///< with sums_in_records (zero_pair_sums)
    record8* sums;         ///< with sums_in_records
    bool update_history;
    bool near_only;

    /// With sums_in_records, copies the sums of the particles of ranks [first_rank, end_rank)
    /// into their force and torque (after the pair sums, before what reads them).
    void store_sums(unsigned first_rank, unsigned end_rank) const
    {
        if constexpr (sums_in_records<Real>) {
            const particle_view<P>& p = eval.p;
            for (unsigned r = first_rank; r < end_rank; ++r) {
                const std::size_t i = c.slot(r);
                const float* s = sums[i].value;
                p.force[i] = {s[0], s[1], s[2]};
                p.torque[i] = {s[3], s[4], s[5]};
            }
        }
    }

    void operator()(unsigned first_rank, unsigned end_rank) const
    {
        tile t;
        unsigned apart[tile::width + tile::overflow]; // entries of pairs that do not touch
        int apart_count = 0;
        // Locals: the stores into the tile could alias the fields of *this, which the loop
        // would otherwise reload for every entry.
        const vec4<Coord>* const x = eval.p.x;
        const unsigned* const partner = c.partner;
        const auto* const flags = c.history.flags;
        const world<Coord> box = eval.box;
        const auto params = eval.params;
#ifdef SPHERE_LANE_RECORDS
        if constexpr (row_walk_in_lanes<Coord>) {
            if (near_only) walk_in_lanes(c.offset, first_rank, end_rank, t, apart, apart_count);
            else
                for (unsigned r = first_rank; r < end_rank; ++r) { // each near row, then its far row
                    walk_in_lanes(c.offset, r, r + 1, t, apart, apart_count);
                    walk_in_lanes(c.offset + c.n, r, r + 1, t, apart, apart_count);
                }
            if (t.count) flush(t);
            forget(apart, apart_count);
            return;
        }
#endif
        for (unsigned r = first_rank; r < end_rank; ++r) {
            const unsigned i = static_cast<unsigned>(c.slot(r));
            const vec4<Coord> xi = x[i];
            // `image`: whether the row's separations need the nearest image (images_inside)
            const auto pair = [&](unsigned e, unsigned j, auto image) {
                t.owner[t.count] = i;
                t.partner[t.count] = j;
                t.entry[t.count] = e;
                // the sliding flag goes into the tile here: the SIMD loop gathers the
                // displacements, but cannot gather bytes
                t.hw[t.count] = Real(flags[e]);
                pair_separation<Real> s;
                const bool touching = sphere::detail::separate<Law, decltype(image)::value>(params, box, xi, x[j], s);
                t.dx[t.count] = s.d.x;
                t.dy[t.count] = s.d.y;
                t.dz[t.count] = s.d.z;
                t.r_i[t.count] = s.r_i;
                t.r_j[t.count] = s.r_j;
                if constexpr (wide) t.excess[t.count] = s.excess;
                // Only touching pairs take a lane; the others only forget their history. Both
                // lists grow without a branch on the outcome, which no predictor could guess.
                apart[apart_count] = e;
                t.count += touching;
                apart_count += !touching;
                if (apart_count == tile::width) forget(apart, apart_count);
                if (t.count == tile::width) flush(t);
            };
            const auto walk = [&](auto image) {
                for (unsigned e = c.offset[r], end = c.offset[r + 1]; e < end; ++e) {
                    const unsigned j = partner[e];
                    if (j >= wall_partner_base) break; // walls come last in a near row
                    pair(e, j, image);
                }
                if (!near_only)
                    for (unsigned e = c.far_begin(r), end = c.far_end(r); e < end; ++e) pair(e, partner[e], image);
            };
            // most owners lie away from the periodic faces: their walk skips the nearest image
            if (eval.images_inside(xi)) walk(std::false_type{});
            else walk(std::true_type{});
        }
        if (t.count) flush(t);
        forget(apart, apart_count);
    }

private:
    using Coord = coord_t<P>;
    /// positions wider than the law's type (mixed): the tile carries the overlap's excess
    static constexpr bool wide = !std::is_same_v<Real, Coord>;
    using history_type = law_history_t<Law, Real>;
    static constexpr unsigned lanes = law_history_shape<Law>::value.lanes;
    using tile = pair_tile<Real, lanes>;
    static constexpr bool records = sums_in_records<Real>;

#ifdef SPHERE_LANE_RECORDS
    /// The pairs of the rows of ranks [first_rank, end_rank), row r holding the entries
    /// [row[r], row[r + 1]), into the tile and the list of pairs apart, eight entries at a time
    /// (lanes::separate_rows): the same lanes, in the same order, as pair() one by one.
    SPHERE_HDI void walk_in_lanes(const unsigned* row, unsigned first_rank, unsigned end_rank, tile& t,
                                  unsigned* apart, int& apart_count) const
    {
        lanes::separate_rows<Law, wide>(
            eval.params, eval.box, eval.p.x, c.partner, c.history.flags, row, first_rank, end_rank,
            [this](unsigned r) { return static_cast<unsigned>(c.slot(r)); }, t, apart, apart_count, [&] {
                if (apart_count >= tile::width) forget(apart, apart_count);
                if (t.count >= tile::width) flush_overflowing(t);
            });
    }

    /// Flushes the tile's first width lanes and moves the lanes past them to the front.
    __attribute__((noinline)) void flush_overflowing(tile& t) const
    {
        const int over = t.count - tile::width;
        t.count = tile::width;
        flush(t);
        for (int k = 0; k < over; ++k) {
            const int from = tile::width + k;
            t.owner[k] = t.owner[from];
            t.partner[k] = t.partner[from];
            t.entry[k] = t.entry[from];
            t.hw[k] = t.hw[from];
            t.dx[k] = t.dx[from];
            t.dy[k] = t.dy[from];
            t.dz[k] = t.dz[from];
            t.r_i[k] = t.r_i[from];
            t.r_j[k] = t.r_j[from];
            if constexpr (wide) t.excess[k] = t.excess[from];
        }
        t.count = over;
    }
#endif

    /// The entries of pairs that do not touch: no force, and the history is forgotten.
    void forget(const unsigned* entry, int& count) const
    {
        for (int k = 0; k < count; ++k) {
            if (update_history) c.history.clear(entry[k]);
            if (Record) c.force[entry[k]] = vec4<Real>{0, 0, 0, 0};
        }
        count = 0;
    }

    void flush(tile& t) const
    {
        constexpr int w = tile::width;
        for (int k = t.count; k < w; ++k) {
            t.owner[k] = t.owner[0];
            t.partner[k] = t.partner[0];
            t.entry[k] = t.entry[0];
            t.hw[k] = t.hw[0];
            t.dx[k] = t.dx[0];
            t.dy[k] = t.dy[0];
            t.dz[k] = t.dz[0];
            t.r_i[k] = t.r_i[0];
            t.r_j[k] = t.r_j[0];
            if constexpr (wide) t.excess[k] = t.excess[0];
        }
        // Local copies: loop invariants the compiler can keep in registers.
        pair_contact<P, Law, OneVelocity> pairs = eval;
        const vec3<Real>* shift = c.history.shift;
        const Real* lane = c.history.lane;
#ifdef SPHERE_LANE_RECORDS
        if constexpr (records) {
            lanes::gather_records(motion, t.owner, t.motion_i);
            lanes::gather_records(motion, t.partner, t.motion_j);
            lanes::gather_vec3(shift, t.entry, t.shift);
        }
#endif
        SPHERE_VECTORISE_LOOP
        for (int k = 0; k < w; ++k) {
            vec3<Real> s;
            if constexpr (records) s = {t.shift[0][k], t.shift[1][k], t.shift[2][k]};
            else s = shift[t.entry[k]];
            history_type h;
            history_base(h) = {s.x, s.y, s.z, t.hw[k]};
            if constexpr (lanes > 0)
                for (unsigned l = 0; l < lanes; ++l) h.lane[l] = lane[t.entry[k] * lanes + l];
            pair_separation<Real> sep;
            sep.d = {t.dx[k], t.dy[k], t.dz[k]};
            sep.r_i = t.r_i[k];
            sep.r_j = t.r_j[k];
            sep.excess = wide ? t.excess[k] : Real(0);
            pair_result<Real> r;
            if constexpr (records)
                r = pairs.evaluate_moving(t.owner[k], t.partner[k], lane_motion{t.motion_i, k}, lane_motion{t.motion_j, k}, sep, h);
            else r = pairs.evaluate_touching(t.owner[k], t.partner[k], sep, h);
            t.fx[k] = r.force.x;
            t.fy[k] = r.force.y;
            t.fz[k] = r.force.z;
            t.tix[k] = r.torque_i.x;
            t.tiy[k] = r.torque_i.y;
            t.tiz[k] = r.torque_i.z;
            t.tjx[k] = r.torque_j.x;
            t.tjy[k] = r.torque_j.y;
            t.tjz[k] = r.torque_j.z;
            const vec4<Real>& hb = history_base(h);
            t.hx[k] = hb.x;
            t.hy[k] = hb.y;
            t.hz[k] = hb.z;
            t.hw[k] = hb.w;
            if constexpr (lanes > 0)
                for (unsigned l = 0; l < lanes; ++l) t.hl[l][k] = h.lane[l];
            if (Book) {
                t.fn[k] = r.fn;
                t.visc[k] = r.visc_rate / 2;
                t.fric[k] = r.fric_rate / 2;
            }
            if (Record) {
                t.rx[k] = r.record.x;
                t.ry[k] = r.record.y;
                t.rz[k] = r.record.z;
                t.rw[k] = r.record.w;
            }
        }
        const particle_view<P>& p = eval.p;
        for (int k = 0; k < t.count; ++k) {
            const unsigned i = t.owner[k], j = t.partner[k], e = t.entry[k];
            if (update_history) {
                c.history.set_base(e, {t.hx[k], t.hy[k], t.hz[k], t.hw[k]});
                if constexpr (lanes > 0)
                    for (unsigned l = 0; l < lanes; ++l) c.history.lane[e * lanes + l] = t.hl[l][k];
            }
            if (Record) c.force[e] = {t.rx[k], t.ry[k], t.rz[k], t.rw[k]};
            if constexpr (!records) {
                const vec3<Real> f{t.fx[k], t.fy[k], t.fz[k]};
                p.force[i] += f;
                p.force[j] -= f;
                p.torque[i] += vec3<Real>{t.tix[k], t.tiy[k], t.tiz[k]};
                p.torque[j] += vec3<Real>{t.tjx[k], t.tjy[k], t.tjz[k]};
            }
            if (Book) {
                p.pressure[i] += t.fn[k];
                p.pressure[j] += t.fn[k];
                p.p_visc[i] += t.visc[k];
                p.p_visc[j] += t.visc[k];
                p.p_fric[i] += t.fric[k];
                p.p_fric[j] += t.fric[k];
            }
        }
#ifdef SPHERE_LANE_RECORDS
        if constexpr (records)
            lanes::add_pair_shares(sums, t.owner, t.partner, {t.fx, t.fy, t.fz}, {t.tix, t.tiy, t.tiz},
                                   {t.tjx, t.tjy, t.tjz}, t.count);
#endif
        t.count = 0;
    }

    /// Lane k's motion from the values of its record (stored_motion's interface; zero_pair_sums
    /// packs v_sync, mass, omega_sync).
    struct lane_motion {
        const float (*m)[tile::record_width];
        int k;
        vec3<float> v() const { return {m[0][k], m[1][k], m[2][k]}; }
        vec3<float> omega() const { return {m[4][k], m[5][k], m[6][k]}; }
        float mass() const { return m[3][k]; }
    };
};

/// The two phases of the slab schedule: tasks of grid layers whose owners write disjoint sets
/// of particles (the owners of layer l write layers l and l + 1). Phase 0 holds the even
/// layers, phase 1 the odd ones; on a periodic axis with an odd number of layers the last
/// layer (which writes the first) joins the task of layer 0.
///
/// The threads share each phase's tasks in contiguous ranges of about equal work (entries),
/// phase by phase: the tasks of a phase write disjoint layers, so any split of them gives the
/// same sums. After the pair sums, a thread runs whatever comes after them for the particles
/// of its block of layers (about equal entries of both phases together).
struct slab_phases {
    struct task {
        unsigned layer[2];
        unsigned layers;
    };
    std::vector<task> phase[2];
    std::vector<unsigned> entries; ///< entries of the layers before each layer (layer_entries)

    slab_phases(const std::vector<unsigned>& layer_entries, bool periodic) : entries(layer_entries)
    {
        const unsigned n = layers();
        const bool merge_last = periodic && n >= 3 && n % 2 == 1;
        for (unsigned l = merge_last ? 1 : 0; l < (merge_last ? n - 1 : n); ++l) phase[l % 2].push_back({{l, 0}, 1});
        if (merge_last) phase[0].push_back({{n - 1, 0}, 2});
    }

    unsigned layers() const { return static_cast<unsigned>(entries.size() - 1); }

    /// Thread t's block of layers among `threads`: the layers whose middle entry falls in its
    /// share of all entries.
    void block(int t, int threads, unsigned& first, unsigned& end) const
    {
        const double total = double(entries.back() - entries.front());
        auto owner = [&](unsigned l) {
            const double middle = (double(entries[l] + entries[l + 1]) / 2 - double(entries.front()));
            const int o = total > 0 ? static_cast<int>(middle * threads / total) : 0;
            return o < threads ? o : threads - 1; // layers after the last entry go to the last thread
        };
        first = end = layers();
        for (unsigned l = 0; l < layers(); ++l) {
            if (owner(l) == t && first == layers()) first = l;
            if (owner(l) > t) {
                end = l;
                break;
            }
        }
        if (first > end) first = end;
    }

    /// Thread t's tasks of phase ph among `threads`: the tasks whose middle entry falls in its
    /// share of the phase's entries.
    void share(int ph, int t, int threads, std::size_t& first, std::size_t& end) const
    {
        const std::vector<task>& tasks = phase[ph];
        double total = 0;
        for (const task& k : tasks) total += work(k);
        first = end = tasks.size();
        double before = 0;
        for (std::size_t k = 0; k < tasks.size(); ++k) {
            const double middle = before + work(tasks[k]) / 2;
            int o = total > 0 ? static_cast<int>(middle * threads / total) : 0;
            if (o >= threads) o = threads - 1;
            if (o == t && first == tasks.size()) first = k;
            if (o > t) {
                end = k;
                break;
            }
            before += work(tasks[k]);
        }
        if (first > end) first = end;
    }

    /// The entries of a task's layers.
    double work(const task& k) const
    {
        double sum = 0;
        for (unsigned m = 0; m < k.layers; ++m) sum += double(entries[k.layer[m] + 1] - entries[k.layer[m]]);
        return sum;
    }
};

/// Thread t of `threads` in the slab schedule (sum_by_slabs): its share of the zeroing, of
/// each phase's tasks and of the finish. The work-sharing loop and the barriers bind to the
/// enclosing parallel region, or, called outside one, to a team of one.
template <class Pairs, class Zero, class Finish>
void slab_share(const Pairs& pairs, const Zero& zero, const Finish& finish, std::size_t n,
                const std::vector<unsigned>& layer_start, const slab_phases& phases, int threads, int t)
{
    const long long count = static_cast<long long>(n);
#pragma omp for schedule(static)
    for (long long i = 0; i < count; ++i) zero(static_cast<std::size_t>(i));
    for (int ph = 0; ph < 2; ++ph) {
        std::size_t first, end;
        phases.share(ph, t, threads, first, end);
        for (std::size_t k = first; k < end; ++k) {
            const slab_phases::task& task = phases.phase[ph][k];
            for (unsigned m = 0; m < task.layers; ++m)
                pairs(layer_start[task.layer[m]], layer_start[task.layer[m] + 1]);
        }
#pragma omp barrier
    }
    unsigned lo, hi;
    phases.block(t, threads, lo, hi);
    pairs.store_sums(layer_start[lo], layer_start[hi]);
    finish(layer_start[lo], layer_start[hi], t);
}

/// Runs the slab schedule on the host: zeroes the sums, then the two phases, each thread
/// working through its share of a phase's tasks, then `finish(first_rank, end_rank, thread)`
/// for the ranks of the thread's block of layers. Few particles, or a team of one, run
/// without an OpenMP region (see for_each_index).
template <class Pairs, class Zero, class Finish>
void sum_by_slabs(const Pairs& pairs, const Zero& zero, const Finish& finish, std::size_t n,
                  const std::vector<unsigned>& layer_start, const slab_phases& phases)
{
    if (n < host_parallel_threshold || host_team() == 1) {
        slab_share(pairs, zero, finish, n, layer_start, phases, 1, 0);
        return;
    }
#pragma omp parallel num_threads(host_team())
    {
#ifdef _OPENMP
        slab_share(pairs, zero, finish, n, layer_start, phases, omp_get_num_threads(), omp_get_thread_num());
#else
        slab_share(pairs, zero, finish, n, layer_start, phases, 1, 0);
#endif
    }
}

/// A finish that does nothing (sum_by_slabs).
struct no_finish {
    void operator()(unsigned, unsigned, int) const {}
};

/// The gather schedule, first pass (one index per rank): evaluates the owner's pairs (its near
/// row, then its far row) and stores each pair's result. `near_only`: the near row alone (the
/// caller knows that the far partners are apart and that their stored results are zero from
/// the walk that last found them apart). Far rows without histories are apart (the caller
/// opens them for a step that may find them touching): their results are zero.
template <class P, class Law, bool Book, bool Record, bool OneVelocity>
struct evaluate_owned_pairs {
    using Real = real_t<P>;
    pair_contact<P, Law, OneVelocity> eval;
    contact_view<Real> c;
    vec3<Real>* force;
    vec3<Real>* torque_i;
    vec3<Real>* torque_j;
    vec3<Real>* audit; ///< |f_n|, half the viscous and half the frictional rate (Book only)
    bool update_history;
    bool near_only;

    SPHERE_HD void operator()(std::size_t r) const
    {
        const std::size_t i = c.slot(r);
        for (unsigned e = c.offset[r]; e < c.offset[r + 1] && c.partner[e] < wall_partner_base; ++e) pair(i, e);
        if (near_only) return;
        for (unsigned e = c.far_begin(r); e < c.far_end(r); ++e) {
            if (c.far_history) {
                pair(i, e);
            } else {
                force[e] = torque_i[e] = torque_j[e] = vec3<Real>{0, 0, 0};
                if (Book) audit[e] = vec3<Real>{0, 0, 0};
            }
        }
    }

private:
    SPHERE_HD void pair(std::size_t i, unsigned e) const
    {
        law_history_t<Law, Real> h;
        c.history.load(e, h);
        pair_result<Real> res = eval.evaluate(i, c.partner[e], h);
        if (update_history) c.history.store(e, h);
        if (Record) c.force[e] = res.record;
        force[e] = res.force;
        torque_i[e] = res.torque_i;
        torque_j[e] = res.torque_j;
        if (Book) audit[e] = {res.fn, res.visc_rate / 2, res.fric_rate / 2};
    }
};

/// The gather schedule, second pass (one index per slot): the particle's own pairs (its near
/// row, then its far row), then the pairs that list it as partner (build_reverse's order).
template <class P, bool Book>
struct gather_pair_results {
    using Real = real_t<P>;
    particle_view<P> p;
    contact_view<Real> c;
    const unsigned* reverse_offset; ///< pairs whose partner has rank r: reverse_entry[reverse_offset[r] ...]
    const unsigned* reverse_entry;
    const vec3<Real>* force;
    const vec3<Real>* torque_i;
    const vec3<Real>* torque_j;
    const vec3<Real>* audit;

    SPHERE_HD void operator()(std::size_t s) const
    {
        const std::size_t r = c.rank(s);
        vec3<Real> f{0, 0, 0}, t{0, 0, 0}, a{0, 0, 0};
        c.for_each_pair(r, [&](unsigned e, unsigned) {
            f += force[e];
            t += torque_i[e];
            if (Book) a += audit[e];
        });
        for (unsigned m = reverse_offset[r]; m < reverse_offset[r + 1]; ++m) {
            const unsigned e = reverse_entry[m];
            f -= force[e];
            t += torque_j[e];
            if (Book) a += audit[e];
        }
        p.force[s] = f;
        p.torque[s] = t;
        if (Book) {
            p.pressure[s] = a.x;
            p.p_visc[s] = a.y;
            p.p_fric[s] = a.z;
        }
    }
};

/// The sort key of each entry for the reverse index: its partner's rank, or n for a wall and
/// for the lists' spare capacity.
template <class Real>
struct reverse_keys {
    contact_view<Real> c;
    unsigned* key;
    unsigned* entry;
    SPHERE_HD void operator()(std::size_t e) const
    {
        const unsigned j = c.partner[e];
        const bool pair = e < c.entries() && j < wall_partner_base; // not a wall, nor past the entries
        key[e] = pair ? static_cast<unsigned>(c.rank(j)) : static_cast<unsigned>(c.n);
        entry[e] = static_cast<unsigned>(e);
    }
};

} // namespace detail

/// Sums the pair contacts into the particles' forces and torques (and, with Book, their audit
/// sums), by the chosen schedule; owns the gather schedule's scratch.
template <class P, class Policy>
class interaction {
public:
    using Real = real_t<P>;
    using Coord = coord_t<P>;

    /// The schedule `how` resolves to on this backend; throws for slabs on CUDA.
    static pair_summation resolve(pair_summation how)
    {
        constexpr bool blocks = runs_in_blocks<Policy>;
        if (how == pair_summation::automatic) return blocks ? pair_summation::slabs : pair_summation::gather;
        if (how == pair_summation::slabs && !blocks)
            detail::fail("settings.pair_summation = slabs needs the host backend; use gather (or automatic) on CUDA");
        if (how != pair_summation::slabs && how != pair_summation::gather)
            detail::fail("settings.pair_summation = ", unsigned(how), ": not a pair_summation");
        return how;
    }

    /// The contact lists were rebuilt or replaced.
    void lists_changed()
    {
        reverse_ready_ = false;
        results_walked_ = false;
    }

    /// Whether the last sum_pairs walked the near partners alone.
    bool walked_near() const { return walked_near_; }

    /// Overwrites every particle's force and torque (and, with Book, its |f_n| sum and
    /// dissipation rates) with the sums over its pair contacts. Book implies update_history.
    /// On the slab schedule, each thread then runs `finish(first_rank, end_rank, thread)` on a
    /// block of ranks (all ranks in all), in the same parallel region; returns whether it did,
    /// so that the caller runs that work otherwise. `near_only`: walk only the near partners of
    /// each row, which the caller has found to be the only ones that can touch, the others
    /// having no history and having been apart at the last walk that visited them. The gather
    /// schedule, which adds up the stored results of every entry, does so only once a walk of
    /// every entry since the lists changed has stored the others' zeros (walked_near() says
    /// whether it did). A simulation's Book is fixed (its initial forces, without the audit,
    /// come before the audit's buffer exists), so that walk stored the audit sums too.
    template <bool Book, bool Record, class Law, bool OneVelocity, class Finish = detail::no_finish>
    bool sum_pairs(execution_context<Policy>& ctx, const detail::pair_contact<P, Law, OneVelocity>& eval,
                   contact_lists<P, Policy>& lists, pair_summation how, bool update_history, bool near_only = false,
                   const Finish& finish = {})
    {
        const particle_view<P>& p = eval.p;
        const contact_view<Real> c = lists.view();
        if (resolve(how) == pair_summation::slabs) {
            if constexpr (runs_in_blocks<Policy>) {
                const detail::slab_phases phases(lists.layer_entries(), lists.periodic_layers());
                if (detail::sums_in_records<Real> && motion_.size() < p.n) {
                    motion_.resize(p.n);
                    sums_.resize(p.n);
                }
                detail::sum_by_slabs(detail::slab_pairs<P, Law, Book, Record, OneVelocity>{eval, c, motion_.data(), sums_.data(),
                                                                                          update_history, near_only},
                                     detail::zero_pair_sums<P, Book>{p, motion_.data(), sums_.data()}, finish, p.n,
                                     lists.layer_start(), phases);
            }
            walked_near_ = near_only;
            return true;
        }
        // sized by the lists' capacity, which the host knows without waiting for a rebuild's totals
        const std::size_t entries = lists.capacity();
        if (force_.size() < entries) {
            force_.resize(entries);
            torque_i_.resize(entries);
            torque_j_.resize(entries);
            results_walked_ = false;
        }
        if (Book && audit_.size() < entries) {
            audit_.resize(entries);
            results_walked_ = false;
        }
        if (!reverse_ready_) build_reverse(ctx, c, entries, p.n);
        walked_near_ = near_only && results_walked_;
        for_each_index(Policy{}, p.n,
                       detail::evaluate_owned_pairs<P, Law, Book, Record, OneVelocity>{
                           eval, c, force_.data(), torque_i_.data(), torque_j_.data(), Book ? audit_.data() : nullptr,
                           update_history, walked_near_});
        if (!walked_near_) results_walked_ = true;
        for_each_index(Policy{}, p.n,
                       detail::gather_pair_results<P, Book>{p, c, reverse_offset_.data(), reverse_entry_.data(),
                                                            force_.data(), torque_i_.data(), torque_j_.data(),
                                                            Book ? audit_.data() : nullptr});
        return false;
    }

private:
    /// The pairs of each partner, in entry order: the near rows' by owner rank, then the far
    /// rows' by owner rank.
    void build_reverse(execution_context<Policy>& ctx, const contact_view<Real>& c, std::size_t entries, std::size_t n)
    {
        if (reverse_entry_.size() < entries) {
            reverse_key_.resize(entries);
            reverse_entry_.resize(entries);
        }
        if (reverse_offset_.size() != n + 1) reverse_offset_.resize(n + 1);
        for_each_index(Policy{}, entries, detail::reverse_keys<Real>{c, reverse_key_.data(), reverse_entry_.data()});
        sort_by_key(ctx, reverse_key_.data(), reverse_entry_.data(), entries, bits_for(n));
        find_starts(ctx, reverse_key_.data(), 0, entries, n, reverse_offset_.data()); // key n: not a pair
        reverse_ready_ = true;
    }

    buffer<vec3<Real>, Policy> force_, torque_i_, torque_j_, audit_;
    buffer<record8, Policy> motion_, sums_; ///< the slab schedule's records (detail::sums_in_records)
    buffer<unsigned, Policy> reverse_offset_, reverse_key_, reverse_entry_;
    bool reverse_ready_ = false;
    bool results_walked_ = false; ///< every entry's result stored since the lists changed (gather)
    bool walked_near_ = false;    ///< walked_near()
};

} // namespace sphere
