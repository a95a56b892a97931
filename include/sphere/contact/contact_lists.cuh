#pragma once
/// \file
/// Contact lists with history, each pair listed once (a half list), in compressed rows (CSR).
///
/// At every rebuild the neighbour grid sorts the particles by cell (ties by user index); a
/// particle's position in that order is its *rank*, and the grid's cells are numbered layer
/// after layer along its slow axis (grid/geometry.cuh), so each layer is a range of ranks. A
/// pair {a, b} with |x_a - x_b| < r_a + r_b + skin is owned by one of the two: the one whose
/// layer comes first (b in the next layer, cyclically on a periodic axis), or, in the same
/// layer, the one of lower rank. Rank r has two rows of the partners it owns: its *near* row,
/// the partners within r_a + r_b + near skin at the rebuild (by partner rank), then every wall
/// face within r + skin (by face); and its *far* row, the other partners (by partner rank).
/// The near rows of all ranks come first in the arrays, the far rows after them. While no
/// particle has moved more than half the near skin since the rebuild, the far partners cannot
/// touch, and the pair sums walk the near rows alone (docs/architecture.md, *Near partners*).
/// Each entry of a near row holds the contact's history (tangential displacement as seen by
/// the owner, sliding flag) and, when recorded, the force of the last step; the far rows'
/// entries have them only once a step must walk them (contact_lists::open_far_rows): a
/// resting bed never stores the histories of the pairs that cannot touch. The lists hold what
/// they find: no capacity to set.
///
/// Ranks and ownership depend on the positions at the rebuild and the user indices alone, so
/// the interaction, which follows them (contact/interact.cuh), gives the same bits whether or
/// not the particles are stored in rank order (settings.reorder) and whatever the thread count.
/// Histories are carried across rebuilds by particle, from the owner's old row or, negated,
/// from the partner's when the ownership changed.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "../boundary/walls.cuh"
#include "../core/error.cuh"
#include "../core/precision.cuh"
#include "../core/vec.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/collectives.cuh"
#include "../exec/context.cuh"
#include "../exec/for_each.cuh"
#include "../exec/policy.cuh"
#include "../grid/neighbor_grid.cuh"
#include "history.cuh"

namespace sphere {

/// Partner codes from here up name a wall face: wall_partner_base + f. Particle indices stay
/// below it.
inline constexpr unsigned wall_partner_base = 0xFFFFFFF0u;

/// The value of contact_lists::wall_ranks() past the ranks that have wall entries.
inline constexpr unsigned no_rank = 0xFFFFFFFFu;

/// What a rebuild found, in the policy's memory (read back with the step's report): the
/// entries whose history it carried over, the entries of the new lists and of their near rows,
/// the particles with wall entries, and whether the first three exceeded the capacities the
/// lists had. After an overflow the new lists are empty and contact_lists::settle grows them
/// for the rebuild to run again. `wrapped`: the entries exceeded what 32-bit offsets hold (an
/// overflow too, which settle reports as an error).
struct list_totals {
    unsigned kept = 0;
    unsigned entries = 0;
    unsigned near_entries = 0;
    unsigned wall_particles = 0;
    unsigned overflow = 0;
    unsigned wrapped = 0;
};

/// Kernel view of the contact lists.
template <class Real>
struct contact_view {
    std::size_t n;                ///< particles
    const unsigned* offset;       ///< 2n + 1 values: near row of rank r [offset[r], offset[r + 1]), far row
                                  ///< [offset[n + r], offset[n + r + 1])
    const unsigned* partner;      ///< storage slot of the partner, or wall_partner_base + f (walls last)
    history_view<Real> history;   ///< as seen by the owner (contact/history.cuh)
    vec4<Real>* force;            ///< f_t on the owner (N) in xyz, f_n . n (N) in w; null when not recorded
    const unsigned* slot_of_rank; ///< storage slot of each rank; null when they coincide (settings.reorder)
    const unsigned* rank_of_slot; ///< the inverse; null when they coincide
    bool far_history;             ///< the far rows' entries have histories (and forces) too

    SPHERE_HDI std::size_t slot(std::size_t r) const { return slot_of_rank ? slot_of_rank[r] : r; }
    SPHERE_HDI std::size_t rank(std::size_t s) const { return rank_of_slot ? rank_of_slot[s] : s; }
    SPHERE_HDI unsigned far_begin(std::size_t r) const { return offset[n + r]; }
    SPHERE_HDI unsigned far_end(std::size_t r) const { return offset[n + r + 1]; }
    /// Entries in all rows.
    SPHERE_HDI unsigned entries() const { return offset[2 * n]; }
    /// Whether entry e has a history (and a recorded force): every near row's entry does, a
    /// far row's only with far_history.
    SPHERE_HDI bool has_history(std::size_t e) const { return far_history || e < offset[n]; }
    /// Calls f(e, partner) for each particle partner of rank r, its near row's then its far
    /// row's (the order of the pair sums); returns where the near row's walls begin.
    template <class F>
    SPHERE_HDI unsigned for_each_pair(std::size_t r, F&& f) const
    {
        unsigned e = offset[r];
        for (; e < offset[r + 1] && partner[e] < wall_partner_base; ++e) f(e, partner[e]);
        for (unsigned k = far_begin(r); k < far_end(r); ++k) f(k, partner[k]);
        return e;
    }
};

/// A host copy of the contact lists in user order, each pair from both sides: entries of
/// particle i at [offset[i], offset[i + 1]), partners as user indices sorted ascending, then
/// walls (wall_partner_base + f). The history and force of an entry are as seen by particle i.
template <class Real>
struct contact_table {
    std::vector<std::size_t> offset{0};
    std::vector<unsigned> partner;
    std::vector<vec4<Real>> history; ///< the bases: tangential displacement (m) xyz, flags w
    history_shape shape;             ///< the law's lanes beside the base (contact/history.cuh)
    std::vector<Real> lane;          ///< shape.lanes per entry
    std::vector<vec4<Real>> force;   ///< empty when the simulation records no contact forces

