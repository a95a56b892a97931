#pragma once
/// \file
/// Particle state as structure-of-arrays in a policy's memory, its kernel view, and a host
/// snapshot of it. The arrays are stored in an order of the library's choosing (the neighbour
/// grid's cell order, set by `permute` at each rebuild); `user[k]` is the index the user gave
/// the particle in storage slot k. Snapshots and restores speak in user indices.
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "../core/constants.cuh"
#include "../core/precision.cuh"
#include "../core/vec.cuh"
#include "../exec/algorithms.cuh"
#include "../exec/buffer.cuh"
#include "../exec/for_each.cuh"
#include "particle.cuh"

namespace sphere {

/// Raw pointers to every per-particle field; trivially copyable, handed to kernels by value.
/// P is a precision policy (core/precision.cuh): positions and radii in coord_t<P>, the rest
/// in real_t<P>.
template <class P>
struct particle_view {
    using Real = real_t<P>;
    using Coord = coord_t<P>;
    std::size_t n;
    vec4<Coord>* x;         ///< position (m) in xyz, radius (m) in w
    vec3<Real>* v;          ///< velocity (m/s)
    vec3<Real>* omega;      ///< angular velocity (rad/s)
    vec3<Real>* v_sync;     ///< velocity at the time of the positions (m/s), seen by contact laws
    vec3<Real>* omega_sync; ///< angular velocity at the time of the positions (rad/s)
    vec3<Real>* angpos;     ///< integrated angular position (rad); null without settings.angular_position
    vec3<Real>* force;      ///< sum of contact forces of the last step (N), without gravity
    vec3<Real>* torque;     ///< sum of contact torques of the last step (N m)
    Real* mass;             ///< (kg)
    // The energy audit (null without it: settings.energy_audit)
    Real* pressure;         ///< sum of normal contact force magnitudes over the surface, 4 pi r^2 (Pa)
    Real* e_visc;           ///< energy dissipated by normal and tangential viscous damping (J)
    Real* e_fric;           ///< energy dissipated by Coulomb sliding (J)
    Real* p_visc;           ///< rate of e_visc in the last step (W)
    Real* p_fric;           ///< rate of e_fric in the last step (W)
    std::uint8_t* kind;     ///< motion, as its underlying value
    std::uint8_t* material; ///< material index (contact::materials)
    unsigned* user;         ///< the user's index of the particle in each storage slot
    /// Displacement since the simulation began, sum of v dt (m), in coord_t<P> (a sum of small
    /// steps that float would round away in mixed precision); null without
    /// settings.accumulated_displacement.
    vec3<Coord>* displacement;
};

namespace detail {
/// to[k] = from[order[k]] (kernel body of a permutation).
template <class T>
struct gather {
    const T* from;
    const unsigned* order;
    T* to;
    SPHERE_HD void operator()(std::size_t k) const { to[k] = from[order[k]]; }
};

/// to[order[k]] = from[k] (kernel body of the inverse of gather).
template <class T>
struct scatter {
    const T* from;
    const unsigned* order;
    T* to;
    SPHERE_HD void operator()(std::size_t k) const { to[order[k]] = from[k]; }
};

/// Coordinate C (0 .. 2: x, y, z; 3: the radius) of a position and radius.
template <int C, class Coord>
SPHERE_HDI Coord& coordinate(vec4<Coord>& v)
{
    if constexpr (C == 0) return v.x;
    else if constexpr (C == 1) return v.y;
    else if constexpr (C == 2) return v.z;
    else return v.w;
}

/// Coordinate C of the position of slot order[k] into to[k] (Gather, like gather), or that of
/// slot k into to[order[k]] (like scatter).
template <int C, class Coord, bool Gather>
struct move_coordinate {
    vec4<Coord>* x;
    const unsigned* order;
    Coord* to;
    SPHERE_HD void operator()(std::size_t k) const
    {
        if constexpr (Gather) to[k] = coordinate<C>(x[order[k]]);
        else to[order[k]] = coordinate<C>(x[k]);
    }
};

/// Coordinate C of x[k] = from[k].
template <int C, class Coord>
struct set_coordinate {
    const Coord* from;
    vec4<Coord>* x;
    SPHERE_HD void operator()(std::size_t k) const { coordinate<C>(x[k]) = from[k]; }
};

/// to[k] = from[k] (kernel body of a copy).
template <class T>
struct copy_back {
    const T* from;
    T* to;
    SPHERE_HD void operator()(std::size_t k) const { to[k] = from[k]; }
};
} // namespace detail

/// A host copy of every per-particle field, in the user's particle order, in the simulation's
/// user-facing type (coord_t of its precision).
template <class Real>
struct particle_snapshot {
    std::vector<vec4<Real>> x;
    std::vector<vec3<Real>> v, omega, v_sync, omega_sync, angpos, force, torque;
    std::vector<Real> mass, pressure, e_visc, e_fric, p_visc, p_fric;
    std::vector<std::uint8_t> kind;
    std::vector<std::uint8_t> material;
    std::vector<vec3<Real>> displacement; ///< accumulated displacement (m); zeros when not kept

