#pragma once
/// \file
/// Materials (LIGGGHTS' per-type properties and per-type-pair coefficients): a material index
/// per particle (particle::material) and per wall face, and contact parameters per pair of
/// materials, around any contact law that mixes (the interface of contact/law.cuh). Mixing
/// rules and units: docs/physics.md, "Materials".
#include <cstdint>
#include <string>

#include "../boundary/walls.cuh"
#include "../core/config.cuh"
#include "../core/error.cuh"
#include "history.cuh"
#include "law.cuh"
#include "linear.cuh"
#include "result.cuh"

namespace sphere {

/// The parameters of `Count` materials in a base law's parameter type `Params`. In
/// settings.contact: the particle materials; `material[k]` is material k's (its contacts with
/// itself), and a pair of unlike materials a < b takes `pair[a][b]` if `given[a][b]`, else the
/// base law's mixing of the two. In settings.wall: the wall materials; `face[f]` is face f's
/// material, `material[w]` wall material w's, and particles of material a meet wall material w
/// with `pair[a][w]` in place of `material[w]` if `given[a][w]`.
template <class Params, unsigned Count>
struct material_params {
    Params material[Count];
    bool given[Count][Count] = {};
    Params pair[Count][Count];
    std::uint8_t face[wall_set<double>::count] = {}; ///< settings.wall only (settings.contact's stay 0)

    /// Gives the parameters of materials a and b (settings.contact: a < b; settings.wall: particle
    /// material a, wall material b).
    void set_pair(unsigned a, unsigned b, const Params& p)
    {
        given[a][b] = true;
        pair[a][b] = p;
    }

    /// Calls f(name, field, unit) for every field (contact/law.cuh): each material's, then each
    /// pair's flag and parameters, then the faces' materials.
    template <class Self, class F>
    static void fields(Self& p, F&& f)
    {
        auto under = [&](const std::string& prefix) {
            return [&f, prefix](const char* name, auto& field, const char* unit) {
                f((prefix + name).c_str(), field, unit);
            };
        };
        for (unsigned k = 0; k < Count; ++k) Params::fields(p.material[k], under(detail::text("material[", k, "].")));
        for (unsigned a = 0; a < Count; ++a)
            for (unsigned b = 0; b < Count; ++b) {
                f(detail::text("given[", a, "][", b, "]").c_str(), p.given[a][b], "");
                Params::fields(p.pair[a][b], under(detail::text("pair[", a, "][", b, "].")));
            }
        for (int g = 0; g < wall_set<double>::count; ++g) f(detail::text("face[", g, "]").c_str(), p.face[g], "");
    }
};

/// What the kernels receive: the base law's kernel parameters of each pair of materials
/// (`with[a][b]`), or at walls of each particle material and face (`with[a][f]`).
template <class BaseKernel, unsigned Count>
struct material_contact {
    static constexpr unsigned columns = Count > 6 ? Count : 6;
    BaseKernel with[Count][columns];
};

namespace contact {

/// `Count` materials (2 to 8) on the contact law `Base`, which declares how it mixes
/// (`kernel(a, b, contact)` and `mix(a, b, a_where, b_where)`: the linear, Hertz-Mindlin,
/// rolling and capillary laws do). Each contact evaluates Base with the parameters of its two
/// materials, chosen by index from a table built once.
template <class Base = linear<>, unsigned Count = 2>
struct materials {
    static_assert(Count >= 2 && Count <= 8, "contact::materials tells 2 to 8 materials apart");
    using base_law = Base;
    template <class Real>
    using base_params = typename Base::template params<Real>;
    template <class Real>
    using params = material_params<base_params<Real>, Count>;
    template <class Real>
    using kernel_params = material_contact<typename Base::template kernel_params<Real>, Count>;

    static constexpr unsigned material_count = Count;
    static std::string name() { return "materials<" + Base::name() + ", " + std::to_string(Count) + ">"; }
    static constexpr const char* history_layout = Base::history_layout;
    static constexpr unsigned history_lanes = law_history_shape<Base>::value.lanes;
    static constexpr unsigned history_mirror = law_history_shape<Base>::value.mirror;
    template <class Real>
    using history = law_history_t<Base, Real>;
    static constexpr time_step_rule time_step = Base::time_step;
    static constexpr bool acts_apart = sphere::acts_apart<Base>::value;

    /// Throws sphere::error naming the first bad parameter, material index or unmixable pair.
    template <class Real>
    static void validate(const params<Real>& pair, const params<Real>& wall, const char* pair_where = "settings.contact",
                         const char* wall_where = "settings.wall")
    {
        for (unsigned k = 0; k < Count; ++k)
            Base::validate(pair.material[k], wall.material[k], at(pair_where, "material", k).c_str(),
                           at(wall_where, "material", k).c_str());
        for (unsigned a = 0; a < Count; ++a)
            for (unsigned b = 0; b < Count; ++b) {
                const std::string given = at(pair_where, "pair", a, b);
                if (pair.given[a][b] && a >= b)
                    detail::fail(pair_where, ".given[", a, "][", b, "]: give a pair of unlike materials a < b once, as ",
                                 pair_where, ".set_pair(", b < a ? b : a, ", ", b < a ? a : b, ", ...)");
                if (pair.given[a][b]) Base::validate(pair.pair[a][b], wall.material[0], given.c_str(), wall_where);
                else if (a < b) mixed(pair, a, b, pair_where); // refuses what the base law cannot mix
                if (wall.given[a][b])
                    Base::validate(pair.material[a], wall.pair[a][b], at(pair_where, "material", a).c_str(),
                                   at(wall_where, "pair", a, b).c_str());
            }
        for (int f = 0; f < wall_set<double>::count; ++f) {
            if (wall.face[f] >= Count)
                detail::fail(wall_where, ".face[", f, "] = ", unsigned(wall.face[f]), ": not a wall material (0 to ",
                             Count - 1, ")");
            if (pair.face[f] != 0)
                detail::fail(pair_where, ".face[", f, "] = ", unsigned(pair.face[f]), ": faces take their material from ",
                             wall_where, ".face");
        }
    }

