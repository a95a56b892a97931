#pragma once
/// \file
/// Contact lists with history, in compressed rows (CSR): the entries of the particle in storage
/// slot k are [offset[k], offset[k + 1]), one for every particle j with
/// |x_k - x_j| < r_k + r_j + skin and one for every wall face within r_k + skin, at the last
/// rebuild. Each entry holds its history (tangential displacement, sliding flag) and, when
/// recorded, the force of the last step. The lists hold what they find: no capacity to set.
///
/// Entries are sorted by the partner's *user* index (walls last, by face), so the order in
/// which a particle sums its contact forces does not depend on where particles are stored, and
/// the history is carried across rebuilds (and the storage permutation that comes with them)
/// by user index.
#include <cstddef>
#include <limits>
#include <vector>

#include "../boundary/walls.cuh"
#include "../core/error.cuh"
#include "../core/precision.cuh"
#include "../core/vec.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/for_each.cuh"
#include "../grid/neighbor_grid.cuh"

namespace sphere {

/// Partner codes from here up name a wall face: wall_partner_base + f. Particle (user and
/// storage) indices stay below it.
inline constexpr unsigned wall_partner_base = 0xFFFFFFF0u;

/// Kernel view of the contact lists (storage order).
template <class Real>
struct contact_view {
    const unsigned* offset;  ///< entries of slot k: [offset[k], offset[k + 1])
    const unsigned* partner; ///< storage slot of the partner, or wall_partner_base + f
    vec4<Real>* history;     ///< delta_t (m) in xyz, sliding flag in w
    vec4<Real>* force;       ///< f_t on this particle (N) in xyz, f_n . n (N) in w; null when not recorded
};

/// A host copy of the contact lists in user order: entries of particle i at
/// [offset[i], offset[i + 1]), partners as user indices (or wall_partner_base + f).
template <class Real>
struct contact_table {
    std::vector<std::size_t> offset{0};
    std::vector<unsigned> partner;
    std::vector<vec4<Real>> history;
    std::vector<vec4<Real>> force; ///< empty when the simulation records no contact forces

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
/// Scans the neighbour cells of the particle at new (sorted) position k and visits every
/// partner within reach, and every active wall within r + skin: `visit(partner_code, key)`
/// with the partner's new slot (or wall code) and its sort key (user index, or the wall code).
template <class Real>
struct neighbour_scan {
    grid_view<Real> grid;
    wall_set<Real> walls;
    Real skin;
    const unsigned* user; ///< user index of each slot *before* the permutation (grid.order maps)
    bool keep_order;      ///< the particles stay in their slots: lists and partners by old slot

    /// The slot the particle at sorted position k will have: k after the permutation into
    /// the grid's order, its old slot when the order is kept.
    SPHERE_HD unsigned slot(std::size_t k) const { return keep_order ? grid.order[k] : static_cast<unsigned>(k); }

    template <class Visit>
    SPHERE_HD void operator()(std::size_t k, Visit& visit) const
    {
        const grid_geometry<Real>& g = grid.geometry;
        const vec4<Real> xi = grid.sorted_x[k];
        const int ci[3] = {g.coordinate(xi.x, 0), g.coordinate(xi.y, 1), g.coordinate(xi.z, 2)};
        const int nx = static_cast<int>(g.n[0]);
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy) {
                int cy = ci[1] + dy, cz = ci[2] + dz;
                if (!wrap_or_reject(cy, 1) || !wrap_or_reject(cz, 2)) continue;
                // The row's cells ci[0]-1 .. ci[0]+1 along x: one run of sorted positions, or two
                // when a periodic x wraps around.
                int x0 = ci[0] - 1, x1 = ci[0] + 1;
                int wrapped0 = 0, wrapped1 = -1;
                if (g.box.periodic(0)) {
                    if (x0 < 0) { wrapped0 = wrapped1 = nx - 1; x0 = 0; }
                    if (x1 >= nx) { wrapped0 = wrapped1 = 0; x1 = nx - 1; }
                } else {
                    x0 = x0 < 0 ? 0 : x0;
                    x1 = x1 >= nx ? nx - 1 : x1;
                }
                scan_run(k, xi, g.index(x0, cy, cz), g.index(x1, cy, cz), visit);
                if (wrapped1 >= 0) scan_run(k, xi, g.index(wrapped0, cy, cz), g.index(wrapped1, cy, cz), visit);
            }
        for (int f = 0; f < wall_set<Real>::count; ++f) {
            const wall_face<Real>& w = walls.face[f];
            if (!w.active) continue;
            const int a = f / 2;
            const Real gap = (xi.xyz()[a] - Real(w.position)) * wall_set<Real>::inward_normal(f)[a] - xi.w;
            if (gap < skin) visit(wall_partner_base + unsigned(f), wall_partner_base + unsigned(f));
        }
    }

private:
    /// Wraps cell coordinate c on a periodic axis; false when it lies outside a wall axis.
    SPHERE_HD bool wrap_or_reject(int& c, int a) const
    {
        const int n = static_cast<int>(grid.geometry.n[a]);
        if (grid.geometry.box.periodic(a)) {
            c = (c + n) % n;
            return true;
        }
        return c >= 0 && c < n;
    }