    std::size_t size() const { return x.size(); }
    vec3<Real> position(std::size_t i) const { return x[i].xyz(); }
    Real radius(std::size_t i) const { return x[i].w; }

    /// Particle descriptions from which a simulation is built before it restores a state with
    /// this snapshot (restarts, insertion): positions, radii, velocities, kinds and materials,
    /// densities from the masses (mass / (4/3 pi r^3), in double).
    std::vector<particle<Real>> descriptions() const
    {
        std::vector<particle<Real>> out(size());
        for (std::size_t i = 0; i < size(); ++i) {
            const double r = double(x[i].w);
            out[i].position = position(i);
            out[i].radius = x[i].w;
            out[i].density = Real(double(mass[i]) / (4.0 / 3.0 * pi<double> * r * r * r));
            out[i].velocity = v[i];
            out[i].angular_velocity = omega[i];
            out[i].kind = static_cast<motion>(kind[i]);
            out[i].material = material[i];
        }
        return out;
    }
};

/// The owning particle arrays, in precision P (core/precision.cuh); snapshots and particle
/// descriptions are in coord_t<P>.
template <class P, class Policy>
class particle_state {
public:
    using Real = real_t<P>;
    using Coord = coord_t<P>;

    particle_state() = default;

    /// Fills the arrays from validated particle descriptions. Without `distinct_sync` the
    /// velocities at the positions' time are the velocities themselves (every integrator but
    /// semi-implicit Euler): v_sync and omega_sync then share v's and omega's arrays. Without
    /// `audit` there are no energy-audit arrays (pressure, dissipation): snapshots show zeros.
    /// Without `angular_position` there is no angular-position array, without `displacement`
    /// no accumulated-displacement array (snapshots show zeros).
    explicit particle_state(const std::vector<particle<Coord>>& particles, bool distinct_sync = true,
                            bool audit = true, bool angular_position = true, bool displacement = true)
        : distinct_sync_(distinct_sync), audit_(audit), angular_position_(angular_position),
          displacement_kept_(displacement)
    {
        // One field at a time, straight from the descriptions (storage order = user order
        // until the first rebuild): set-up needs one field's copy beside the arrays.
        const std::size_t n = particles.size();
        auto field = [&](auto& to, auto value_of) {
            using T = typename std::remove_reference_t<decltype(to)>::value_type;
            std::vector<T> values(n);
            for (std::size_t i = 0; i < n; ++i) values[i] = value_of(particles[i]);
            to.assign(std::move(values));
        };
        const vec3<Real> zero{0, 0, 0};
        // velocities and masses are held in Real; a fixed particle has none
        auto velocity = [](const particle<Coord>& p) {
            return p.kind == motion::fixed ? vec3<Real>{0, 0, 0} : vec_cast<Real>(p.velocity);
        };
        auto spin = [](const particle<Coord>& p) {
            return p.kind == motion::fixed ? vec3<Real>{0, 0, 0} : vec_cast<Real>(p.angular_velocity);
        };
        field(x_, [](const particle<Coord>& p) { return vec4<Coord>{p.position.x, p.position.y, p.position.z, p.radius}; });
        field(v_, velocity);
        field(omega_, spin);
        if (distinct_sync_) {
            field(v_sync_, velocity);
            field(omega_sync_, spin);
        }
        if (angular_position_) angpos_.resize(n, zero);
        if (displacement_kept_) displacement_.resize(n, vec3<Coord>{0, 0, 0});
        if (displacement_kept_ && !std::is_same_v<Real, Coord>) wide_scratch_.resize(n, vec3<Coord>{0, 0, 0});
        force_.resize(n, zero);
        torque_.resize(n, zero);
        field(mass_, [](const particle<Coord>& p) { return Real(sphere_mass(p.radius, p.density)); });
        if (audit_)
            for (buffer<Real, Policy>* b : {&pressure_, &e_visc_, &e_fric_, &p_visc_, &p_fric_}) b->resize(n, Real(0));
        field(kind_, [](const particle<Coord>& p) { return static_cast<std::uint8_t>(p.kind); });
        field(material_, [](const particle<Coord>& p) { return p.material; });
        std::vector<unsigned> identity(n);
        for (std::size_t i = 0; i < n; ++i) identity[i] = static_cast<unsigned>(i);
        user_.assign(std::move(identity));
    }