    std::size_t particles() const { return offset.size() - 1; }
    std::size_t begin(std::size_t i) const { return offset[i]; }
    std::size_t end(std::size_t i) const { return offset[i + 1]; }
    /// The particle partners of particle i (user indices), walls left out.
    std::vector<unsigned> partners_of(std::size_t i) const
    {
        std::vector<unsigned> out;
        for (std::size_t e = begin(i); e < end(i); ++e)
            if (partner[e] < wall_partner_base) out.push_back(partner[e]);
        return out;
    }
    /// The entry of particle i for partner j (a user index or wall_partner_base + f), or ~0.
    std::size_t find(std::size_t i, unsigned j) const
    {
        for (std::size_t e = begin(i); e < end(i); ++e)
            if (partner[e] == j) return e;
        return ~std::size_t(0);
    }
};

namespace detail {
/// Whether particles at xi and xj (centre in xyz, radius in w) lie within r_i + r_j + skin of
/// each other (nearest image): listed partners with the lists' skin, near partners with the
/// near skin (neighbour_scan, contact_lists::restore).
template <class Real>
SPHERE_HDI bool within_skin(const world<Real>& box, const vec4<Real>& xi, const vec4<Real>& xj, Real skin)
{
    const Real reach = xi.w + xj.w + skin;
    return norm2(box.nearest_image(xi.xyz() - xj.xyz())) < reach * reach;
}

/// Scans the cells around the particle at rank k and visits the partners it owns within reach
/// (`pair(q, near)` with the partner's rank q, and whether it lies within the near skin) and
/// then every active wall within r + skin (`wall(f)`). Owned partners lie in k's own layer at
/// a higher rank or in the next layer, so only those two layers are scanned. Where the grid
/// has reference positions (each in its particle's cell), they decide the near partners.
template <class Real>
struct neighbour_scan {
    grid_view<Real> grid;
    wall_set<Real> walls;
    Real skin;
    Real near_skin;

    template <class Visit>
    SPHERE_HD void operator()(std::size_t k, Visit& visit) const
    {
        // the kind of near test decided once, not for every candidate
        if (grid.sorted_x.reference) scan<true>(k, visit);
        else scan<false>(k, visit);
    }

private:
    template <bool Reference, class Visit>
    SPHERE_HD void scan(std::size_t k, Visit& visit) const
    {
        // Cell coordinates along the slow, mid and fast axes, in scalars (arrays indexed by
        // run-time axes would live in local memory on CUDA).
        const grid_geometry<Real>& g = grid.geometry;
        const vec4<Real> xi = grid.sorted_x.x[k];
        const int cs = g.coordinate(component(xi.xyz(), g.slow), g.slow);
        const int cm = g.coordinate(component(xi.xyz(), g.mid), g.mid);
        const int cf = g.coordinate(component(xi.xyz(), g.fast), g.fast);
        const int layers = static_cast<int>(g.cells(g.slow)), nf = static_cast<int>(g.cells(g.fast));
        for (int ds = 0; ds <= 1; ++ds) {
            int s = cs + ds;
            if (s == layers) {
                // the next layer of the last one: the first, on a periodic axis with more than
                // two layers (with two, the first is also the previous one and owns the pair)
                if (!g.box.periodic(g.slow) || layers < 3) continue;
                s = 0;
            }
            for (int dm = -1; dm <= 1; ++dm) {
                int m = cm + dm;
                if (!wrap_or_reject(m, g.mid)) continue;
                // The cells cf - 1 .. cf + 1 along the fast axis: one run of ranks, or two when
                // a periodic axis wraps around.
                int f0 = cf - 1, f1 = cf + 1;
                int wrapped0 = 0, wrapped1 = -1;
                if (g.box.periodic(g.fast)) {
                    if (f0 < 0) { wrapped0 = wrapped1 = nf - 1; f0 = 0; }
                    if (f1 >= nf) { wrapped0 = wrapped1 = 0; f1 = nf - 1; }
                } else {
                    f0 = f0 < 0 ? 0 : f0;
                    f1 = f1 >= nf ? nf - 1 : f1;
                }
                const std::size_t above = ds == 0 ? k + 1 : 0; // same layer: higher ranks only
                scan_run<Reference>(k, xi, g.index_in_order(s, m, f0), g.index_in_order(s, m, f1), above, visit);
                if (wrapped1 >= 0)
                    scan_run<Reference>(k, xi, g.index_in_order(s, m, wrapped0), g.index_in_order(s, m, wrapped1),
                                        above, visit);
            }
        }
        SPHERE_UNROLL
        for (int f = 0; f < wall_set<Real>::count; ++f) {
            const wall_face<Real>& w = walls.face[f];
            const int a = f / 2;
            const Real gap =
                (component(xi.xyz(), a) - Real(w.position)) * component(wall_set<Real>::inward_normal(f), a) - xi.w;
            if (w.active && gap < skin) visit.wall(f);
        }
    }

    /// Wraps cell coordinate c on a periodic axis; false when it lies outside a wall axis.
    SPHERE_HD bool wrap_or_reject(int& c, int a) const
    {
        const int n = static_cast<int>(grid.geometry.cells(a));
        if (grid.geometry.box.periodic(a)) {
            c = (c + n) % n;
            return true;
        }
        return c >= 0 && c < n;
    }

