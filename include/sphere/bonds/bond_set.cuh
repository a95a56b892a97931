#pragma once
/// \file
/// The owner of a simulation's bonds: their arrays in the policy's memory, by bond, and the
/// index from each user index to its bonds (built on the host when the bonds change; it does
/// not change when the particles move between slots: only `slot_of` does, by locate()).
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "../core/precision.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/for_each.cuh"
#include "bond_forces.cuh"
#include "bond_table.cuh"

namespace sphere {

template <class Precision, class Policy>
class bond_set {
    using Real = real_t<Precision>;
    using Coord = coord_t<Precision>;

public:
    std::size_t size() const { return rest_.size(); }

    /// Replaces every bond by those of `t` (user indices below `particles`, checked by the
    /// caller); `audit`: keep their dissipation (settings.energy_audit).
    void assign(const bond_table<Coord>& t, std::size_t particles, bool audit)
    {
        const std::size_t count = t.size();
        if (count == 0) { // no arrays at all, not even the index by user
            *this = bond_set();
            return;
        }
        std::vector<unsigned> ends(2 * count), first(particles + 1, 0), entries(2 * count), broken(count);
        for (std::size_t k = 0; k < count; ++k) {
            ends[2 * k] = t.i[k];
            ends[2 * k + 1] = t.j[k];
            ++first[t.i[k] + 1];
            ++first[t.j[k] + 1];
            broken[k] = t.broken[k];
        }
        for (std::size_t u = 0; u < particles; ++u) first[u + 1] += first[u];
        std::vector<unsigned> next(first.begin(), first.end() - 1);
        for (std::size_t e = 0; e < 2 * count; ++e) entries[next[ends[e]]++] = static_cast<unsigned>(e);
        ends_.assign(ends);
        first_.assign(first);
        entries_.assign(entries);
        rest_.assign(t.rest);
        shear_.assign(converted<vec4<Real>>(t.shear));
        bend_.assign(converted<vec3<Real>>(t.bend));
        broken_.assign(broken);
        released_.assign(converted<Real>(t.released));
        dissipated_ = buffer<Real, Policy>();
        rate_ = buffer<Real, Policy>();
        if (audit) {
            dissipated_.assign(converted<Real>(t.dissipated));
            rate_.resize(count, Real(0));
        }
        force_.assign(converted<vec3<Real>>(t.force));
        torque_i_.assign(converted<vec3<Real>>(t.torque_i));
        torque_j_.assign(converted<vec3<Real>>(t.torque_j));
        slot_of_.resize(particles);
    }

    /// A host copy of every bond.
    bond_table<Coord> table() const
    {
        bond_table<Coord> t;
        const std::vector<unsigned> ends = ends_.to_host(), broken = broken_.to_host();
        for (std::size_t k = 0; k < size(); ++k) {
            t.i.push_back(ends[2 * k]);
            t.j.push_back(ends[2 * k + 1]);
            t.broken.push_back(static_cast<std::uint8_t>(broken[k]));
        }
        t.rest = rest_.to_host();
        t.shear = converted<vec4<Coord>>(shear_.to_host());
        t.bend = converted<vec3<Coord>>(bend_.to_host());
        t.released = converted<Coord>(released_.to_host());
        t.dissipated = dissipated_.size() ? converted<Coord>(dissipated_.to_host()) : std::vector<Coord>(size(), Coord(0));
        t.force = converted<vec3<Coord>>(force_.to_host());
        t.torque_i = converted<vec3<Coord>>(torque_i_.to_host());
        t.torque_j = converted<vec3<Coord>>(torque_j_.to_host());
        return t;
    }

    bond_view<Precision> view()
    {
        return {size(),          ends_.data(),     rest_.data(),     shear_.data(),     bend_.data(),
                broken_.data(),  released_.data(), dissipated_.size() ? dissipated_.data() : nullptr,
                rate_.size() ? rate_.data() : nullptr, force_.data(), torque_i_.data(), torque_j_.data(),
                slot_of_.data(), first_.data(),    entries_.data()};
    }

    /// Learns the slot of every user index from the particles (after they moved).
    void locate(const particle_view<Precision>& p)
    {
        if (size()) for_each_index(Policy{}, p.n, detail::locate_bond_ends<Precision>{p, slot_of_.data()});
    }

    /// How many bonds have broken.
    std::size_t broken() const
    {
        return size() ? transform_reduce(Policy{}, size(), detail::broken_bond{broken_.data()}, std::size_t(0), plus_op{}) : 0;
    }

private:
    /// The values of `from` in another precision (Real on the device, Coord on the host).
    template <class To, class From>
    static std::vector<To> converted(const std::vector<From>& from)
    {
        std::vector<To> out(from.size());
        for (std::size_t k = 0; k < from.size(); ++k) {
            if constexpr (std::is_arithmetic_v<To>) out[k] = To(from[k]);
            else out[k] = vec_cast<decltype(To{}.x)>(from[k]);
        }
        return out;
    }

    buffer<unsigned, Policy> ends_, first_, entries_, broken_, slot_of_;
    buffer<Coord, Policy> rest_;
    buffer<vec4<Real>, Policy> shear_;
    buffer<vec3<Real>, Policy> bend_, force_, torque_i_, torque_j_;
    buffer<Real, Policy> released_, dissipated_, rate_;
};

} // namespace sphere
