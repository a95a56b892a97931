#pragma once
/// \file
/// A contact's history: what a contact law remembers from one step to the next, as the laws
/// see it and as the contact lists store it (contact/contact_lists.cuh).
///
/// Every law keeps a tangential displacement (xyz, m) and whole-number flags (w, 0 to 255;
/// bit 0: sliding, the tangential laws'; bit 1: a liquid bridge, contact::capillary's): the
/// history's `base`, a vec4. A law that remembers more declares
///
///     static constexpr unsigned history_lanes;  // how many more values (at most 8)
///     static constexpr unsigned history_mirror; // bit l set: lane l changes sign when the
///                                               // contact is seen from the other particle
///
/// and its kernels receive a contact_history<Real, history_lanes> (contact::rolling's rolling
/// and twisting angles); the others receive the vec4 itself. Laws that declare nothing cost
/// the lists no memory for lanes.
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "../core/config.cuh"
#include "../core/vec.cuh"
#include "../exec/buffer.cuh"

namespace sphere {

/// The history of a law with `Lanes` values of its own beside the base.
template <class Real, unsigned Lanes>
struct contact_history {
    vec4<Real> base{0, 0, 0, 0}; ///< tangential displacement (m) xyz, flags w
    Real lane[Lanes] = {};       ///< the law's own values (its history_layout names them)
};

/// The base of a history (the vec4 of every law).
template <class Real>
SPHERE_HDI vec4<Real>& history_base(vec4<Real>& h)
{
    return h;
}
template <class Real>
SPHERE_HDI const vec4<Real>& history_base(const vec4<Real>& h)
{
    return h;
}
template <class Real, unsigned Lanes>
SPHERE_HDI vec4<Real>& history_base(contact_history<Real, Lanes>& h)
{
    return h.base;
}
template <class Real, unsigned Lanes>
SPHERE_HDI const vec4<Real>& history_base(const contact_history<Real, Lanes>& h)
{
    return h.base;
}

/// c ? a : b for whole histories, lane by lane (a select that a loop over contacts vectorises).
template <class Real, unsigned Lanes>
SPHERE_HDI contact_history<Real, Lanes> select(bool c, const contact_history<Real, Lanes>& a,
                                               const contact_history<Real, Lanes>& b)
{
    contact_history<Real, Lanes> out;
    out.base = select(c, a.base, b.base);
    for (unsigned l = 0; l < Lanes; ++l) out.lane[l] = c ? a.lane[l] : b.lane[l];
    return out;
}

/// What the contact lists need to know of a law's history: its extra lanes and which of
/// them change sign seen from the other particle.
struct history_shape {
    unsigned lanes = 0;
    unsigned mirror = 0;
    static constexpr unsigned max_lanes = 8;
};

/// The history shape Law declares (none beyond the base unless it declares history_lanes).
template <class Law, class = void>
struct law_history_shape {
    static constexpr history_shape value{0, 0};
};
template <class Law>
struct law_history_shape<Law, std::void_t<decltype(Law::history_lanes)>> {
    static_assert(Law::history_lanes <= history_shape::max_lanes, "a contact history holds at most 8 lanes");
    static constexpr history_shape value{Law::history_lanes, Law::history_mirror};
};

/// The history type Law's kernels receive.
template <class Law, class Real>
using law_history_t = std::conditional_t<law_history_shape<Law>::value.lanes == 0, vec4<Real>,
                                         contact_history<Real, law_history_shape<Law>::value.lanes>>;

/// A contact's history or recorded force as seen from its other particle: the tangential part
/// (xyz: displacement or force) reversed, w (flags, or f_n . n) kept.
template <class Real>
SPHERE_HDI vec4<Real> mirrored(const vec4<Real>& h)
{
    return {-h.x, -h.y, -h.z, h.w};
}

/// Where the contact histories live: each entry's tangential displacement (m) and its flags in
/// two arrays (25 B per entry in double, where one vec4 takes 32), and the lanes of a law that
/// declares some (shape.lanes per entry, entry after entry).
template <class Real>
struct history_view {
    vec3<Real>* shift;
    std::uint8_t* flags;
    Real* lane;
    history_shape shape;

    SPHERE_HDI vec4<Real> base(std::size_t k) const
    {
        const vec3<Real> d = shift[k];
        return {d.x, d.y, d.z, Real(flags[k])};
    }
    SPHERE_HDI void set_base(std::size_t k, const vec4<Real>& h) const
    {
        shift[k] = {h.x, h.y, h.z};
        flags[k] = static_cast<std::uint8_t>(h.w);
    }

