#pragma once
/// \file
/// A host copy of the evolving state of the pore fluid (docs/fluid.md, *Restarting a coupled
/// run*): what a fluid model, the porosity estimator and the coupling carry from one step to
/// the next, so that a checkpoint (io/checkpoint.cuh) can hold it and a coupled run restarted
/// from it continues bit-identically. `snapshot()` of navier_stokes, darcy_flow,
/// porosity_estimator and fluid_coupling fills one; their `restore()` checks it against the
/// object (model, grid, every array's length) and throws sphere::error naming what differs.
/// Host-only code.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "../boundary/world.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "grid.cuh"

namespace sphere {

/// The state of a fluid model (or of the porosity estimator, or of a whole coupling), by name:
/// arrays of Real in the fluid grid's field layout (fluid_grid::field_index, ghost nodes
/// included; a vec3 field as x, y, z of each node in turn), and named scalars: floating values
/// (`numbers`: times, sums) and whole numbers (`counts`: step counts, flags). What each model
/// stores is listed in docs/fluid.md, *Restarting a coupled run*.
template <class Real>
struct fluid_snapshot {
    struct array {
        std::string name;
        std::vector<Real> values;
    };
    struct number {
        std::string name;
        double value;
    };
    struct count {
        std::string name;
        std::uint64_t value;
    };

    std::string model;          ///< "navier_stokes", "darcy", or "porosity" (the estimator alone)
    unsigned n[3] = {0, 0, 0};  ///< the grid's cells along x, y, z
    double lo[3] = {0, 0, 0};   ///< the grid's box (m)
    double hi[3] = {0, 0, 0};
    std::vector<array> arrays;
    std::vector<number> numbers;
    std::vector<count> counts;

    /// An empty snapshot of `model` on grid g.
    static fluid_snapshot of(const std::string& model, const fluid_grid<Real>& g)
    {
        fluid_snapshot s;
        s.model = model;
        for (int a = 0; a < 3; ++a) {
            s.n[a] = g.n[a];
            s.lo[a] = double(g.box.lo[a]);
            s.hi[a] = double(g.box.hi[a]);
        }
        return s;
    }

    /// The grid the snapshot was taken on (its cells and box).
    fluid_grid<Real> grid() const
    {
        world<Real> box;
        for (int a = 0; a < 3; ++a) {
            box.lo[a] = Real(lo[a]);
            box.hi[a] = Real(hi[a]);
        }
        return fluid_grid<Real>::make(box, n[0], n[1], n[2]);
    }

    void add(const std::string& name, std::vector<Real> values) { arrays.push_back({name, std::move(values)}); }
    /// A field of vec3, flattened (x, y, z of each node in turn).
    void add(const std::string& name, const std::vector<vec3<Real>>& values)
    {
        std::vector<Real> flat(3 * values.size());
        for (std::size_t i = 0; i < values.size(); ++i)
            for (int a = 0; a < 3; ++a) flat[3 * i + a] = values[i][a];
        add(name, std::move(flat));
    }
    void add_number(const std::string& name, double value) { numbers.push_back({name, value}); }
    void add_count(const std::string& name, std::uint64_t value) { counts.push_back({name, value}); }

    /// Throws unless the snapshot is of `expected_model` on a grid of g's cells and box (the box
    /// within 1e-6 relative, as a float snapshot converts to double and back); `who` begins
    /// the message (e.g. "navier_stokes::restore").
    void check_model_and_grid(const char* who, const std::string& expected_model, const fluid_grid<Real>& g) const
    {
        if (model != expected_model)
            detail::fail(who, ": the snapshot is of the model \"", model, "\", this one is \"", expected_model, "\"");
        check_grid(who, g);
    }
    /// The grid part of check_model_and_grid.
    void check_grid(const char* who, const fluid_grid<Real>& g) const
    {
        if (n[0] != g.n[0] || n[1] != g.n[1] || n[2] != g.n[2])
            detail::fail(who, ": the snapshot's grid has ", n[0], " x ", n[1], " x ", n[2], " cells, this one ", g.n[0],
                         " x ", g.n[1], " x ", g.n[2]);
        const char* axis_name[3] = {"x", "y", "z"};
        for (int a = 0; a < 3; ++a) {
            const double l = double(g.box.lo[a]), h = double(g.box.hi[a]);
            const auto same = [](double u, double v) {
                return std::abs(u - v) <= 1e-6 * (std::abs(u) > std::abs(v) ? std::abs(u) : std::abs(v));
            };
            if (!same(lo[a], l) || !same(hi[a], h))
                detail::fail(who, ": the snapshot's grid spans [", lo[a], ", ", hi[a], "] m along ", axis_name[a],
                             ", this one [", l, ", ", h, "] m");
        }
    }