    std::size_t size() const { return x_.size(); }

    particle_view<P> view()
    {
        vec3<Real>* v_sync = distinct_sync_ ? v_sync_.data() : v_.data();
        vec3<Real>* omega_sync = distinct_sync_ ? omega_sync_.data() : omega_.data();
        auto audit = [&](buffer<Real, Policy>& b) { return audit_ ? b.data() : nullptr; };
        vec3<Real>* angpos = angular_position_ ? angpos_.data() : nullptr;
        vec3<Coord>* displacement = displacement_kept_ ? displacement_.data() : nullptr;
        return {x_.size(),       x_.data(),        v_.data(),         omega_.data(),     v_sync,
                omega_sync,      angpos,           force_.data(),     torque_.data(),    mass_.data(),
                audit(pressure_), audit(e_visc_), audit(e_fric_),   audit(p_visc_),    audit(p_fric_),
                kind_.data(),    material_.data(), user_.data(),      displacement};
    }

    /// The user's index of the particle in each storage slot (host copy).
    std::vector<unsigned> user_indices() const { return user_.to_host(); }

    /// Moves the particle in slot order[k] to slot k, for every k (order is a permutation),
    /// and with it every array in `along` that must stay in step with the particles (e.g.
    /// external forces, the positions at the last rebuild; an empty one stays empty). The
    /// forces are not carried (the next force evaluation writes them): their array is the
    /// permutation's scratch and holds zeros afterwards.
    template <class... Along>
    void permute(const unsigned* order, Along&... along)
    {
        move_positions<true>(order);
        move_fields<detail::gather>(order, along...);
    }

    /// Undoes permute(order, along...): every particle and `along` array back into the slot it
    /// had before (the forces, scratch, are left zero). Every array keeps its address.
    template <class... Along>
    void unpermute(const unsigned* order, Along&... along)
    {
        move_positions<false>(order);
        move_fields<detail::scatter>(order, along...);
    }

    /// Sets which particle each slot holds (user index per slot), e.g. for a restart; the
    /// fields' contents must be restored afterwards.
    void set_storage_order(const std::vector<unsigned>& user) { user_.assign(user); }

