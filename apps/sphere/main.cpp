// sphere: runs the simulation a checkpoint describes until a total simulated time, writing
// numbered checkpoints and VTK frames at an interval of simulated time, a status file and a
// progress line; resumes from its last output after a crash (docs/program.md).
#include <sphere/dem.cuh>
#include <sphere/fluid.cuh>
#include <sphere/io.cuh>
#include <sphere/io/vti.cuh>

#include <CLI/CLI.hpp>
#if defined(SPHERE_PROGRAM_PNG)
#include <sphere/io/render_png.cuh>
#endif

#include "describe.hpp"
#include "film.hpp"
#include "run_plan.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>

#ifndef SPHERE_PROGRAM_VERSION
#define SPHERE_PROGRAM_VERSION "unknown"
#endif

namespace {

struct options {
    std::string input;
    std::string out = "output";
    std::string backend = "host";
    std::string precision = "file";
    std::string integrator = "euler";
    double total = std::numeric_limits<double>::quiet_NaN();
    double interval = std::numeric_limits<double>::quiet_NaN();
    bool dry = false, quiet = false, fresh = false, vtk = true;
    std::string render;     ///< a render method (normal, pres, vel, angvel, xdisp), or empty: no pictures
    double max_val = std::numeric_limits<double>::quiet_NaN(); ///< top of the colour map; NaN: each picture's largest value
    double lower_cutoff = 0; ///< bottom of the colour map; smaller values are not drawn
    bool film = false;       ///< join the pictures into a video with ffmpeg at the end
    double fps = 10;         ///< the video's frames per second
};

namespace fs = std::filesystem;

/// The progress line on stderr: a bar, the simulated time, the output number and the wall
/// time left at the speed of this process so far; at most once a second.
class progress_line {
public:
    progress_line(bool quiet, const program::run_plan& plan, std::size_t from)
        : quiet_(quiet), plan_(plan), from_(from), start_(clock::now()), shown_(start_)
    {}

    void show(std::size_t step, double time, std::size_t output, bool force)
    {
        const auto now = clock::now();
        if (quiet_ || (!force && now - shown_ < std::chrono::seconds(1))) return;
        shown_ = now;
        const std::size_t all = plan_.last - plan_.first, done = step - plan_.first;
        const double fraction = all ? double(done) / double(all) : 1.0;
        const double elapsed = std::chrono::duration<double>(now - start_).count();
        const double rate = step > from_ ? elapsed / double(step - from_) : 0; // wall seconds per step
        const int width = 30, filled = static_cast<int>(fraction * width);
        std::fprintf(stderr, "\r[%.*s%.*s] %5.1f%%  t = %.6g s  output %zu/%zu  %.0f s", filled,
                     "##############################", width - filled, "                              ",
                     100 * fraction, time, output, plan_.outputs() - 1, elapsed);
        if (step > from_) std::fprintf(stderr, ", ~%.0f s left   ", rate * double(plan_.last - step));
    }

    void end() const
    {
        if (!quiet_) std::fprintf(stderr, "\n");
    }

private:
    using clock = std::chrono::steady_clock;
    bool quiet_;
    program::run_plan plan_;
    std::size_t from_;
    clock::time_point start_, shown_;
};

/// Removes the files of an earlier run of `files.name` from the output folder (--fresh).
void remove_earlier_run(const program::run_files& files)
{
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(files.folder, ec)) {
        const std::string name = entry.path().filename().string();
        const bool numbered = name.rfind(files.name + ".output", 0) == 0;
        if (numbered || name == files.name + ".pvd" || name == files.name + ".fluid.pvd" ||
            name == files.name + ".status.dat")
            fs::remove(entry.path());
    }
}