    /// The candidates in cells [first_cell, last_cell] (from rank `above` on) of rank k at xi.
    template <bool Reference, class Visit>
    SPHERE_HD void scan_run(std::size_t k, const vec4<Real>& xi, unsigned first_cell, unsigned last_cell,
                            std::size_t above, Visit& visit) const
    {
        const unsigned end = grid.cell_start[last_cell + 1];
        unsigned q = grid.cell_start[first_cell];
        if (q < above) q = static_cast<unsigned>(above < end ? above : end);
        const position_source<Real>& at = grid.sorted_x;
        const world<Real>& box = grid.geometry.box;
        for (; q < end; ++q) {
            const vec4<Real> xq = at.x[q];
            if (!within_skin(box, xi, xq, skin)) continue;
            if constexpr (Reference) {
                // the separation of the reference positions (as within_skin forms it between them)
                const Real reach = xi.w + xq.w + near_skin;
                visit.pair(q, norm2(box.nearest_image(at.lattice.between(at.reference[k], at.reference[q]))) <
                                  reach * reach);
            } else {
                visit.pair(q, within_skin(box, xi, xq, near_skin));
            }
        }
    }
};

struct count_visit {
    unsigned near = 0, far = 0;
    SPHERE_HD void pair(unsigned, bool is_near) { ++(is_near ? near : far); }
    SPHERE_HD void wall(int) { ++near; }
};

/// The lengths of rank k's near row (count[k]) and far row (count[n + k]).
template <class Real>
struct count_entries {
    neighbour_scan<Real> scan;
    unsigned* count;
    SPHERE_HD void operator()(std::size_t k) const
    {
        count_visit v;
        scan(k, v);
        count[k] = v.near;
        count[scan.grid.n + k] = v.far;
    }
};

/// Writes partner ranks (sort keys) in visit order, near ones and walls (which come after
/// every partner) into the near row, the others into the far row.
struct fill_visit {
    unsigned* near_key;
    unsigned* far_key;
    unsigned near = 0, far = 0;
    SPHERE_HD void pair(unsigned q, bool is_near)
    {
        if (is_near) near_key[near++] = q;
        else far_key[far++] = q;
    }
    SPHERE_HD void wall(int f) { near_key[near++] = wall_partner_base + unsigned(f); }
};

/// Sorts the first n keys ascending (insertion sort: rows are short).
SPHERE_HDI void sort_row(unsigned* key, unsigned n)
{
    for (unsigned a = 1; a < n; ++a) {
        const unsigned q = key[a];
        unsigned b = a;
        for (; b > 0 && key[b - 1] > q; --b) key[b] = key[b - 1];
        key[b] = q;
    }
}

/// The histories carried over from the old lists (contact_lists' kept entries): rows by the
/// particles' old slots, partners as old slots or wall codes.
template <class Real>
struct old_lists {
    const unsigned* offset;
    const unsigned* partner;
    history_view<Real> history;

    /// The kept entry of old slot `owner` for `code` (an old slot or a wall code); false when
    /// there is none.
    SPHERE_HD bool find(unsigned owner, unsigned code, unsigned& entry) const
    {
        for (unsigned m = offset[owner]; m < offset[owner + 1]; ++m)
            if (partner[m] == code) {
                entry = m;
                return true;
            }
        return false;
    }
};

/// Fills the new rows of rank k: partners by rank (stored as slots: the rank itself once the
/// particles are permuted into rank order, the grid's old slot with `keep_order`), walls last
/// in the near row, and carries over the history each near contact had in the old lists. The
/// far partners have no history: they do not touch now (a contact that touched lies within
/// the near skin), and their rows have histories only once a step walks them.
template <class Coord, class Real>
struct fill_entries {
    neighbour_scan<Coord> scan;
    const unsigned* offset;
    unsigned* partner;
    history_view<Real> history;
    old_lists<Real> old;
    bool keep_order;
    const list_totals* totals; ///< nothing is written when the lists overflowed