    /// A host copy of every field, in user order.
    particle_snapshot<Coord> snapshot() const
    {
        const std::vector<unsigned> user = user_.to_host();
        auto out = [&](const auto& field) { return in_user_order(field, user); };
        return {out(x_),     out(v_),      out(omega_),  out(distinct_sync_ ? v_sync_ : v_),
                out(distinct_sync_ ? omega_sync_ : omega_),
                out(angpos_), out(force_),  out(torque_), out(mass_),   out(pressure_),
                out(e_visc_), out(e_fric_), out(p_visc_), out(p_fric_), out(kind_), out(material_),
                out(displacement_)};
    }

    /// A host copy of the positions and radii alone, in user order (what snapshot().x holds).
    std::vector<vec4<Coord>> positions() const { return in_user_order(x_, user_.to_host()); }

    /// Replaces every field by a snapshot's, given in user order (for restarts and for
    /// host-side edits); the storage order stays.
    void restore(const particle_snapshot<Coord>& s)
    {
        const std::vector<unsigned> user = user_.to_host();
        auto in = [&](auto& field, const auto& users) {
            using T = typename std::remove_reference_t<decltype(field)>::value_type;
            std::vector<T> slots(users.size());
            for (std::size_t k = 0; k < slots.size(); ++k) slots[k] = narrow<T>(users[user[k]]);
            field.assign(slots);
        };
        in(x_, s.x);
        in(v_, s.v);
        in(omega_, s.omega);
        if (distinct_sync_) {
            in(v_sync_, s.v_sync);
            in(omega_sync_, s.omega_sync);
        }
        if (angular_position_) in(angpos_, s.angpos);
        in(force_, s.force);
        in(torque_, s.torque);
        in(mass_, s.mass);
        if (audit_) {
            in(pressure_, s.pressure);
            in(e_visc_, s.e_visc);
            in(e_fric_, s.e_fric);
            in(p_visc_, s.p_visc);
            in(p_fric_, s.p_fric);
        }
        in(kind_, s.kind);
        in(material_, s.material);
        if (displacement_kept_) in(displacement_, s.displacement);
    }

private:
    /// A stored value in the snapshot's type, and back (identity unless P is mixed).
    static vec4<Coord> widen(const vec4<Coord>& a) { return a; }
    static vec3<Coord> widen(const vec3<Real>& a) { return vec_cast<Coord>(a); }
    template <class R = Real, class = std::enable_if_t<!std::is_same_v<R, Coord>>>
    static vec3<Coord> widen(const vec3<Coord>& a) { return a; }
    static Coord widen(Real a) { return Coord(a); }
    static std::uint8_t widen(std::uint8_t a) { return a; }

    /// A host copy of `field` in user order (`user`: the user index of each slot), widened to
    /// Coord; zeros for a field that is not kept.
    template <class T>
    static auto in_user_order(const buffer<T, Policy>& field, const std::vector<unsigned>& user)
    {
        const std::vector<T> slots = field.to_host();
        std::vector<decltype(widen(T{}))> users(user.size(), decltype(widen(T{})){});
        for (std::size_t k = 0; k < slots.size(); ++k) users[user[k]] = widen(slots[k]);
        return users;
    }

    template <class T> static T narrow(const vec4<Coord>& a) { return a; }
    template <class T> static T narrow(const vec3<Coord>& a)
    {
        if constexpr (std::is_same_v<T, vec3<Coord>>) return a; // the accumulated displacement
        else return vec_cast<Real>(a);
    }
    template <class T> static T narrow(Coord a) { return T(a); }
    template <class T> static T narrow(std::uint8_t a) { return a; }

    /// Every field that a permutation carries: all but the positions (copied from the sorted
    /// ones) and the forces (its scratch).
    template <class F>
    void each_carried_field(F f)
    {
        f(v_); f(omega_); f(v_sync_); f(omega_sync_); f(angpos_); f(torque_);
        f(mass_); f(pressure_); f(e_visc_); f(e_fric_); f(p_visc_); f(p_fric_); f(kind_);
        f(material_); f(displacement_);
    }

