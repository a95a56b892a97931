#pragma once
/// \file
/// Per-particle contact lists with history. Each particle i keeps, sorted by partner index,
/// every j with |x_i - x_j| < r_i + r_j + skin at the last rebuild, and for each a history
/// entry (tangential displacement, sliding flag). Entries are keyed by the user's particle
/// indices, so the history survives the grid's reordering. Walls have one entry per face.
///
/// `rebuild` returns the first particle that found more partners than the capacity; the
/// simulation turns that into a sphere::error naming the particle: no contact is dropped
/// silently.
#include <cstddef>
#include <vector>

#include "../boundary/walls.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/for_each.cuh"
#include "../grid/neighbor_grid.cuh"

namespace sphere {

/// Kernel view of the contact lists.
template <class Real>
struct contact_view {
    std::size_t capacity;
    const unsigned* count;  ///< number of partners of particle i (may exceed capacity on overflow)
    const unsigned* partner;///< partner of entry k of particle i at [i * capacity + k]
    vec4<Real>* history;    ///< history of that entry: delta_t (m) in xyz, sliding flag in w
    vec4<Real>* force;      ///< force of that entry in the last step: f_t (N) in xyz, f_n . n (N) in w
    vec4<Real>* wall_history; ///< history of particle i against wall face f at [i * 6 + f]
    vec3<Real>* wall_force; ///< force of wall face f on particle i (N), normal and friction, [i * 6 + f]
};

namespace detail {
/// Builds the new partner list of the particle at sorted position k (neighbouring threads
/// then read neighbouring cells) and carries over the history of partners already listed.
template <class Real>
struct build_contact_list {
    grid_view<Real> grid;
    Real skin;
    std::size_t capacity;
    const unsigned* old_count;
    const unsigned* old_partner;
    const vec4<Real>* old_history;
    unsigned* count;
    unsigned* partner;
    vec4<Real>* history;

    SPHERE_HD void operator()(std::size_t k) const
    {
        const grid_geometry<Real>& g = grid.geometry;
        const std::size_t i = grid.order[k];
        const vec4<Real> xi = grid.sorted_x[k];
        const int ci[3] = {g.coordinate(xi.x, 0), g.coordinate(xi.y, 1), g.coordinate(xi.z, 2)};
        const int nx = static_cast<int>(g.n[0]);
        unsigned* mine = partner + i * capacity;
        unsigned found = 0;
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
                found = scan_run(i, xi, g.index(x0, cy, cz), g.index(x1, cy, cz), mine, found);
                if (wrapped1 >= 0) found = scan_run(i, xi, g.index(wrapped0, cy, cz), g.index(wrapped1, cy, cz), mine, found);
            }
        count[i] = found;
        const unsigned kept = found < capacity ? found : static_cast<unsigned>(capacity);
        for (unsigned a = 1; a < kept; ++a) { // insertion sort by partner index: lists are short
            const unsigned v = mine[a];
            unsigned b = a;
            for (; b > 0 && mine[b - 1] > v; --b) mine[b] = mine[b - 1];
            mine[b] = v;
        }
        const unsigned* before = old_partner + i * capacity;
        const unsigned old_kept = old_count[i] < capacity ? old_count[i] : static_cast<unsigned>(capacity);
        unsigned m = 0;
        for (unsigned a = 0; a < kept; ++a) {
            while (m < old_kept && before[m] < mine[a]) ++m;
            history[i * capacity + a] =
                (m < old_kept && before[m] == mine[a]) ? old_history[i * capacity + m] : vec4<Real>{0, 0, 0, 0};
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

    /// Lists every particle of cells [first_cell, last_cell] within reach of particle i;
    /// returns the updated number found (entries beyond the capacity are counted, not stored).
    SPHERE_HD unsigned scan_run(std::size_t i, const vec4<Real>& xi, unsigned first_cell, unsigned last_cell,
                                unsigned* mine, unsigned found) const
    {
        const unsigned end = grid.cell_start[last_cell + 1];
        for (unsigned k = grid.cell_start[first_cell]; k < end; ++k) {
            const unsigned j = grid.order[k];
            if (j == i) continue;
            const vec4<Real> xj = grid.sorted_x[k];
            const Real reach = xi.w + xj.w + skin;
            if (norm2(grid.geometry.box.nearest_image(xi.xyz() - xj.xyz())) < reach * reach) {
                if (found < capacity) mine[found] = j;
                ++found;
            }
        }
        return found;
    }
};

struct overflow_index {
    const unsigned* count;
    std::size_t capacity;
    SPHERE_HD std::size_t operator()(std::size_t i) const { return count[i] > capacity ? i : ~std::size_t(0); }
};
} // namespace detail

template <class Real, class Policy>
class contact_lists {
public:
    contact_lists() = default;
    contact_lists(std::size_t n, std::size_t capacity)
        : capacity_(capacity), count_(n, 0u), partner_(n * capacity, 0u), history_(n * capacity),
          force_(n * capacity), wall_history_(n * wall_set<Real>::count, vec4<Real>{0, 0, 0, 0}),
          wall_force_(n * wall_set<Real>::count, vec3<Real>{0, 0, 0}), new_count_(n, 0u), new_partner_(n * capacity, 0u),
          new_history_(n * capacity)
    {
    }