    template <class Visit>
    SPHERE_HD void scan_run(std::size_t k, const vec4<Real>& xi, unsigned first_cell, unsigned last_cell,
                            Visit& visit) const
    {
        const unsigned end = grid.cell_start[last_cell + 1];
        for (unsigned q = grid.cell_start[first_cell]; q < end; ++q) {
            if (q == k) continue;
            const vec4<Real> xj = grid.sorted_x[q];
            const Real reach = xi.w + xj.w + skin;
            if (norm2(grid.geometry.box.nearest_image(xi.xyz() - xj.xyz())) < reach * reach)
                visit(slot(q), user[grid.order[q]]);
        }
    }
};

struct count_visit {
    unsigned found = 0;
    SPHERE_HD void operator()(unsigned, unsigned) { ++found; }
};

template <class Real>
struct count_entries {
    neighbour_scan<Real> scan;
    unsigned* count;
    SPHERE_HD void operator()(std::size_t k) const
    {
        count_visit v;
        scan(k, v);
        count[scan.slot(k)] = v.found;
    }
};

struct fill_visit {
    unsigned* partner;
    unsigned* key;
    unsigned found = 0;
    SPHERE_HD void operator()(unsigned code, unsigned sort_key)
    {
        partner[found] = code;
        key[found] = sort_key;
        ++found;
    }
};

/// Fills the new list of sorted position k, sorted by partner key, and carries over the
/// history of the partners that the particle's old list (at its old slot) already had.
/// Positions in Coord, histories in Real.
template <class Coord, class Real>
struct fill_entries {
    neighbour_scan<Coord> scan;
    const unsigned* offset;
    unsigned* partner;
    unsigned* key; ///< scratch: each entry's sort key
    vec4<Real>* history;
    const unsigned* old_offset;
    const unsigned* old_partner;
    const vec4<Real>* old_history;