/// Writes the picture of the particles `snap` that --render asks for to `path`
/// (docs/program.md, *Pictures*): the method's values, the colour map from --lower-cutoff to
/// --max-val (by default the largest value shown, or lower_cutoff + 1 when none is above it).
template <class Real>
void write_picture(const options& o, const sphere::particle_snapshot<Real>& snap, const std::string& path)
{
#if defined(SPHERE_PROGRAM_PNG)
    const sphere::render_method method = sphere::render_method_named(o.render);
    sphere::render_options style;
    style.lower_cutoff = o.lower_cutoff;
    style.max_val = o.max_val;
    if (std::isnan(o.max_val)) {
        double largest = o.lower_cutoff;
        for (Real v : sphere::particle_values(snap, method)) largest = std::max(largest, double(v));
        style.max_val = largest > o.lower_cutoff ? largest : o.lower_cutoff + 1;
    }
    sphere::render_png(path, snap, method, style);
#else
    (void)o, (void)snap, (void)path;
    sphere::detail::fail("--render: this sphere program was built without libpng (Debian: libpng-dev)");
#endif
}

/// What a run without pore fluid couples to its simulation: nothing.
struct no_fluid {};

/// Runs the checkpoint `input` (`bytes` the input file's) with the simulation type Sim (its
/// precision, law, backend and integrator), coupled to the pore fluid `fluid` (a
/// fluid_coupling built from the checkpoint's setup, its state restored from it here), or to
/// none (Fluid = no_fluid, `fluid` null).
template <class Sim, class Fluid>
int run_with(const options& o, const std::string& run_name, const std::string& bytes,
             const sphere::checkpoint_data<typename Sim::real_type, typename Sim::law_type>& input, Fluid* fluid)
{
    constexpr bool coupled = !std::is_same_v<Fluid, no_fluid>;
    const double dt = double(input.config.dt);
    const program::run_files files{o.out, fs::path(o.input).stem().string()};
    const double t0 = double(input.state.steps) * dt;
    if (!o.dry && !o.render.empty() && !std::isfinite(o.total)) { // the original's -r: a picture of the input
        std::error_code made;
        fs::create_directories(o.out, made);
        if (made) sphere::detail::fail("cannot create the output folder '", o.out, "': ", made.message());
        const std::string path = o.out + "/" + files.name + ".png";
        write_picture(o, input.state.particles, path);
        if (!o.quiet) std::printf("picture of %s (%s) in %s\n", o.input.c_str(), o.render.c_str(), path.c_str());
        return 0;
    }
    if (!o.dry && !std::isfinite(o.total)) sphere::detail::fail("--total: the simulated time to run to (s) is required");
    const double total = std::isfinite(o.total) ? o.total : t0; // --dry without it: the settings and an empty run
    std::size_t stride = 1; // steps between the times the run may stop: a coupled run's fluid step
    if constexpr (coupled) stride = fluid->options().dem_steps;
    const double interval = !std::isnan(o.interval) ? o.interval : total > t0 ? (total - t0) / 10 : dt * double(stride);
    const program::run_plan plan = program::run_plan::make(input.state.steps, dt, total, interval, stride);
    if (o.dry) {
        program::describe(o.input, input, run_name, plan, files);
        if constexpr (coupled) program::describe_fluid(fluid->setup(), *input.fluid, dt);
        if (!std::isfinite(o.total)) std::printf("(no --total given: a run needs one)\n");
        return 0;
    }

    program::run_status status;
    status.identity = {{"input", o.input},
                       {"input_checksum", program::checksum_text(bytes)},
                       {"run", run_name},
                       {"first_step", std::to_string(plan.first)},
                       {"last_step", std::to_string(plan.last)},
                       {"output_every", std::to_string(plan.every)}};
    std::error_code ec;
    fs::create_directories(o.out, ec);
    if (ec) sphere::detail::fail("cannot create the output folder '", o.out, "': ", ec.message());
    if (o.fresh) remove_earlier_run(files);

    std::optional<Sim> sim;
    std::size_t output = 0;
    sphere::pvd_collection frames(files.collection()), fluid_frames(files.fluid_collection());
    if (fs::exists(files.status())) {
        const program::run_status earlier = program::run_status::read(files.status());
        const std::string difference = status.difference(earlier);
        if (!difference.empty())
            sphere::detail::fail("the output folder '", o.out, "' holds another run of '", files.name, "' (",
                                 difference, "): give --fresh to replace it, or another --out");
        output = earlier.last_output;
        if (output >= plan.outputs())
            sphere::detail::fail("status file '", files.status(), "': last output ", output, ", but the run has ",
                                 plan.outputs());
        if constexpr (coupled) sim.emplace(sphere::restart<Sim>(files.checkpoint(output), *fluid));
        else sim.emplace(sphere::restart<Sim>(files.checkpoint(output)));
        if (sim->steps() != plan.step_of(output))
            sphere::detail::fail("'", files.checkpoint(output), "' is at step ", sim->steps(), ", output ", output,
                                 " of this run is at step ", plan.step_of(output));
        if (o.vtk && fs::exists(files.collection())) {
            frames = sphere::pvd_collection::load(files.collection());
            frames.drop_from(sim->time() + dt / 2);
        }
        if (coupled && o.vtk && fs::exists(files.fluid_collection())) {
            fluid_frames = sphere::pvd_collection::load(files.fluid_collection());
            fluid_frames.drop_from(sim->time() + dt / 2);
        }
        if (!o.quiet) std::printf("resuming from output %zu (t = %.9g s)\n", output, sim->time());
    } else {
        sim.emplace(sphere::detail::restart_from<Sim>(input));
        if constexpr (coupled) fluid->restore(*input.fluid);
    }

    const auto write_output = [&](std::size_t k) {
        if constexpr (coupled) sphere::write_checkpoint(files.checkpoint(k), *sim, *fluid);
        else sphere::write_checkpoint(files.checkpoint(k), *sim);
        if (o.vtk) {
            sphere::write_vtu(files.folder + "/" + files.frame(k), *sim);
            frames.add(sim->time(), files.frame(k));
            if constexpr (coupled) {
                sphere::write_vti(files.folder + "/" + files.fluid_frame(k), *fluid, sim->time());
                fluid_frames.add(sim->time(), files.fluid_frame(k));
            }
        }
        if (!o.render.empty()) write_picture(o, sim->snapshot(), files.folder + "/" + files.numbered(k, ".png"));
        status.time = sim->time();
        status.percent = plan.last > plan.first
                             ? 100.0 * double(sim->steps() - plan.first) / double(plan.last - plan.first)
                             : 100.0;
        status.last_output = k;
        status.write(files.status());
    };
    if (!fs::exists(files.status())) write_output(0);

    progress_line bar(o.quiet, plan, sim->steps());
    bar.show(sim->steps(), sim->time(), output, true);
    for (std::size_t k = output + 1; k < plan.outputs(); ++k) {
        while (sim->steps() < plan.step_of(k)) {
            if constexpr (coupled) fluid->step(*sim); // dem_steps steps, which divide the outputs' steps
            else sim->run(std::min<std::size_t>(plan.step_of(k) - sim->steps(), 100));
            bar.show(sim->steps(), sim->time(), k - 1, false);
        }
        write_output(k);
        bar.show(sim->steps(), sim->time(), k, k + 1 == plan.outputs());
    }
    bar.end();
    const bool filmed = o.film && program::write_film(files.folder, files.name, o.fps);
    if (!o.quiet)
        std::printf("t = %.9g s after %zu steps; output in %s/: %s.output00000 to %05zu (.ck%s%s), %s.status.dat%s\n",
                    sim->time(), sim->steps(), o.out.c_str(), files.name.c_str(), plan.outputs() - 1,
                    !o.vtk ? "" : coupled ? ", .vtu, .vti, .pvd, .fluid.pvd" : ", .vtu, .pvd",
                    o.render.empty() ? "" : ", .png", files.name.c_str(),
                    filmed ? (", " + files.name + ".mp4").c_str() : "");
    return 0;
}