    SPHERE_HD void operator()(std::size_t k) const
    {
        if (totals->overflow) return;
        const std::size_t n = scan.grid.n;
        const unsigned begin = offset[k], far_begin = offset[n + k];
        unsigned* p = partner + begin;
        unsigned* q = partner + far_begin;
        fill_visit v{p, q};
        scan(k, v);
        unsigned pairs = 0;
        while (pairs < v.near && p[pairs] < wall_partner_base) ++pairs;
        sort_row(p, pairs);
        sort_row(q, v.far);
        const unsigned* order = scan.grid.order; // old slot of each rank
        const unsigned me = order[k];
        for (unsigned a = 0; a < v.near; ++a) {
            const unsigned code = p[a];
            unsigned m = 0;
            bool found = false, mirror = false;
            if (code >= wall_partner_base) {
                found = old.find(me, code, m);
            } else {
                const unsigned them = order[code];
                found = old.find(me, them, m);
                if (!found) found = mirror = old.find(them, me, m);
                p[a] = keep_order ? them : code;
            }
            if (found) history.copy(begin + a, old.history, m, mirror);
            else history.clear(begin + a);
        }
        if (keep_order)
            for (unsigned a = 0; a < v.far; ++a) q[a] = order[q[a]];
    }
};

/// Calls f(e) for each entry of rank r's rows that has a history: its near row, and its far
/// row when those have histories.
template <class Real, class F>
SPHERE_HDI void for_each_history(const contact_view<Real>& c, std::size_t r, F&& f)
{
    for (unsigned e = c.offset[r]; e < c.offset[r + 1]; ++e) f(e);
    if (c.far_history)
        for (unsigned e = c.far_begin(r); e < c.far_end(r); ++e) f(e);
}

/// How many entries of rank r have a non-zero history, counted at the rank's particle's slot.
template <class Real>
struct count_histories {
    contact_view<Real> c;
    unsigned* count;
    SPHERE_HD void operator()(std::size_t r) const
    {
        unsigned kept = 0;
        for_each_history(c, r, [&](unsigned e) { kept += c.history.has(e); });
        count[c.slot(r)] = kept;
    }
};

/// Copies the entries of rank r with a non-zero history to the kept entries, in a row by the
/// particle's slot; nothing when they do not fit `capacity` (to_offset[n] is their total).
template <class Real>
struct copy_histories {
    contact_view<Real> c;
    const unsigned* to_offset;
    std::size_t capacity;
    unsigned* to_partner;
    history_view<Real> to_history;
    SPHERE_HD void operator()(std::size_t r) const
    {
        if (to_offset[c.n] > capacity) return;
        unsigned k = to_offset[c.slot(r)];
        for_each_history(c, r, [&](unsigned e) {
            if (c.history.has(e)) {
                to_partner[k] = c.partner[e];
                to_history.copy(k, c.history, e, false);
                ++k;
            }
        });
    }
};

/// Clears the far rows' histories (and recorded forces) from entry `first` on.
template <class Real>
struct clear_far_histories {
    history_view<Real> history;
    vec4<Real>* force;
    std::size_t first;
    SPHERE_HD void operator()(std::size_t k) const
    {
        history.clear(first + k);
        if (force) force[first + k] = vec4<Real>{0, 0, 0, 0};
    }
};

/// 1 where the scan of the rows' entry counts wrapped around 2^32 at row r (its end lies
/// below its start), else 0. Reduced with max: whether any row did.
struct row_wraps {
    const unsigned* offset;
    SPHERE_HD unsigned operator()(std::size_t r) const { return offset[r + 1] < offset[r] ? 1u : 0u; }
};

/// Writes the totals of a rebuild from its scans (kept entries, new entries, near rows'
/// entries) and whether they exceed the capacities (totals->wrapped, found before, counts as
/// exceeding them).
struct record_totals {
    const unsigned* kept_offset;
    const unsigned* offset;
    std::size_t n, kept_capacity, entry_capacity, history_capacity;
    list_totals* totals;
    SPHERE_HD void operator()(std::size_t) const
    {
        totals->kept = kept_offset[n];
        totals->entries = offset[2 * n];
        totals->near_entries = offset[n];
        totals->wall_particles = 0;
        totals->overflow = kept_offset[n] > kept_capacity || offset[2 * n] > entry_capacity ||
                           offset[n] > history_capacity || totals->wrapped;
    }
};

/// Whether row r of the near rows at `offset` has wall entries (they end it).
SPHERE_HDI bool row_has_walls(const unsigned* offset, const unsigned* partner, std::size_t r)
{
    const unsigned end = offset[r + 1];
    return end > offset[r] && partner[end - 1] >= wall_partner_base;
}

/// Whether rank r has wall entries (1 or 0), for the list of such ranks.
struct has_walls {
    const unsigned* offset;
    const unsigned* partner;
    const list_totals* totals;
    unsigned* flag;
    SPHERE_HD void operator()(std::size_t r) const
    {
        flag[r] = !totals->overflow && row_has_walls(offset, partner, r) ? 1u : 0u;
    }
};

/// Writes rank r at its place in the list of ranks with wall entries (`place`: the exclusive
/// scan of has_walls' flags; the list is filled with no_rank beforehand).
struct list_wall_ranks {
    const unsigned* place;
    unsigned* ranks;
    SPHERE_HD void operator()(std::size_t r) const
    {
        if (place[r + 1] > place[r]) ranks[place[r]] = static_cast<unsigned>(r);
    }
};

/// The number of ranks with wall entries, into the totals.
struct record_wall_particles {
    const unsigned* place;
    std::size_t n;
    list_totals* totals;
    SPHERE_HD void operator()(std::size_t) const { totals->wall_particles = place[n]; }
};

/// Empties every row of lists that overflowed, so that nothing reads past their arrays.
struct empty_if_overflow {
    unsigned* offset;
    const list_totals* totals;
    SPHERE_HD void operator()(std::size_t r) const
    {
        if (totals->overflow) offset[r] = 0;
    }
};

/// The storage slot of each rank and its inverse (lists that keep the particles' order), unless
/// the lists overflowed (the old ones stay in use).
struct set_rank_slots {
    const unsigned* order;
    const list_totals* totals;
    unsigned* slot_of_rank;
    unsigned* rank_of_slot;
    SPHERE_HD void operator()(std::size_t k) const
    {
        if (totals->overflow) return;
        slot_of_rank[k] = order[k];
        rank_of_slot[order[k]] = static_cast<unsigned>(k);
    }
};
} // namespace detail
/// The contact lists of particles in precision P (core/precision.cuh): the neighbour search in
/// coord_t<P> (the positions' type), histories and forces in real_t<P>; host tables in coord_t<P>.
template <class P, class Policy>
class contact_lists {
public:
    using Real = real_t<P>;
    using Coord = coord_t<P>;

    contact_lists() = default;
    /// Empty lists for n particles whose histories have `shape` (the contact law's,
    /// contact/history.cuh); `record_forces` keeps each entry's force of the last step.
    contact_lists(std::size_t n, bool record_forces, history_shape shape = {})
        : record_forces_(record_forces), offset_(2 * n + 1, 0u), history_(shape),
          kept_offset_(n + 1, 0u), kept_history_(shape), wall_ranks_(n, no_rank)
    {
    }