    SPHERE_HD void operator()(std::size_t k) const
    {
        const unsigned at = scan.slot(k), begin = offset[at], n = offset[at + 1] - begin;
        fill_visit v{partner + begin, key + begin};
        scan(k, v);
        unsigned* p = partner + begin;
        unsigned* s = key + begin;
        for (unsigned a = 1; a < n; ++a) { // insertion sort by key: lists are short
            const unsigned pv = p[a], sv = s[a];
            unsigned b = a;
            for (; b > 0 && s[b - 1] > sv; --b) {
                p[b] = p[b - 1];
                s[b] = s[b - 1];
            }
            p[b] = pv;
            s[b] = sv;
        }
        const unsigned o = scan.grid.order[k]; // the particle's slot before the permutation
        const unsigned old_begin = old_offset[o], old_end = old_offset[o + 1];
        unsigned m = old_begin;
        for (unsigned a = 0; a < n; ++a) {
            // old partners are old slots: their keys are user indices (or wall codes)
            while (m < old_end && old_key(m) < s[a]) ++m;
            history[begin + a] = (m < old_end && old_key(m) == s[a]) ? old_history[m] : vec4<Real>{0, 0, 0, 0};
        }
    }

private:
    SPHERE_HD unsigned old_key(unsigned m) const
    {
        const unsigned q = old_partner[m];
        return q >= wall_partner_base ? q : scan.user[q];
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
    /// Empty lists for n particles; `record_forces` keeps each entry's force of the last step.
    contact_lists(std::size_t n, bool record_forces)
        : record_forces_(record_forces), offset_(n + 1, 0u), new_offset_(n + 1, 0u)
    {
    }

    std::size_t size() const { return offset_.size() - 1; }
    /// Entries in all lists.
    std::size_t entries() const { return entries_; }
    bool records_forces() const { return record_forces_; }

    /// Rebuilds every list from a grid built over the particles before their permutation into
    /// the grid's order (`user` is the user index of each slot before it): the new lists are
    /// in the new order, or in the old one with `keep_order`. Walls within r + skin are listed too.
    void rebuild(const grid_view<Coord>& grid, const wall_set<Coord>& walls, Coord skin, const unsigned* user,
                 bool keep_order = false)
    {
        const std::size_t n = size();
        const detail::neighbour_scan<Coord> scan{grid, walls, skin, user, keep_order};
        for_each_index(Policy{}, n, detail::count_entries<Coord>{scan, new_offset_.data()});
        const std::size_t total = exclusive_scan_in_place(Policy{}, new_offset_.data(), n + 1);
        if (total >= std::size_t(std::numeric_limits<unsigned>::max()))
            detail::fail("contact lists: ", total, " entries within r_i + r_j + skin, more than 2^32 - 1; reduce the skin");
        for (buffer<unsigned, Policy>* b : {&new_partner_, &key_})
            if (b->size() < total) b->resize(total);
        if (new_history_.size() < total) new_history_.resize(total);
        for_each_index(Policy{}, n,
                       detail::fill_entries<Coord, Real>{scan, new_offset_.data(), new_partner_.data(), key_.data(),
                                                  new_history_.data(), offset_.data(), partner_.data(),
                                                  history_.data()});
        offset_.swap(new_offset_);
        partner_.swap(new_partner_);
        history_.swap(new_history_);
        entries_ = total;
        if (record_forces_ && force_.size() < total) force_.resize(total); // the interaction writes every entry
    }

    contact_view<Real> view()
    {
        return {offset_.data(), partner_.data(), history_.data(), record_forces_ ? force_.data() : nullptr};
    }

    /// A host copy in user order; `user` is the user index of each storage slot.
    contact_table<Coord> table(const std::vector<unsigned>& user) const
    {
        const std::size_t n = size();
        const std::vector<unsigned> off = offset_.to_host(), part = partner_.to_host();
        const std::vector<vec4<Real>> hist = history_.to_host();
        std::vector<vec4<Real>> frc;
        if (record_forces_) frc = force_.to_host();
        std::vector<std::size_t> slot_of(n);
        for (std::size_t k = 0; k < n; ++k) slot_of[user[k]] = k;
        contact_table<Coord> t;
        t.offset.assign(n + 1, 0);
        for (std::size_t i = 0; i < n; ++i) t.offset[i + 1] = t.offset[i] + (off[slot_of[i] + 1] - off[slot_of[i]]);
        t.partner.resize(t.offset[n]);
        t.history.resize(t.offset[n]);
        if (record_forces_) t.force.resize(t.offset[n]);
        for (std::size_t i = 0; i < n; ++i) {
            std::size_t e = t.offset[i];
            for (unsigned s = off[slot_of[i]]; s < off[slot_of[i] + 1]; ++s, ++e) {
                t.partner[e] = part[s] >= wall_partner_base ? part[s] : user[part[s]];
                t.history[e] = vec_cast<Coord>(hist[s]);
                if (record_forces_) t.force[e] = vec_cast<Coord>(frc[s]);
            }
        }
        return t;
    }

    /// Replaces the lists and their history by a table in user order (for restarts); `user`
    /// is the user index of each storage slot. Throws when the table does not fit.
    void restore(const contact_table<Coord>& t, const std::vector<unsigned>& user)
    {
        const std::size_t n = size();
        if (t.particles() != n || t.partner.size() != t.offset[n] || t.history.size() != t.partner.size())
            detail::fail("contact lists: the restored table does not fit ", n, " particles");
        std::vector<unsigned> slot_of(n);
        for (std::size_t k = 0; k < n; ++k) slot_of[user[k]] = static_cast<unsigned>(k);
        std::vector<unsigned> off(n + 1, 0), part;
        std::vector<vec4<Real>> hist;
        for (std::size_t k = 0; k < n; ++k) {
            const std::size_t i = user[k];
            for (std::size_t e = t.begin(i); e < t.end(i); ++e) {
                const unsigned j = t.partner[e];
                if (j < wall_partner_base && j >= n)
                    detail::fail("contact lists: particle ", i, " lists partner ", j, ", but there are ", n, " particles");
                if (j >= wall_partner_base + unsigned(wall_set<Real>::count))
                    detail::fail("contact lists: particle ", i, " lists wall code ", j, ", not a wall face");
                part.push_back(j >= wall_partner_base ? j : slot_of[j]);
                hist.push_back(vec_cast<Real>(t.history[e]));
            }
            off[k + 1] = static_cast<unsigned>(part.size());
        }
        offset_.assign(off);
        partner_.assign(part);
        history_.assign(hist);
        entries_ = part.size();
        if (record_forces_) force_.assign(std::vector<vec4<Real>>(part.size(), vec4<Real>{0, 0, 0, 0}));
    }

private:
    bool record_forces_ = true;
    std::size_t entries_ = 0;
    buffer<unsigned, Policy> offset_, partner_;
    buffer<vec4<Real>, Policy> history_, force_;
    buffer<unsigned, Policy> new_offset_, new_partner_, key_;
    buffer<vec4<Real>, Policy> new_history_;
};

} // namespace sphere
