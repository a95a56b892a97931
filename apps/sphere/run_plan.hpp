#pragma once
// The `sphere` program's plan of a run and its files (docs/program.md): which steps end with an
// output, what the numbered files are called, and the status file that says how far a run got
// and which run it is, so that a run killed at any moment resumes from its last output.
#include <sphere/core/error.cuh>
#include <sphere/io/atomic_file.cuh>
#include <sphere/io/checkpoint.cuh>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <locale>
#include <sstream>
#include <string>
#include <vector>

namespace program {

/// A number in at most 9 significant digits (as a user writes it on the command line).
inline std::string short_number(double v)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", v);
    return text;
}

/// Steps of a run: it starts at the input's step count `first` and ends at `last`; output k
/// (output 0 is the input's state) is written at first + k every, and the last output at
/// `last` even where that is not a multiple.
struct run_plan {
    std::size_t first = 0, last = 0, every = 1;

    /// The steps from the input's time t0 = first dt to `total` (s), rounded up (to the nearest
    /// step where total / dt is within 1e-9 of it), and an output every round(interval / dt)
    /// steps (at least 1), both in whole strides of `stride` steps from `first` (a coupled
    /// run's fluid step: dem_steps DEM steps). Throws sphere::error for a total before t0 or a
    /// non-positive interval.
    static run_plan make(std::size_t first, double dt, double total, double interval, std::size_t stride = 1)
    {
        const double t0 = double(first) * dt;
        if (!(total >= t0) || !std::isfinite(total))
            sphere::detail::fail("--total ", short_number(total), " s: must be finite and at least the input's time, ",
                                 short_number(t0), " s");
        if (!(interval > 0) || !std::isfinite(interval))
            sphere::detail::fail("--interval ", short_number(interval), " s: must be positive and finite");
        const double steps = total / dt, nearest = std::round(steps);
        const double to_total = std::abs(steps - nearest) <= 1e-9 * std::max(1.0, nearest) ? nearest : std::ceil(steps);
        if (to_total > 1e15)
            sphere::detail::fail("--total ", short_number(total), " s is ", to_total, " steps of ", dt, " s: too many");
        run_plan p;
        p.first = first;
        const std::size_t steps_to_total = std::max(first, static_cast<std::size_t>(to_total)) - first;
        p.last = first + (steps_to_total + stride - 1) / stride * stride;
        const double strides = std::round(interval / (dt * double(stride)));
        p.every = stride * std::max<std::size_t>(1, static_cast<std::size_t>(strides));
        return p;
    }

    /// Number of outputs, output 0 included.
    std::size_t outputs() const { return (last - first + every - 1) / every + 1; }
    /// The step at which output k is written.
    std::size_t step_of(std::size_t k) const { return std::min(first + k * every, last); }
};

/// Names of a run's files in its output folder, from the input's name without folder and
/// extension: <name>.output<NNNNN>.ck and .vtu, <name>.pvd, <name>.status.dat.
struct run_files {
    std::string folder, name;

    std::string numbered(std::size_t k, const char* extension) const
    {
        std::ostringstream s;
        s << name << ".output" << std::setw(5) << std::setfill('0') << k << extension;
        return s.str();
    }
    std::string checkpoint(std::size_t k) const { return folder + "/" + numbered(k, ".ck"); }
    std::string frame(std::size_t k) const { return numbered(k, ".vtu"); } // relative to the folder, as the .pvd lists it
    std::string collection() const { return folder + "/" + name + ".pvd"; }
    /// A coupled run's fluid frames and their collection.
    std::string fluid_frame(std::size_t k) const { return numbered(k, ".vti"); }
    std::string fluid_collection() const { return folder + "/" + name + ".fluid.pvd"; }
    std::string status() const { return folder + "/" + name + ".status.dat"; }
};

/// What the status file records. Its first line is the original sphere's status.dat: the
/// simulated time (s), the percentage of the run done and the number of the last output; the
/// lines after it identify the run (the input's checksum and the options that change the
/// results), so that a resumed run continues only the run it belongs to.
struct run_status {
    double time = 0;
    double percent = 0;
    std::size_t last_output = 0;
    std::vector<std::pair<std::string, std::string>> identity; ///< (key, value), in order

    std::string text() const
    {
        std::ostringstream s;
        s.imbue(std::locale::classic());
        s << std::setprecision(17) << time << ' ' << std::setprecision(6) << percent << ' ' << last_output << '\n';
        for (const auto& [key, value] : identity) s << key << ' ' << value << '\n';
        return s.str();
    }

    void write(const std::string& path) const { sphere::write_file_atomically(path, text()); }

    /// Reads a status file; throws sphere::error naming it when it is not one.
    static run_status read(const std::string& path)
    {
        std::ifstream in(path);
        if (!in) sphere::detail::fail("cannot read the status file '", path, "'");
        run_status s;
        std::string line;
        std::getline(in, line);
        std::istringstream first(line);
        first.imbue(std::locale::classic());
        if (!(first >> s.time >> s.percent >> s.last_output))
            sphere::detail::fail("status file '", path, "': its first line '", line,
                                 "' is not 'time percent last-output'");
        while (std::getline(in, line)) {
            const std::size_t space = line.find(' ');
            if (space == std::string::npos)
                sphere::detail::fail("status file '", path, "': line '", line, "' is not 'key value'");
            s.identity.emplace_back(line.substr(0, space), line.substr(space + 1));
        }
        return s;
    }

    /// The first entry of `identity` whose value differs from `other`'s (or is missing there),
    /// as "key value-there there, value-here here"; empty when both identify the same run. The
    /// input's path is not compared (the same file may be named another way): its checksum is.
    std::string difference(const run_status& other) const
    {
        for (const auto& [key, value] : identity) {
            if (key == "input") continue;
            std::string theirs = "(none)";
            for (const auto& [k, v] : other.identity)
                if (k == key) theirs = v;
            if (theirs != value) return key + " " + theirs + " there, " + value + " here";
        }
        return {};
    }
};

/// The checksum of a checkpoint file's bytes as 16 hex digits (FNV-1a 64, as the file's own).
inline std::string checksum_text(const std::string& bytes)
{
    std::ostringstream hex;
    hex << std::hex << std::setw(16) << std::setfill('0') << sphere::detail::fnv1a64(bytes.data(), bytes.size());
    return hex.str();
}

} // namespace program