    std::size_t size() const { return (offset_.size() - 1) / 2; }
    /// Entries in all lists: each pair once, and each particle's walls within reach (host
    /// copy, from the last settled rebuild).
    std::size_t entries() const { return entries_; }
    /// Of those, the entries of the near rows (host copy).
    std::size_t near_entries() const { return near_entries_; }
    /// How many entries the lists' arrays hold (at least entries()).
    std::size_t capacity() const { return partner_.size(); }
    /// How many entries the histories' arrays hold: at least near_entries(), and entries()
    /// once the far rows have histories.
    std::size_t history_capacity() const { return history_.size(); }
    /// Whether the far rows' entries have histories (open_far_rows()).
    bool far_histories() const { return far_history_; }
    /// How many rebuilds overflowed the capacities and ran again.
    std::size_t overflows() const { return overflows_; }
    bool records_forces() const { return record_forces_; }
    /// The first rank of each layer of the grid along its slow axis, and one past the last
    /// (host copy, from the last rebuild; for the host's slab schedule only).
    const std::vector<unsigned>& layer_start() const { return layer_start_; }
    /// Whether the slow axis of the grid of the last rebuild is periodic.
    bool periodic_layers() const { return periodic_layers_; }
    /// Entries of ranks [0, r) for each r of layer_start() (host copy, from the last rebuild).
    const std::vector<unsigned>& layer_entries() const { return layer_entries_; }
    /// The ranks that have wall entries, ascending, then no_rank up to size() (policy memory).
    const unsigned* wall_ranks() const { return wall_ranks_.data(); }
    /// How many ranks have wall entries (host copy, from the last settled rebuild).
    std::size_t wall_particles() const { return wall_particles_; }

    /// Rebuilds every list from a grid built over the particles in their current slots,
    /// without waiting for the device: its totals go to `totals` (policy memory), for the
    /// caller to read back and hand to settle(). The new lists are in the grid's order (its
    /// ranks); partners are stored as ranks, to be the slots once the caller permutes the
    /// particles into that order, or, with `keep_order`, as the current slots, which the
    /// particles keep. Walls within r + skin are listed too; the partners within r_a + r_b +
    /// near_skin (at most skin) go to the near rows, the others to the far rows, which have no
    /// histories until open_far_rows(). When the histories to carry over or the new entries
    /// exceed the capacities, the new lists are empty and the old ones (or their histories)
    /// stay for the rebuild to run again after settle().
    void rebuild(execution_context<Policy>& ctx, const grid_view<Coord>& grid, const wall_set<Coord>& walls, Coord skin,
                 Coord near_skin, bool keep_order, list_totals* totals)
    {
        const std::size_t n = size();
        if (!histories_kept_) keep_histories(ctx);
        histories_kept_ = true;
        // The new rows are counted beside the old ones where the kept entries may not have
        // held the old histories (settle() then puts the old lists back in use): always on
        // CUDA, which does not wait to learn it, on the host only when they did not hold them
        // (it knows at once), so that the host keeps no second row offsets between rebuilds.
        bool beside = true;
        if constexpr (runs_in_blocks<Policy>) beside = kept_offset_.data()[n] > kept_capacity();
        if (beside && next_offset_.size() != 2 * n + 1) next_offset_.resize(2 * n + 1);
        const detail::neighbour_scan<Coord> scan{grid, walls, skin, near_skin};
        // the near rows' lengths, then the far rows'
        unsigned* offset = beside ? next_offset_.data() : offset_.data();
        for_each_index(Policy{}, n, detail::count_entries<Coord>{scan, offset});
        for_each_index(Policy{}, 1, detail::fill_value<unsigned>{offset + 2 * n, 0u});
        exclusive_scan(ctx, offset, 2 * n + 1);
        // The kept entries are at most the old lists' entries: only the new ones can wrap.
        transform_reduce_into(ctx, 2 * n, detail::row_wraps{offset}, 0u, max_op{}, &totals->wrapped);
        for_each_index(Policy{}, 1,
                       detail::record_totals{kept_offset_.data(), offset, n, kept_capacity(), capacity(),
                                             history_capacity(), totals});
        const detail::old_lists<Real> old{kept_offset_.data(), kept_partner_.data(), kept_history_.view()};
        for_each_index(Policy{}, n,
                       detail::fill_entries<Coord, Real>{scan, offset, partner_.data(), history_.view(), old, keep_order,
                                                         totals});
        if (record_forces_) for_each_index(Policy{}, force_.size(), detail::fill_value<vec4<Real>>{force_.data(), {0, 0, 0, 0}});
        set_wall_ranks(ctx, offset, totals);
        for_each_index(Policy{}, 2 * n + 1, detail::empty_if_overflow{offset, totals});
        if (keep_order) {
            if (slot_of_rank_.size() != n) {
                slot_of_rank_.resize(n);
                rank_of_slot_.resize(n);
            }
            for_each_index(Policy{}, n,
                           detail::set_rank_slots{grid.order, totals, slot_of_rank_.data(), rank_of_slot_.data()});
        }
        if (beside) offset_.swap(next_offset_);
        keep_order_ = keep_order;
        old_far_history_ = far_history_;
        far_history_ = false;
        if constexpr (runs_in_blocks<Policy>) set_layers(grid);
    }

