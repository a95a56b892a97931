#pragma once
/// \file
/// CSV time series (docs/io.md, "CSV time series"): a header of `name_unit` columns and rows
/// of numbers with 17 significant digits (every double reads back exactly). Rows collect in
/// memory; flush() rewrites the whole file atomically (io/atomic_file.cuh), so the file on disk
/// always holds complete rows. Also the standard diagnostics row of a simulation: time,
/// energies and the state of every wall. Host-only code.
///
/// Usage:
///
///     sphere::csv_series csv = sphere::diagnostics_series("out/diagnostics.csv", sim);
///     sim.add_observer(100, [&](const auto& s) { csv.add_row(sphere::diagnostics_row(s)); });
///     sim.run(10000);
///     csv.close();
#include <cstddef>
#include <limits>
#include <locale>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../boundary/walls.cuh"
#include "../core/error.cuh"
#include "atomic_file.cuh"

namespace sphere {

/// A CSV file of numeric rows under a fixed header. The destructor writes nothing: call
/// flush() whenever the file on disk should catch up, and close() at the end.
class csv_series {
public:
    /// A series to be written to `path` with the given column names (by convention
    /// `name_unit`, e.g. `time_s`). Writes nothing yet. Throws sphere::error when there are no
    /// columns, or a name is empty or holds a comma, quote or line break.
    csv_series(std::string path, std::vector<std::string> columns)
        : path_(std::move(path)), columns_(std::move(columns))
    {
        if (columns_.empty()) detail::fail("CSV '", path_, "': no columns");
        for (std::size_t c = 0; c < columns_.size(); ++c)
            if (columns_[c].empty() || columns_[c].find_first_of(",\"\r\n") != std::string::npos)
                detail::fail("CSV '", path_, "': column ", c, " name '", columns_[c],
                             "' must be non-empty without commas, quotes or line breaks");
        for (std::size_t c = 0; c < columns_.size(); ++c) header_ += (c ? "," : "") + columns_[c];
        header_ += '\n';
    }

    /// Appends one row in memory (not yet on disk). Throws sphere::error when the row's length
    /// differs from the number of columns or the series is closed.
    void add_row(const std::vector<double>& row)
    {
        if (closed_) detail::fail("CSV '", path_, "': add_row after close()");
        if (row.size() != columns_.size())
            detail::fail("CSV '", path_, "': row ", rows_, " has ", row.size(), " values for ", columns_.size(),
                         " columns");
        std::ostringstream out;
        out.imbue(std::locale::classic());
        out.precision(std::numeric_limits<double>::max_digits10);
        for (std::size_t c = 0; c < row.size(); ++c) out << (c ? "," : "") << row[c];
        out << '\n';
        body_ += out.str();
        ++rows_;
    }

    /// Rewrites the whole file (header and every row so far) atomically. Throws sphere::error
    /// naming the file when it cannot be written; the previous file, if any, stays then.
    void flush() { write_file_atomically(path_, header_ + body_); }

    /// Flushes and closes the series: later add_row calls throw; flush and close may repeat.
    void close()
    {
        flush();
        closed_ = true;
    }

    const std::string& path() const { return path_; }
    const std::vector<std::string>& columns() const { return columns_; }
    /// Rows added so far.
    std::size_t rows() const { return rows_; }

private:
    std::string path_;
    std::vector<std::string> columns_;
    std::string header_, body_;
    std::size_t rows_ = 0;
    bool closed_ = false;
};

/// Short name of wall face f: xlo, xhi, ylo, yhi, zlo, zhi.
inline const char* wall_face_name(int f)
{
    static const char* const names[6] = {"xlo", "xhi", "ylo", "yhi", "zlo", "zhi"};
    return f >= 0 && f < 6 ? names[f] : "?";
}

/// Column names of the diagnostics row (diagnostics_row): time_s, kinetic_J, rotational_J,
/// potential_J, elastic_J, dissipated_visc_J, dissipated_fric_J, boundary_work_J, total_J, then
/// for each active wall face (in face order) wall_<face>_position_m, wall_<face>_velocity_m/s
/// and wall_<face>_force_N; with `bonds`, then bond_elastic_J, bond_broken_J and broken_bonds.
template <class Real>
std::vector<std::string> diagnostics_columns(const wall_set<Real>& walls, bool bonds = false)
{
    std::vector<std::string> c = {"time_s",           "kinetic_J",         "rotational_J",
                                  "potential_J",      "elastic_J",         "dissipated_visc_J",
                                  "dissipated_fric_J", "boundary_work_J", "total_J"};
    for (int f = 0; f < wall_set<Real>::count; ++f) {
        if (!walls.face[f].active) continue;
        const std::string w = std::string("wall_") + wall_face_name(f);
        c.push_back(w + "_position_m");
        c.push_back(w + "_velocity_m/s");
        c.push_back(w + "_force_N");
    }
    if (bonds)
        for (const char* name : {"bond_elastic_J", "bond_broken_J", "broken_bonds"}) c.push_back(name);
    return c;
}

/// The diagnostics of a simulation now, matching diagnostics_columns(sim.walls(), a simulation
/// with bonds): time (s), the energy budget (J, sim.energy(), total = energy().total()), for
/// each active wall face its position (m), velocity (m/s) along its axis and the particles'
/// force on it (N), and for a simulation with bonds the energy they hold and released (J) and
/// how many have broken.
template <class Sim>
std::vector<double> diagnostics_row(const Sim& sim)
{
    const auto e = sim.energy();
    std::vector<double> row = {sim.time(),
                               double(e.kinetic),
                               double(e.rotational),
                               double(e.potential),
                               double(e.elastic),
                               double(e.dissipated_visc),
                               double(e.dissipated_fric),
                               double(e.boundary_work),
                               double(e.total())};
    for (const auto& w : sim.walls().face) {
        if (!w.active) continue;
        row.push_back(double(w.position));
        row.push_back(double(w.velocity));
        row.push_back(double(w.force));
    }
    if (sim.bond_count()) {
        row.push_back(double(e.bond_elastic));
        row.push_back(double(e.bond_broken));
        row.push_back(double(sim.broken_bonds()));
    }
    return row;
}

/// A csv_series at `path` with the diagnostics columns of `sim` (nothing written yet).
template <class Sim>
csv_series diagnostics_series(const std::string& path, const Sim& sim)
{
    return csv_series(path, diagnostics_columns(sim.walls(), sim.bond_count() > 0));
}

} // namespace sphere