    /// Entry k into h (the history type of a law whose shape this is).
    SPHERE_HDI void load(std::size_t k, vec4<Real>& h) const { h = base(k); }
    template <unsigned Lanes>
    SPHERE_HDI void load(std::size_t k, contact_history<Real, Lanes>& h) const
    {
        h.base = base(k);
        for (unsigned l = 0; l < Lanes; ++l) h.lane[l] = lane[k * Lanes + l];
    }
    SPHERE_HDI void store(std::size_t k, const vec4<Real>& h) const { set_base(k, h); }
    template <unsigned Lanes>
    SPHERE_HDI void store(std::size_t k, const contact_history<Real, Lanes>& h) const
    {
        set_base(k, h.base);
        for (unsigned l = 0; l < Lanes; ++l) lane[k * Lanes + l] = h.lane[l];
    }

    /// Entry k forgets its history.
    SPHERE_HDI void clear(std::size_t k) const
    {
        set_base(k, {0, 0, 0, 0});
        for (unsigned l = 0; l < shape.lanes; ++l) lane[k * shape.lanes + l] = Real(0);
    }

    /// Whether entry k has a history to pass on (a contact that touched at the last step).
    SPHERE_HDI bool has(std::size_t k) const
    {
        const vec4<Real> h = base(k);
        bool any = h.x != Real(0) || h.y != Real(0) || h.z != Real(0) || h.w != Real(0);
        for (unsigned l = 0; l < shape.lanes; ++l) any = any || lane[k * shape.lanes + l] != Real(0);
        return any;
    }

    /// Entry k takes entry `from` of `source` (of the same shape), as seen from the contact's
    /// other particle when `mirror`.
    SPHERE_HDI void copy(std::size_t k, const history_view& source, std::size_t from, bool mirror) const
    {
        const vec4<Real> h = source.base(from);
        set_base(k, mirror ? mirrored(h) : h);
        for (unsigned l = 0; l < shape.lanes; ++l) {
            const Real v = source.lane[from * shape.lanes + l];
            lane[k * shape.lanes + l] = mirror && (shape.mirror >> l & 1u) ? -v : v;
        }
    }
};

/// The owning arrays of history_view, in a policy's memory.
template <class Real, class Policy>
class history_store {
public:
    history_store() = default;
    explicit history_store(history_shape shape) : shape_(shape) {}

    std::size_t size() const { return shift_.size(); }
    history_shape shape() const { return shape_; }
    history_view<Real> view() { return {shift_.data(), flags_.data(), lane_.data(), shape_}; }
    /// n entries; those already there keep their values, new ones have no history.
    void resize(std::size_t n)
    {
        shift_.resize(n, vec3<Real>{0, 0, 0});
        flags_.resize(n, std::uint8_t(0));
        if (shape_.lanes) lane_.resize(n * shape_.lanes, Real(0));
    }
    void swap(history_store& other) noexcept
    {
        shift_.swap(other.shift_);
        flags_.swap(other.flags_);
        lane_.swap(other.lane_);
        std::swap(shape_, other.shape_);
    }
    /// A host copy of the bases, one vec4 per entry (xyz displacement, w flags).
    std::vector<vec4<Real>> to_host() const
    {
        const std::vector<vec3<Real>> d = shift_.to_host();
        const std::vector<std::uint8_t> s = flags_.to_host();
        std::vector<vec4<Real>> out(d.size());
        for (std::size_t k = 0; k < d.size(); ++k) out[k] = {d[k].x, d[k].y, d[k].z, Real(s[k])};
        return out;
    }
    /// A host copy of the lanes, shape().lanes per entry.
    std::vector<Real> lanes_to_host() const { return shape_.lanes ? lane_.to_host() : std::vector<Real>{}; }
    /// Bases (flags out of 0 ... 255 become 0) and lanes (shape().lanes per entry).
    void assign(const std::vector<vec4<Real>>& h, const std::vector<Real>& lanes)
    {
        std::vector<vec3<Real>> d(h.size());
        std::vector<std::uint8_t> s(h.size());
        for (std::size_t k = 0; k < h.size(); ++k) {
            d[k] = {h[k].x, h[k].y, h[k].z};
            s[k] = h[k].w >= Real(0) && h[k].w < Real(256) ? static_cast<std::uint8_t>(h[k].w) : std::uint8_t(0);
        }
        shift_.assign(std::move(d));
        flags_.assign(std::move(s));
        if (shape_.lanes) lane_.assign(lanes);
    }

private:
    history_shape shape_;
    buffer<vec3<Real>, Policy> shift_;
    buffer<std::uint8_t, Policy> flags_;
    buffer<Real, Policy> lane_;
};

} // namespace sphere