    /// Moves every carried field, the user indices and the `along` arrays through `order` by
    /// `Move` (detail::gather for permute, detail::scatter to undo it), each by way of the
    /// forces' array, which holds zeros afterwards.
    template <template <class> class Move, class... Along>
    void move_fields(const unsigned* order, Along&... along)
    {
        each_carried_field([&](auto& field) { move_field<Move>(field, order); });
        move_field<Move>(user_, order);
        (move_field<Move>(along, order), ...);
        for_each_index(Policy{}, force_.size(), detail::fill_value<vec3<Real>>{force_.data(), {0, 0, 0}});
    }

    /// Moves the positions and radii through `order` (Gather: like detail::gather, else like
    /// detail::scatter) one coordinate at a time by way of the forces' array, which holds a
    /// coordinate of every particle (no array as large as the positions' is needed).
    template <bool Gather>
    void move_positions(const unsigned* order)
    {
        // A coordinate fits in a force's place, and buffers start at least 16-B aligned
        // (operator new, cudaMalloc): a double is aligned in the forces' array of mixed
        // precision too.
        static_assert(sizeof(Coord) <= sizeof(vec3<Real>) && alignof(Coord) <= 16, "a coordinate fits in a force's place");
        move_coordinate<0, Gather>(order);
        move_coordinate<1, Gather>(order);
        move_coordinate<2, Gather>(order);
        move_coordinate<3, Gather>(order);
    }

    template <int C, bool Gather>
    void move_coordinate(const unsigned* order)
    {
        Coord* tmp = reinterpret_cast<Coord*>(force_.data());
        const std::size_t n = x_.size();
        for_each_index(Policy{}, n, detail::move_coordinate<C, Coord, Gather>{x_.data(), order, tmp});
        for_each_index(Policy{}, n, detail::set_coordinate<C, Coord>{tmp, x_.data()});
    }

    /// Moves one field through `order` by `Move` into the forces' array (for the accumulated
    /// displacement of mixed precision, wider than a force, into wide_scratch_) and copies it
    /// back.
    template <template <class> class Move, class T>
    void move_field(buffer<T, Policy>& field, const unsigned* order)
    {
        const std::size_t n = field.size();
        T* tmp;
        if constexpr (sizeof(T) <= sizeof(vec3<Real>) && alignof(T) <= alignof(vec3<Real>)) {
            tmp = reinterpret_cast<T*>(force_.data());
        } else {
            static_assert(std::is_same_v<T, vec3<Coord>>, "only the accumulated displacement is wider than a force");
            tmp = wide_scratch_.data();
        }
        for_each_index(Policy{}, n, Move<T>{field.data(), order, tmp});
        for_each_index(Policy{}, n, detail::copy_back<T>{tmp, field.data()});
    }

    buffer<vec4<Coord>, Policy> x_;
    buffer<vec3<Real>, Policy> v_, omega_, v_sync_, omega_sync_, angpos_, force_, torque_;
    buffer<Real, Policy> mass_, pressure_, e_visc_, e_fric_, p_visc_, p_fric_;
    buffer<std::uint8_t, Policy> kind_, material_;
    buffer<unsigned, Policy> user_;
    bool distinct_sync_ = true; ///< v_sync_, omega_sync_ hold their own values (else empty: v_, omega_)
    bool audit_ = true;         ///< the energy-audit arrays exist (else empty)
    bool angular_position_ = true; ///< angpos_ exists (else empty)
    buffer<vec3<Coord>, Policy> displacement_;
    /// The permutation's scratch for displacement_ where it is wider than a force (mixed
    /// precision only: 24 B per particle more there).
    buffer<vec3<Coord>, Policy> wide_scratch_;
    bool displacement_kept_ = true; ///< displacement_ exists (else empty)
};

} // namespace sphere
