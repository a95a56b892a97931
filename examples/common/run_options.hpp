#pragma once
// Shared by every example but collision: the options that say where the output goes, in which
// precision the run is made and whether it shows a progress line, and the call that runs the
// example in that precision, reporting a sphere::error on stderr with exit status 1.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

namespace example {

struct run_options {
    std::string out;                  ///< output folder
    std::string precision = "double"; ///< "float" or "double"
    bool quiet = false;               ///< no progress line
};

inline void add_run_options(CLI::App& app, run_options& o)
{
    app.add_option("-o,--out", o.out, "output folder (created)")->capture_default_str();
    app.add_option("--precision", o.precision, "float or double")->check(CLI::IsMember({"float", "double"}))
        ->capture_default_str();
    app.add_flag("-q,--quiet", o.quiet, "no progress line");
}

/// run(float{}) or run(double{}) as o.precision says; an exception ends the progress line and
/// is printed on stderr, with exit status 1.
template <class Run>
int run_in_precision(const run_options& o, Run run)
{
    try {
        return o.precision == "float" ? run(float{}) : run(double{});
    } catch (const std::exception& ex) {
        if (!o.quiet) std::fprintf(stderr, "\n");
        std::cerr << ex.what() << '\n';
        return 1;
    }
}

} // namespace example