    /// The array `name`, which must hold `expected` values (`what` says what they are, e.g.
    /// "the grid's field size").
    const std::vector<Real>& array_named(const char* who, const std::string& name, std::size_t expected,
                                         const char* what) const
    {
        for (const array& a : arrays)
            if (a.name == name) {
                if (a.values.size() != expected)
                    detail::fail(who, ": the snapshot's array \"", name, "\" holds ", a.values.size(), " values, expected ",
                                 expected, " (", what, ")");
                return a.values;
            }
        detail::fail(who, ": the snapshot of the model \"", model, "\" has no array \"", name, "\"");
    }
    /// The vec3 field `name` of `expected` nodes (flattened, see add).
    std::vector<vec3<Real>> vectors_named(const char* who, const std::string& name, std::size_t expected,
                                          const char* what) const
    {
        const std::vector<Real>& flat = array_named(who, name, 3 * expected, what);
        std::vector<vec3<Real>> out(expected);
        for (std::size_t i = 0; i < expected; ++i)
            for (int a = 0; a < 3; ++a) out[i][a] = flat[3 * i + a];
        return out;
    }
    double number_named(const char* who, const std::string& name) const
    {
        for (const number& x : numbers)
            if (x.name == name) return x.value;
        detail::fail(who, ": the snapshot of the model \"", model, "\" has no number \"", name, "\"");
    }
    /// The count `name`, which must be at most `max`.
    std::uint64_t count_named(const char* who, const std::string& name, std::uint64_t max) const
    {
        for (const count& x : counts)
            if (x.name == name) {
                if (x.value > max)
                    detail::fail(who, ": the snapshot's count \"", name, "\" is ", x.value, ", at most ", max,
                                 " is valid");
                return x.value;
            }
        detail::fail(who, ": the snapshot of the model \"", model, "\" has no count \"", name, "\"");
    }

    /// Throws when the snapshot holds an entry that is not among the names given (a snapshot
    /// of a model with more state than this one restores).
    void check_only(const char* who, const std::vector<std::string>& array_names,
                    const std::vector<std::string>& number_names, const std::vector<std::string>& count_names) const
    {
        const auto known = [](const std::vector<std::string>& names, const std::string& name) {
            for (const std::string& k : names)
                if (k == name) return true;
            return false;
        };
        for (const array& a : arrays)
            if (!known(array_names, a.name))
                detail::fail(who, ": the snapshot holds an array \"", a.name, "\" that the model \"", model,
                             "\" does not have");
        for (const number& x : numbers)
            if (!known(number_names, x.name))
                detail::fail(who, ": the snapshot holds a number \"", x.name, "\" that the model \"", model,
                             "\" does not have");
        for (const count& x : counts)
            if (!known(count_names, x.name))
                detail::fail(who, ": the snapshot holds a count \"", x.name, "\" that the model \"", model,
                             "\" does not have");
    }

    /// The entries whose names begin with `prefix`, without it, as a snapshot of `part_model`
    /// on the same grid (fluid_coupling splits its snapshot so).
    fluid_snapshot part(const std::string& prefix, const std::string& part_model) const
    {
        fluid_snapshot s = *this;
        s.model = part_model;
        s.arrays.clear();
        s.numbers.clear();
        s.counts.clear();
        const auto strip = [&](const std::string& name, std::string& rest) {
            if (name.compare(0, prefix.size(), prefix) != 0) return false;
            rest = name.substr(prefix.size());
            return true;
        };
        std::string rest;
        for (const array& a : arrays)
            if (strip(a.name, rest)) s.arrays.push_back({rest, a.values});
        for (const number& x : numbers)
            if (strip(x.name, rest)) s.numbers.push_back({rest, x.value});
        for (const count& x : counts)
            if (strip(x.name, rest)) s.counts.push_back({rest, x.value});
        return s;
    }
    /// The entries of `other` added under `prefix` (the reverse of part()).
    void merge(const std::string& prefix, const fluid_snapshot& other)
    {
        for (const array& a : other.arrays) arrays.push_back({prefix + a.name, a.values});
        for (const number& x : other.numbers) numbers.push_back({prefix + x.name, x.value});
        for (const count& x : other.counts) counts.push_back({prefix + x.name, x.value});
    }
    /// The entries whose names begin with none of `prefixes` (a model's own, in a coupling's
    /// snapshot).
    fluid_snapshot other_than(const std::vector<std::string>& prefixes) const
    {
        const auto kept = [&](const std::string& name) {
            for (const std::string& p : prefixes)
                if (name.compare(0, p.size(), p) == 0) return false;
            return true;
        };
        fluid_snapshot s = *this;
        s.arrays.clear();
        s.numbers.clear();
        s.counts.clear();
        for (const array& a : arrays)
            if (kept(a.name)) s.arrays.push_back(a);
        for (const number& x : numbers)
            if (kept(x.name)) s.numbers.push_back(x);
        for (const count& x : counts)
            if (kept(x.name)) s.counts.push_back(x);
        return s;
    }
};

} // namespace sphere