    /// Gives the far rows' entries histories (none: they were apart) and recorded forces
    /// (zero), for a step that must walk them, until the next rebuild; false when they had
    /// them already or are empty. The first time, the histories' arrays grow to the lists'
    /// capacity (an allocation, which later lists of no more entries do not repeat).
    bool open_far_rows()
    {
        if (far_history_ || entries_ == near_entries_) return false;
        const std::size_t first = near_entries_, far = entries_ - near_entries_;
        reserve_histories(capacity());
        for_each_index(Policy{}, far,
                       detail::clear_far_histories<Real>{history_.view(), record_forces_ ? force_.data() : nullptr, first});
        far_history_ = true;
        return true;
    }

    /// Makes room for at least `entries` entries (and their histories, far rows' included)
    /// and `kept` carried histories, so that rebuilds up to those sizes neither allocate nor
    /// overflow.
    void reserve(std::size_t entries, std::size_t kept)
    {
        if (entries > capacity()) partner_.resize(entries);
        reserve_histories(entries);
        if (kept > kept_capacity()) {
            kept_partner_.resize(kept);
            kept_history_.resize(kept);
        }
    }

    /// Takes the totals of the last rebuild, read back. Returns true when its lists are
    /// complete. After an overflow it grows the capacities (to what the rebuild needed, with
    /// `headroom` a quarter above), puts the old lists back in use when their histories did not
    /// fit, and returns false: the caller puts the particles back where they were and rebuilds
    /// again.
    bool settle(const list_totals& t, bool headroom = true)
    {
        if (t.wrapped)
            detail::fail("contact lists: a rebuild found more than 4294967295 contact entries, more than their 32-bit "
                         "offsets hold; use a smaller skin or fewer particles per simulation");
        if (!t.overflow) {
            entries_ = t.entries;
            near_entries_ = t.near_entries;
            wall_particles_ = t.wall_particles;
            histories_kept_ = false;
            return true;
        }
        ++overflows_;
        if (t.kept > kept_capacity()) {
            offset_.swap(next_offset_); // the old lists are whole: their histories were not copied
            if constexpr (runs_in_blocks<Policy>) next_offset_ = buffer<unsigned, Policy>(); // see rebuild()
            far_history_ = old_far_history_;
            histories_kept_ = false;
        }
        const auto grown = [&](std::size_t needed) { return headroom ? needed + needed / 4 + 64 : needed; };
        if (t.entries > capacity()) partner_.resize(grown(t.entries));
        if (t.near_entries > history_capacity()) reserve_histories(grown(t.near_entries));
        if (t.kept > kept_capacity()) reserve(0, grown(t.kept));
        return false;
    }

    contact_view<Real> view()
    {
        return {size(),
                offset_.data(),
                partner_.data(),
                history_.view(),
                record_forces_ ? force_.data() : nullptr,
                keep_order_ ? slot_of_rank_.data() : nullptr,
                keep_order_ ? rank_of_slot_.data() : nullptr,
                far_history_};
    }

    /// A host copy in user order, each pair from both sides; `user` is the user index of each
    /// storage slot.
    contact_table<Coord> table(const std::vector<unsigned>& user) const
    {
        const std::size_t n = size();
        const std::vector<unsigned> off = offset_.to_host(), part = partner_.to_host();
        const std::vector<vec4<Real>> hist = history_.to_host();
        const std::vector<Real> lanes = history_.lanes_to_host();
        const history_shape shape = history_.shape();
        std::vector<vec4<Real>> frc;
        if (record_forces_) frc = force_.to_host();
        const std::vector<unsigned> slots = keep_order_ ? slot_of_rank_.to_host() : std::vector<unsigned>{};
        // every entry twice (pairs) or once (walls), as (owner, partner, entry, mirrored)
        struct item {
            unsigned owner, partner, entry; // not `particle`: clang 14 reads `a.particle <` as the
                                            // template particle<...>
            bool mirrored;
        };
        std::vector<item> items;
        items.reserve(2 * part.size());
        for (std::size_t r = 0; r < n; ++r) {
            const unsigned me = user[keep_order_ ? slots[r] : r];
            const auto add = [&](unsigned e) {
                if (part[e] >= wall_partner_base) {
                    items.push_back({me, part[e], e, false});
                } else {
                    items.push_back({me, user[part[e]], e, false});
                    items.push_back({user[part[e]], me, e, true});
                }
            };
            for (unsigned e = off[r]; e < off[r + 1]; ++e) add(e);
            for (unsigned e = off[n + r]; e < off[n + r + 1]; ++e) add(e);
        }
        std::sort(items.begin(), items.end(), [](const item& a, const item& b) {
            return a.owner != b.owner ? a.owner < b.owner : a.partner < b.partner;
        });
        contact_table<Coord> t;
        t.offset.assign(n + 1, 0);
        for (const item& it : items) ++t.offset[it.owner + 1];
        for (std::size_t i = 0; i < n; ++i) t.offset[i + 1] += t.offset[i];
        t.partner.reserve(items.size());
        t.history.reserve(items.size());
        t.shape = shape;
        t.lane.reserve(items.size() * shape.lanes);
        if (record_forces_) t.force.reserve(items.size());
        for (const item& it : items) {
            t.partner.push_back(it.partner);
            // a far row's entry without a history has none and no force (it is apart)
            const bool stored = far_history_ || it.entry < off[n];
            const vec4<Real> h = stored ? hist[it.entry] : vec4<Real>{0, 0, 0, 0};
            t.history.push_back(vec_cast<Coord>(it.mirrored ? mirrored(h) : h));
            for (unsigned l = 0; l < shape.lanes; ++l) {
                const Real v = stored ? lanes[it.entry * shape.lanes + l] : Real(0);
                t.lane.push_back(Coord(it.mirrored && (shape.mirror >> l & 1u) ? -v : v));
            }
            if (record_forces_) {
                const vec4<Real> f = stored ? frc[it.entry] : vec4<Real>{0, 0, 0, 0};
                t.force.push_back(vec_cast<Coord>(it.mirrored ? mirrored(f) : f));
            }
        }
        return t;
    }