/// Runs a coupled checkpoint: the coupling its setup describes (fluid/setup.cuh), on the grid
/// of its fluid section. The program builds the Gidaspow drag law with the mg or cg solver, in
/// float or double on the host backend.
template <class Sim>
int run_coupled(const options& o, const std::string& run_name, const std::string& bytes,
                const sphere::checkpoint_data<typename Sim::real_type, typename Sim::law_type>& input)
{
    using Real = typename Sim::real_type;
    const std::string where = "checkpoint '" + o.input + "'";
    const sphere::fluid_snapshot<Real>& state = *input.fluid;
#if defined(SPHERE_PROGRAM_CUDA)
    (void)run_name, (void)bytes, (void)state;
    sphere::detail::fail(where, " holds a pore-fluid section (model ", state.model,
                         "): sphere-cuda runs DEM checkpoints; the sphere program runs coupled ones on the host");
#else
    constexpr bool runs = std::is_same_v<typename Sim::precision_type, Real> &&
                          std::is_same_v<typename Sim::policy_type, sphere::host>;
    if constexpr (!runs) {
        sphere::detail::fail(where, " holds a pore-fluid section (model ", state.model, "): precision ",
                             o.precision, " is not coupled to the pore fluid; use float or double");
    } else {
        const sphere::coupling_setup<Real> setup = sphere::coupling_setup<Real>::read(state, where.c_str());
        const std::string name = run_name + ", " + setup.model + " (" + setup.solver + ")";
        sphere::setup_coupling<Real, sphere::host> coupling =
            sphere::make_coupling<Real, sphere::host>(setup, state.grid(), where + ": setup");
        return std::visit([&](auto& c) { return run_with<Sim>(o, name, bytes, input, c.get()); }, coupling);
    }
#endif
}