    std::size_t capacity() const { return capacity_; }
    std::size_t size() const { return count_.size(); }

    /// Rebuilds every list from a built grid; returns the first particle whose partners
    /// exceed the capacity, or ~0 when none does.
    std::size_t rebuild(const grid_view<Real>& grid, Real skin)
    {
        const std::size_t n = count_.size();
        for_each_index(Policy{}, n,
                       detail::build_contact_list<Real>{grid, skin, capacity_, count_.data(), partner_.data(),
                                                        history_.data(), new_count_.data(), new_partner_.data(),
                                                        new_history_.data()});
        count_.swap(new_count_);
        partner_.swap(new_partner_);
        history_.swap(new_history_);
        return transform_reduce(Policy{}, n, detail::overflow_index{count_.data(), capacity_}, ~std::size_t(0),
                                min_op{});
    }

    /// Number of partners listed for particle i (host copy; for diagnostics and errors).
    unsigned count_of(std::size_t i) const { return count_.to_host()[i]; }

    contact_view<Real> view()
    {
        return {capacity_,     count_.data(),        partner_.data(),
                history_.data(), force_.data(),        wall_history_.data(),
                wall_force_.data()};
    }

    /// Host copies for checkpoints and tests.
    std::vector<unsigned> counts() const { return count_.to_host(); }
    std::vector<unsigned> partners() const { return partner_.to_host(); }
    std::vector<vec4<Real>> histories() const { return history_.to_host(); }
    std::vector<vec4<Real>> wall_histories() const { return wall_history_.to_host(); }
    std::vector<vec4<Real>> forces() const { return force_.to_host(); }
    std::vector<vec3<Real>> wall_forces() const { return wall_force_.to_host(); }

    /// Replaces the lists and their history (for restarts); sizes must match this store's.
    void restore(const std::vector<unsigned>& counts, const std::vector<unsigned>& partners,
                 const std::vector<vec4<Real>>& histories, const std::vector<vec4<Real>>& wall_histories)
    {
        if (counts.size() != count_.size() || partners.size() != partner_.size() ||
            histories.size() != history_.size() || wall_histories.size() != wall_history_.size())
            detail::fail("contact lists: restored arrays have the wrong sizes for ", count_.size(),
                         " particles with capacity ", capacity_);
        count_.assign(counts);
        partner_.assign(partners);
        history_.assign(histories);
        wall_history_.assign(wall_histories);
    }

private:
    std::size_t capacity_ = 0;
    buffer<unsigned, Policy> count_, partner_;
    buffer<vec4<Real>, Policy> history_, force_, wall_history_;
    buffer<vec3<Real>, Policy> wall_force_;
    buffer<unsigned, Policy> new_count_, new_partner_;
    buffer<vec4<Real>, Policy> new_history_;
};

} // namespace sphere
