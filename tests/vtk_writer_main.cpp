// Test helper `vtk_writer_for_test DIR`: runs a small simulation in float and in double and
// writes, into DIR/float and DIR/double, VTK frames every 25 steps for 100 steps
// (particles_000000.vtu ... particles_000004.vtu and particles.pvd, through
// sphere::add_vtk_output) and expected.json: for every frame its file, step, time and every
// particle field taken directly from simulation::snapshot(), printed with 17 digits.
// tests/vtk_read.py reads the VTK files with VTK's own readers and compares. Exit status 0 on
// success, 1 on an error (message on stderr), 2 on bad usage.
#include <sphere/dem.cuh>
#include <sphere/io.cuh>

#include "support.hpp"

#include <cstddef>
#include <cstdint>
#include <exception>
#include <iostream>
#include <limits>
#include <locale>
#include <sstream>
#include <string>
#include <vector>

namespace {

/// Constants of the run that the reader checks against analytically.
constexpr double density = 2500;                  // kg/m^3, every particle
constexpr double prescribed_velocity = 0.05;      // m/s along x, particle 1
constexpr std::size_t every = 25, steps = 100;

template <class Real>
sphere::simulation<Real> make_simulation()
{
    sphere::settings<Real> s = sphere_test::frictional_box<Real>(0.05);
    s.box.hi.z = Real(0.04);
    s.wall = s.contact;
    s.skin = Real(0.002);
    std::vector<sphere::particle<Real>> ps;
    for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 3; ++i) {
                const int n = static_cast<int>(ps.size());
                sphere::particle<Real> p;
                p.position = {Real(-0.025 + 0.025 * i), Real(-0.025 + 0.025 * j), Real(-0.04 + 0.0195 * k)};
                p.radius = Real(0.009 + 0.0002 * (n % 7));
                p.density = Real(density);
                p.velocity = {Real(0.01 * (n % 5) - 0.02), Real(0.013 * (n % 3) - 0.01), Real(k == 1 ? -0.3 : 0.3)};
                p.angular_velocity = {Real(n % 4), Real(-(n % 3)), Real(0.5 * (n % 2))};
                ps.push_back(p);
            }
    ps[0].kind = sphere::motion::fixed;
    ps[1].kind = sphere::motion::prescribed;
    ps[1].velocity = {Real(prescribed_velocity), Real(0), Real(0)};
    ps[1].angular_velocity = {Real(0), Real(0), Real(0)};
    return sphere::simulation<Real>(s, ps);
}

std::ostringstream json_stream()
{
    std::ostringstream out;
    out.imbue(std::locale::classic());
    out.precision(17);
    return out;
}

template <class Real>
void scalars(std::ostream& out, const char* name, const std::vector<Real>& v)
{
    out << "\"" << name << "\": [";
    for (std::size_t i = 0; i < v.size(); ++i) out << (i ? ", " : "") << double(v[i]);
    out << "]";
}

template <class Real>
void vectors(std::ostream& out, const char* name, const std::vector<sphere::vec3<Real>>& v)
{
    out << "\"" << name << "\": [";
    for (std::size_t i = 0; i < v.size(); ++i)
        out << (i ? ", " : "") << "[" << double(v[i].x) << ", " << double(v[i].y) << ", " << double(v[i].z) << "]";
    out << "]";
}

/// One frame of expected.json from the snapshot taken directly from the simulation.
template <class Real>
std::string frame_json(const sphere::simulation<Real>& sim, const std::string& file)
{
    const sphere::particle_snapshot<Real> s = sim.snapshot();
    std::vector<sphere::vec3<Real>> position(s.size());
    std::vector<Real> radius(s.size());
    std::vector<unsigned> kind(s.size()), material(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        position[i] = s.position(i);
        radius[i] = s.radius(i);
        kind[i] = s.kind[i];
        material[i] = s.material[i];
    }
    std::ostringstream out = json_stream();
    out << "    {\"file\": \"" << file << "\", \"step\": " << sim.steps() << ", \"time\": " << sim.time()
        << ", \"points\": " << s.size() << ",\n     ";
    vectors(out, "position", position);
    out << ",\n     ";
    scalars(out, "radius", radius);
    out << ",\n     ";
    vectors(out, "velocity", s.v_sync);
    out << ",\n     ";
    vectors(out, "angular_velocity", s.omega_sync);
    out << ",\n     ";
    vectors(out, "angular_position", s.angpos);
    out << ",\n     ";
    vectors(out, "force", s.force);
    out << ",\n     ";
    vectors(out, "torque", s.torque);
    out << ",\n     ";
    scalars(out, "mass", s.mass);
    out << ",\n     ";
    scalars(out, "pressure", s.pressure);
    out << ",\n     ";
    scalars(out, "dissipated_viscous", s.e_visc);
    out << ",\n     ";
    scalars(out, "dissipated_frictional", s.e_fric);
    out << ",\n     ";
    vectors(out, "accumulated_displacement", s.displacement);
    out << ",\n     ";
    scalars(out, "kind", kind);
    out << ",\n     ";
    scalars(out, "material", material);
    out << "}";
    return out.str();
}

template <class Real>
void write_case(const std::string& folder, const char* precision)
{
    sphere::simulation<Real> sim = make_simulation<Real>();
    auto writer = sphere::add_vtk_output(sim, folder, every);
    std::vector<std::string> frames = {frame_json(sim, writer->frame_name(0))};
    sim.add_observer(every, [&](const sphere::simulation<Real>& s) {
        frames.push_back(frame_json(s, writer->frame_name(s.steps() / every)));
    });
    sim.run(steps);
    std::ostringstream out = json_stream();
    out << "{\"precision\": \"" << precision << "\", \"density\": " << density
        << ", \"prescribed_particle\": 1, \"prescribed_velocity\": [" << prescribed_velocity
        << ", 0, 0], \"fixed_particle\": 0, \"pvd\": \"particles.pvd\", \"frames\": [\n";
    for (std::size_t k = 0; k < frames.size(); ++k) out << frames[k] << (k + 1 < frames.size() ? ",\n" : "\n");
    out << "]}\n";
    sphere::write_file_atomically(folder + "/expected.json", out.str());
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 2) {
        std::cerr << "usage: vtk_writer_for_test DIR\n";
        return 2;
    }
    try {
        const std::string dir = argv[1];
        write_case<float>(dir + "/float", "float");
        write_case<double>(dir + "/double", "double");
    } catch (const std::exception& e) {
        std::cerr << e.what() << "\n";
        return 1;
    }
    return 0;
}