/// Runs the checkpoint (`bytes` the input file's) with the simulation type Sim: coupled to the
/// pore fluid its fluid section describes, or on its own.
template <class Sim>
int run(const options& o, const std::string& run_name, const std::string& bytes)
{
    using Real = typename Sim::real_type;
    using Law = typename Sim::law_type;
    const sphere::checkpoint_data<Real, Law> input = sphere::decode_checkpoint<Real, Law>(bytes, o.input);
    if (input.fluid) return run_coupled<Sim>(o, run_name, bytes, input);
    return run_with<Sim>(o, run_name, bytes, input, static_cast<no_fluid*>(nullptr));
}

/// The simulation type for the options and the checkpoint's precision and law; runs it.
template <class Policy, class Precision, class Law>
int run_integrator(const options& o, const std::string& precision, const std::string& bytes)
{
    const std::string law = Law::name();
    if (o.integrator == "verlet")
        return run<sphere::simulation<Precision, Policy, Law, sphere::integrate::velocity_verlet>>(
            o, law + ", " + precision + ", velocity Verlet, " + o.backend, bytes);
    return run<sphere::simulation<Precision, Policy, Law, sphere::integrate::semi_implicit_euler>>(
        o, law + ", " + precision + ", semi-implicit Euler, " + o.backend, bytes);
}

template <class Policy, class Law>
int run_precision(const options& o, const sphere::checkpoint_header& header, const std::string& bytes)
{
    const std::string p = o.precision == "file" ? (header.written_precision == 4 ? "float" : "double") : o.precision;
    if (p == "float") return run_integrator<Policy, float, Law>(o, p, bytes);
    if (p == "mixed") return run_integrator<Policy, sphere::mixed, Law>(o, p, bytes);
    return run_integrator<Policy, double, Law>(o, p, bytes);
}

template <class Policy>
int run_law(const options& o, const sphere::checkpoint_header& header, const std::string& bytes)
{
    using linear = sphere::contact::linear<>;
    using hertz = sphere::contact::hertz_mindlin<>;
    if (header.version < 5 || header.law == linear::name()) return run_precision<Policy, linear>(o, header, bytes);
    if (header.law == hertz::name()) return run_precision<Policy, hertz>(o, header, bytes);
    sphere::detail::fail("checkpoint '", o.input, "': contact law ", header.law, "; the sphere program runs ",
                         linear::name(), " and ", hertz::name(), " (other laws: restart from C++)");
}