    /// Replaces the lists by a table in user order (for restarts): `grid` is built over the
    /// positions of the last rebuild in user order (its `order` holds the user index of each
    /// rank), and the particles are stored in rank order unless `keep_order` (then in user
    /// order). Each pair takes the history its owner's entry has in the table; the partners
    /// within r_a + r_b + near_skin of those positions go to the near rows, as rebuild() puts
    /// them, and the far rows have histories (a restored table's far pairs may have one).
    /// Throws when the table does not fit or is not symmetric.
    void restore(const contact_table<Coord>& t, const grid_view<Coord>& grid, Coord near_skin, bool keep_order)
    {
        const std::size_t n = size();
        const history_shape shape = history_.shape();
        if (t.particles() != n || t.partner.size() != t.offset[n] || t.history.size() != t.partner.size())
            detail::fail("contact lists: the restored table does not fit ", n, " particles");
        if (t.shape.lanes != shape.lanes || t.lane.size() != t.partner.size() * shape.lanes)
            detail::fail("contact lists: the restored table's histories have ", t.shape.lanes,
                         " lanes beside the base, the contact law's have ", shape.lanes);
        const std::vector<unsigned> user_of_rank = buffer_copy(grid.order, n);
        // the positions of the last rebuild (a grid over them without reference positions)
        const std::vector<vec4<Coord>> x = buffer_copy(grid.sorted_x.x, n);
        std::vector<unsigned> rank_of_user(n);
        for (std::size_t r = 0; r < n; ++r) rank_of_user[user_of_rank[r]] = static_cast<unsigned>(r);
        const grid_geometry<Coord>& g = grid.geometry;
        auto layer = [&](unsigned r) { return g.coordinate(x[r].xyz()[g.slow], g.slow); };
        const int layers = static_cast<int>(g.n[g.slow]);
        auto owns = [&](unsigned a, unsigned b) { // ranks
            const int la = layer(a), lb = layer(b);
            if (la == lb) return a < b;
            return lb == la + 1 || (g.box.periodic(g.slow) && layers >= 3 && la == layers - 1 && lb == 0);
        };
        std::vector<unsigned> off(2 * n + 1, 0), part, far_part;
        std::vector<vec4<Real>> hist, far_hist;
        std::vector<Real> lanes, far_lanes;
        std::vector<std::size_t> far_rows(n + 1, 0);
        // the table's entry e as the lists store it: its partner, its base, then its lanes
        auto take = [&](bool near, unsigned code, std::size_t e) {
            (near ? part : far_part).push_back(code);
            (near ? hist : far_hist).push_back(vec_cast<Real>(t.history[e]));
            for (unsigned l = 0; l < shape.lanes; ++l) (near ? lanes : far_lanes).push_back(Real(t.lane[e * shape.lanes + l]));
        };
        for (std::size_t r = 0; r < n; ++r) {
            const unsigned i = user_of_rank[r];
            std::vector<std::pair<unsigned, std::size_t>> row, walls; // (partner rank or wall code, table entry)
            for (std::size_t e = t.begin(i); e < t.end(i); ++e) {
                const unsigned j = t.partner[e];
                if (j >= wall_partner_base) {
                    if (j >= wall_partner_base + unsigned(wall_set<Coord>::count))
                        detail::fail("contact lists: particle ", i, " lists wall code ", j, ", not a wall face");
                    walls.emplace_back(j, e);
                    continue;
                }
                if (j >= n) detail::fail("contact lists: particle ", i, " lists partner ", j, ", but there are ", n, " particles");
                if (t.find(j, unsigned(i)) == ~std::size_t(0))
                    detail::fail("contact lists: particle ", i, " lists partner ", j, ", but ", j, " does not list ", i);
                const unsigned q = rank_of_user[j];
                if (!owns(unsigned(r), q) && !owns(q, unsigned(r)))
                    detail::fail("contact lists: particle ", i, " lists partner ", j,
                                 ", but their positions at the last rebuild lie more than one grid layer apart");
                if (owns(unsigned(r), q)) row.emplace_back(q, e);
            }
            std::sort(row.begin(), row.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
            std::sort(walls.begin(), walls.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
            for (const auto& [q, e] : row)
                take(detail::within_skin(g.box, x[r], x[q], near_skin), keep_order ? user_of_rank[q] : q, e);
            for (const auto& [code, e] : walls) take(true, code, e);
            off[r + 1] = static_cast<unsigned>(part.size());
            far_rows[r + 1] = far_part.size();
        }
        std::vector<unsigned> wall_ranks(n, no_rank);
        std::size_t with_walls = 0;
        for (std::size_t r = 0; r < n; ++r)
            if (detail::row_has_walls(off.data(), part.data(), r)) wall_ranks[with_walls++] = unsigned(r);
        near_entries_ = part.size();
        for (std::size_t r = 0; r <= n; ++r) off[n + r] = static_cast<unsigned>(near_entries_ + far_rows[r]);
        part.insert(part.end(), far_part.begin(), far_part.end());
        hist.insert(hist.end(), far_hist.begin(), far_hist.end());
        lanes.insert(lanes.end(), far_lanes.begin(), far_lanes.end());
        offset_.assign(off);
        partner_.assign(part);
        history_.assign(hist, lanes);
        wall_ranks_.assign(wall_ranks);
        entries_ = part.size();
        wall_particles_ = with_walls;
        histories_kept_ = false;
        far_history_ = true;
        if (record_forces_) force_.assign(std::vector<vec4<Real>>(part.size(), vec4<Real>{0, 0, 0, 0}));
        keep_order_ = keep_order;
        if (keep_order) {
            slot_of_rank_.assign(user_of_rank);
            rank_of_slot_.assign(rank_of_user);
        }
        if constexpr (runs_in_blocks<Policy>) set_layers(grid);
    }

private:
    std::size_t kept_capacity() const { return kept_partner_.size(); }

    /// Makes room for the histories (and recorded forces) of at least `entries` entries.
    void reserve_histories(std::size_t entries)
    {
        if (entries <= history_capacity()) return;
        history_.resize(entries);
        if (record_forces_) force_.resize(entries);
    }

    /// Copies the entries whose history is not zero (contacts that touched at the last step,
    /// whose history a rebuild carries over) into the kept entries, in rows by slot.
    void keep_histories(execution_context<Policy>& ctx)
    {
        const std::size_t n = size();
        const contact_view<Real> c = view();
        for_each_index(Policy{}, n, detail::count_histories<Real>{c, kept_offset_.data()});
        for_each_index(Policy{}, 1, detail::fill_value<unsigned>{kept_offset_.data() + n, 0u});
        exclusive_scan(ctx, kept_offset_.data(), n + 1);
        for_each_index(Policy{}, n,
                       detail::copy_histories<Real>{c, kept_offset_.data(), kept_capacity(), kept_partner_.data(),
                                                    kept_history_.view()});
    }

    /// The ranks with wall entries in the new lists (rows at `offset`), and their number into
    /// `totals`.
    void set_wall_ranks(execution_context<Policy>& ctx, const unsigned* offset, list_totals* totals)
    {
        const std::size_t n = size();
        if constexpr (runs_in_blocks<Policy>) { // host memory: in one pass, without the scan's array
            unsigned* ranks = wall_ranks_.data();
            std::size_t with = 0;
            if (!totals->overflow)
                for (std::size_t r = 0; r < n; ++r)
                    if (detail::row_has_walls(offset, partner_.data(), r)) ranks[with++] = static_cast<unsigned>(r);
            std::fill(ranks + with, ranks + n, no_rank);
            totals->wall_particles = static_cast<unsigned>(with);
            return;
        }
        if (wall_place_.size() != n + 1) wall_place_.resize(n + 1);
        unsigned* place = wall_place_.data();
        for_each_index(Policy{}, n, detail::has_walls{offset, partner_.data(), totals, place});
        for_each_index(Policy{}, 1, detail::fill_value<unsigned>{place + n, 0u});
        exclusive_scan(ctx, place, n + 1);
        for_each_index(Policy{}, n, detail::fill_value<unsigned>{wall_ranks_.data(), no_rank});
        for_each_index(Policy{}, n, detail::list_wall_ranks{place, wall_ranks_.data()});
        for_each_index(Policy{}, 1, detail::record_wall_particles{place, n, totals});
    }

    /// The layers of the grid as ranks and entries (both rows'), for the host's slab schedule
    /// (reads the grid's cell starts and the offsets in place: host memory).
    void set_layers(const grid_view<Coord>& grid)
    {
        const grid_geometry<Coord>& g = grid.geometry;
        const std::size_t layers = g.layers(), per_layer = g.cells_per_layer(), n = size();
        const unsigned* off = offset_.data();
        layer_start_.resize(layers + 1);
        layer_entries_.resize(layers + 1);
        for (std::size_t l = 0; l <= layers; ++l) {
            layer_start_[l] = grid.cell_start[l * per_layer];
            layer_entries_[l] = off[layer_start_[l]] + (off[n + layer_start_[l]] - off[n]);
        }
        periodic_layers_ = g.box.periodic(g.slow);
    }

    /// A host copy of the first n elements of policy memory.
    template <class T>
    static std::vector<T> buffer_copy(const T* data, std::size_t n)
    {
        buffer<T, Policy> b(n);
        for_each_index(Policy{}, n, detail::copy_back<T>{data, b.data()});
        return b.to_host();
    }

    bool record_forces_ = true;
    bool keep_order_ = false;
    bool periodic_layers_ = false;
    bool histories_kept_ = false; ///< the kept entries hold the histories of the lists in use
    bool far_history_ = false;     ///< far_histories()
    bool old_far_history_ = false; ///< far_history_ of the lists before the last rebuild
    std::size_t entries_ = 0, near_entries_ = 0, overflows_ = 0;
    buffer<unsigned, Policy> offset_;      ///< the near rows, then the far rows (contact_view::offset)
    /// the rows a rebuild counts beside offset_ (then swaps with it); on the host only while
    /// the old lists' histories did not fit the kept entries (rebuild())
    buffer<unsigned, Policy> next_offset_;
    buffer<unsigned, Policy> partner_;     ///< capacity() entries
    history_store<Real, Policy> history_;  ///< history_capacity() entries
    buffer<vec4<Real>, Policy> force_;     ///< history_capacity() entries when recorded
    // The histories a rebuild carries over, in rows by slot (kept between rebuilds: their
    // arrays only grow).
    buffer<unsigned, Policy> kept_offset_, kept_partner_;
    history_store<Real, Policy> kept_history_;
    buffer<unsigned, Policy> slot_of_rank_, rank_of_slot_; ///< only with keep_order
    buffer<unsigned, Policy> wall_ranks_;
    buffer<unsigned, Policy> wall_place_; ///< the scan that places wall_ranks_ (CUDA only)
    std::size_t wall_particles_ = 0;
    std::vector<unsigned> layer_start_, layer_entries_;
};

} // namespace sphere