    template <class Real, class From>
    static kernel_params<Real> pair_kernel(const params<From>& pair)
    {
        kernel_params<Real> out{};
        for (unsigned a = 0; a < Count; ++a)
            for (unsigned b = 0; b < Count; ++b)
                out.with[a][b] = Base::template kernel<Real>(pair.material[a], pair.material[b],
                                                              mixed(pair, a, b, "settings.contact"));
        return out;
    }
    template <class Real, class From>
    static kernel_params<Real> wall_kernel(const params<From>& pair, const params<From>& wall)
    {
        kernel_params<Real> out{};
        for (unsigned a = 0; a < Count; ++a)
            for (int f = 0; f < wall_set<double>::count; ++f) {
                const unsigned w = wall.face[f];
                out.with[a][f] = Base::template wall_kernel<Real>(pair.material[a], wall.given[a][w] ? wall.pair[a][w]
                                                                                                    : wall.material[w]);
            }
        return out;
    }

    /// The smallest of the base law's time scales over every material, wall material and given
    /// pair (which material the particle has is not asked: the bound holds for any).
    template <class Real>
    static Real time_scale(const params<Real>& pair, const params<Real>& wall, Real mass, Real radius)
    {
        Real out = 0;
        bool first = true;
        each_scale(pair, wall, [&](const base_params<Real>& p, const base_params<Real>& w, const std::string&) {
            const Real t = Base::time_scale(p, w, mass, radius);
            if (first || t < out) out = t;
            first = false;
        });
        return out;
    }
    template <class Real>
    static std::string time_scale_inputs(const params<Real>& pair, const params<Real>& wall, Real mass, Real radius)
    {
        const Real smallest = time_scale(pair, wall, mass, radius);
        std::string out;
        each_scale(pair, wall, [&](const base_params<Real>& p, const base_params<Real>& w, const std::string& which) {
            if (out.empty() && Base::time_scale(p, w, mass, radius) == smallest)
                out = which + ": " + Base::time_scale_inputs(p, w, mass, radius);
        });
        return out;
    }

    /// The largest range of the base law over the pairs of materials (m).
    template <class Real>
    SPHERE_HDI static Real range(const kernel_params<Real>& p)
    {
        Real out = 0;
        for (unsigned a = 0; a < Count; ++a)
            for (unsigned b = 0; b < Count; ++b) {
                const Real r = law_range<Base, Real>(p.with[a][b]);
                out = r > out ? r : out;
            }
        return out;
    }

    template <class Real>
    SPHERE_HDI static contact_result<Real> pair(const kernel_params<Real>& p, const contact_motion<Real>& m,
                                               history<Real>& h, Real dt)
    {
        return Base::pair(p.with[m.material_i][m.material_j], m, h, dt);
    }
    template <class Real>
    SPHERE_HDI static contact_result<Real> wall(const kernel_params<Real>& p, const contact_motion<Real>& m,
                                               history<Real>& h, Real dt)
    {
        return Base::wall(p.with[m.material_i][m.material_j], m, h, dt);
    }
    template <class Real>
    SPHERE_HDI static Real pair_energy(const kernel_params<Real>& p, const contact_geometry<Real>& g,
                                      const history<Real>& h)
    {
        return Base::pair_energy(p.with[g.material_i][g.material_j], g, h);
    }
    template <class Real>
    SPHERE_HDI static Real wall_energy(const kernel_params<Real>& p, const contact_geometry<Real>& g,
                                      const history<Real>& h)
    {
        return Base::wall_energy(p.with[g.material_i][g.material_j], g, h);
    }

private:
    static std::string at(const char* where, const char* what, unsigned a)
    {
        return detail::text(where, ".", what, "[", a, "]");
    }
    static std::string at(const char* where, const char* what, unsigned a, unsigned b)
    {
        return detail::text(where, ".", what, "[", a, "][", b, "]");
    }

    /// The contact parameters of materials a and b: material a's when a == b, the given pair's,
    /// or the base law's mixing.
    template <class Real>
    static base_params<Real> mixed(const params<Real>& pair, unsigned a, unsigned b, const char* where)
    {
        const unsigned lo = a < b ? a : b, hi = a < b ? b : a;
        if (a == b) return pair.material[a];
        if (pair.given[lo][hi]) return pair.pair[lo][hi];
        return Base::mix(pair.material[lo], pair.material[hi], at(where, "material", lo).c_str(),
                         at(where, "material", hi).c_str());
    }

    /// Calls f(pair params, wall params, what they are) for every combination the time step
    /// must cover.
    template <class Real, class F>
    static void each_scale(const params<Real>& pair, const params<Real>& wall, F&& f)
    {
        for (unsigned a = 0; a < Count; ++a)
            for (unsigned w = 0; w < Count; ++w) {
                f(pair.material[a], wall.material[w], detail::text("material ", a, ", wall material ", w));
                if (wall.given[a][w]) f(pair.material[a], wall.pair[a][w], detail::text("material ", a, ", wall pair ", w));
                if (pair.given[a][w]) f(pair.pair[a][w], wall.material[0], detail::text("pair of materials ", a, " and ", w));
            }
    }
};

} // namespace contact
} // namespace sphere