/// Reads the input once (its header checked here, the rest by the run) and runs it on the
/// backend asked for.
int dispatch(const options& o)
{
#if defined(SPHERE_PROGRAM_CUDA)
    if (o.backend == "cuda") { // before anything is written
        int devices = 0;
        const cudaError_t found = cudaGetDeviceCount(&devices);
        if (found != cudaSuccess || devices == 0)
            sphere::detail::fail("--backend cuda: no CUDA device (",
                                 found != cudaSuccess ? cudaGetErrorString(found) : "none found", ")");
    }
#else
    if (o.backend == "cuda")
        sphere::detail::fail("--backend cuda: this sphere program was built for the host backend only; its CUDA "
                             "build is sphere-cuda (docs/program.md)");
#endif
    const std::string bytes = sphere::detail::checkpoint_bytes(o.input);
    sphere::checkpoint_header header;
    sphere::detail::open_checkpoint(bytes, o.input, header);
#if defined(SPHERE_PROGRAM_CUDA)
    if (o.backend == "cuda") return run_law<sphere::cuda>(o, header, bytes);
#endif
    return run_law<sphere::host>(o, header, bytes);
}

} // namespace

int main(int argc, char** argv)
{
#if defined(SPHERE_PROGRAM_CUDA)
    const std::string backends = "host, cuda";
#else
    const std::string backends = "host";
#endif
    options o;
    CLI::App app{"sphere: runs the simulation a checkpoint describes until --total seconds of simulated time, "
                 "writing numbered checkpoints, VTK frames and a status file into the output folder; run again, "
                 "it resumes from the last output"};
    app.set_version_flag("-V,--version", std::string("sphere ") + SPHERE_PROGRAM_VERSION + " (checkpoint format " +
                                             std::to_string(sphere::checkpoint_format_version) +
                                             ", backends: " + backends + ")");
    app.add_option("input", o.input, "the checkpoint to run (a .ck file)")->required();
    app.add_option("-o,--out", o.out, "output folder (created)")->capture_default_str();
    app.add_option("-t,--total", o.total, "simulated time to run to (s), counted from the simulation's start");
    app.add_option("-i,--interval", o.interval,
                   "simulated time between outputs (s); default a tenth of the run");
    app.add_option("--backend", o.backend, "host or cuda")->check(CLI::IsMember({"host", "cuda"}))->capture_default_str();
    app.add_option("--precision", o.precision, "file (the checkpoint's), float, double or mixed")
        ->check(CLI::IsMember({"file", "float", "double", "mixed"}))->capture_default_str();
    app.add_option("--integrator", o.integrator, "euler (semi-implicit) or verlet (velocity Verlet)")
        ->check(CLI::IsMember({"euler", "verlet"}))->capture_default_str();
    app.add_flag("-n,--dry", o.dry, "print the settings, the time step and the plan of the run; run nothing");
    app.add_flag("--fresh", o.fresh, "start from the input, replacing an earlier run's output of it");
    app.add_flag("!--no-vtk", o.vtk, "write no VTK frames");
    app.add_option("-r,--render", o.render,
                   "also write a PNG picture of every output, coloured by normal, pres, vel, angvel or xdisp; "
                   "without --total, only a picture of the input")
        ->check(CLI::IsMember({"normal", "pres", "vel", "angvel", "xdisp"}));
    app.add_flag("--film", o.film, "join the pictures of --render into <name>.mp4 with ffmpeg at the end, when installed")
        ->needs("--render");
    app.add_option("--fps", o.fps, "frames per second of the film")->check(CLI::Range(0.01, 1000.0))->capture_default_str();
    app.add_option("--max-val", o.max_val, "top of the pictures' colour map (default: each picture's largest value)");
    app.add_option("--lower-cutoff", o.lower_cutoff, "bottom of the colour map; particles below it are not drawn")
        ->capture_default_str();
    app.add_flag("-q,--quiet", o.quiet, "no progress line and no summary");
    CLI11_PARSE(app, argc, argv);
    try {
        return dispatch(o);
    } catch (const std::exception& ex) {
        if (!o.quiet) std::fprintf(stderr, "\n");
        std::cerr << ex.what() << '\n';
        return 1;
    }
}
