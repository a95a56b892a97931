// VTK ImageData output of the fluid grid (include/sphere/io/vti.cuh, docs/io.md), float and
// double: the text of a .vti written from known fields is parsed here independently (extent,
// origin, spacing, time, every cell value in VTK's cell order, ghosts left out), the solver and
// coupling overloads write what their accessors hold, fields of the wrong size are refused, and
// vti_writer numbers its frames and keeps the .pvd. tests/read_vti.py reads such files with
// VTK's own reader (CTest fluid_io_vti_read).
#include <catch2/catch.hpp>

#include "temp_folder.hpp"

#include <sphere/dem.cuh>
#include <sphere/fluid.cuh>
#include <sphere/io/vti.cuh>

#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <locale>
#include <map>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include <unistd.h>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_vti {

namespace {

namespace fs = std::filesystem;
using sphere::vec3;

using sphere_test::read_bytes;
using sphere_test::temp_folder;

/// The value of attribute `name` of the first element `<tag ...>` in `text`.
std::string attribute(const std::string& text, const std::string& tag, const std::string& name)
{
    const std::size_t at = text.find("<" + tag + " ");
    REQUIRE(at != std::string::npos);
    const std::string element = text.substr(at, text.find('>', at) - at);
    const std::string key = " " + name + "=\"";
    const std::size_t begin = element.find(key);
    if (begin == std::string::npos) return {};
    const std::size_t from = begin + key.size();
    return element.substr(from, element.find('"', from) - from);
}

std::vector<double> numbers(const std::string& text)
{
    std::istringstream in(text);
    in.imbue(std::locale::classic());
    std::vector<double> out;
    for (double v; in >> v;) out.push_back(v);
    return out;
}

struct data_array {
    std::string type;
    int components = 1;
    std::vector<double> values;
};

/// Every DataArray of the text by name, its values parsed as double.
std::map<std::string, data_array> data_arrays(const std::string& text)
{
    std::map<std::string, data_array> out;
    for (std::size_t at = text.find("<DataArray "); at != std::string::npos; at = text.find("<DataArray ", at + 1)) {
        const std::size_t open_end = text.find('>', at);
        const std::string element = text.substr(at, open_end - at + 1);
        const std::string name = attribute(element, "DataArray", "Name");
        data_array a;
        a.type = attribute(element, "DataArray", "type");
        const std::string c = attribute(element, "DataArray", "NumberOfComponents");
        a.components = c.empty() ? 1 : std::stoi(c);
        const std::size_t close = text.find("</DataArray>", open_end);
        a.values = numbers(text.substr(open_end + 1, close - open_end - 1));
        out[name] = a;
    }
    return out;
}

/// Known fields on a 3 x 2 x 4 grid over [-0.1, 0.2] x [0.2, 0.4] x [0.3, 1.1] (cells of 0.1,
/// 0.1, 0.2 m), every value exact in float; the ghosts hold -999, which must not be written.
template <class Real>
sphere::vti_fields<Real> known_fields(bool with_rate)
{
    sphere::world<Real> box;
    box.lo = {Real(-0.1), Real(0.2), Real(0.3)};
    box.hi = {Real(0.2), Real(0.4), Real(1.1)};
    sphere::vti_fields<Real> f;
    f.grid = sphere::fluid_grid<Real>::make(box, 3, 2, 4);
    const std::size_t n = f.grid.field_size();
    f.pressure.assign(n, Real(-999));
    f.velocity.assign(n, vec3<Real>{Real(-999), Real(-999), Real(-999)});
    f.porosity.assign(n, Real(-999));
    if (with_rate) f.porosity_rate.assign(n, Real(-999));
    for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 3; ++i) {
                const std::size_t c = f.grid.field_index(i, j, k);
                f.pressure[c] = Real(1000 * k + 100 * j + 10 * i + 1.5);
                f.velocity[c] = {Real(i + 0.25), Real(-j), Real(0.125 * k - 1)};
                f.porosity[c] = Real(0.5 + 0.0625 * i + 0.125 * j + 0.03125 * k);
                if (with_rate) f.porosity_rate[c] = Real(-0.5 * (i + 2 * j + 4 * k));
            }
    return f;
}

/// Compares the array `name` with the cell values of a field (VTK cell order: x fastest).
template <class Real>
void check_scalars(const std::map<std::string, data_array>& arrays, const std::string& name,
                   const std::vector<Real>& field, const sphere::fluid_grid<Real>& g)
{
    INFO("array " << name);
    REQUIRE(arrays.count(name) == 1);
    const data_array& a = arrays.at(name);
    CHECK(a.type == (sizeof(Real) == 8 ? "Float64" : "Float32"));
    CHECK(a.components == 1);
    REQUIRE(a.values.size() == g.cell_count());
    std::size_t m = 0;
    for (int k = 0; k < int(g.n[2]); ++k)
        for (int j = 0; j < int(g.n[1]); ++j)
            for (int i = 0; i < int(g.n[0]); ++i, ++m) {
                CAPTURE(i, j, k);
                CHECK(Real(a.values[m]) == field[g.field_index(i, j, k)]);
            }
}

template <class Real>
void check_vectors(const std::map<std::string, data_array>& arrays, const std::string& name,
                   const std::vector<vec3<Real>>& field, const sphere::fluid_grid<Real>& g)
{
    INFO("array " << name);
    REQUIRE(arrays.count(name) == 1);
    const data_array& a = arrays.at(name);
    CHECK(a.type == (sizeof(Real) == 8 ? "Float64" : "Float32"));
    CHECK(a.components == 3);
    REQUIRE(a.values.size() == 3 * g.cell_count());
    std::size_t m = 0;
    for (int k = 0; k < int(g.n[2]); ++k)
        for (int j = 0; j < int(g.n[1]); ++j)
            for (int i = 0; i < int(g.n[0]); ++i, ++m) {
                CAPTURE(i, j, k);
                const vec3<Real> v = field[g.field_index(i, j, k)];
                CHECK(Real(a.values[3 * m]) == v.x);
                CHECK(Real(a.values[3 * m + 1]) == v.y);
                CHECK(Real(a.values[3 * m + 2]) == v.z);
            }
}

template <class Real>
std::vector<Real> three(const std::string& text)
{
    std::vector<Real> out;
    for (double v : numbers(text)) out.push_back(Real(v));
    return out;
}

} // namespace

TEMPLATE_TEST_CASE("vti: known fields are written cell by cell with extent, origin, spacing and time", "[io][vti]",
                   float, double)
{
    using Real = TestType;
    const sphere::vti_fields<Real> f = known_fields<Real>(true);
    const double time = 0.1 + 1.0 / 3.0;
    const std::string text = sphere::vti_text(f, time);

    CHECK(text.rfind("<?xml version=\"1.0\"?>\n<VTKFile type=\"ImageData\" version=\"0.1\"", 0) == 0);
    CHECK(attribute(text, "ImageData", "WholeExtent") == "0 3 0 2 0 4");
    CHECK(attribute(text, "Piece", "Extent") == "0 3 0 2 0 4");
    CHECK(three<Real>(attribute(text, "ImageData", "Origin")) == std::vector<Real>{Real(-0.1), Real(0.2), Real(0.3)});
    CHECK(three<Real>(attribute(text, "ImageData", "Spacing")) ==
          std::vector<Real>{f.grid.width.x, f.grid.width.y, f.grid.width.z});
    CHECK(Real(numbers(attribute(text, "ImageData", "Spacing"))[2]) == Approx(0.2).epsilon(1e-6));
    // Cell data only: the point data block is empty.
    CHECK(text.find("<PointData>\n      </PointData>") != std::string::npos);
    CHECK(text.find("-999") == std::string::npos);

    const auto arrays = data_arrays(text);
    REQUIRE(arrays.count("TimeValue") == 1);
    CHECK(arrays.at("TimeValue").values == std::vector<double>{time});
    CHECK(arrays.size() == 5);
    check_scalars(arrays, "pressure", f.pressure, f.grid);
    check_vectors(arrays, "velocity", f.velocity, f.grid);
    check_scalars(arrays, "porosity", f.porosity, f.grid);
    check_scalars(arrays, "porosity_rate", f.porosity_rate, f.grid);
    // Spot check of VTK's cell order: cell id i + 3 (j + 2 k).
    CHECK(arrays.at("pressure").values[1 + 3 * (1 + 2 * 2)] == 2111.5);

    // Without a porosity rate the array is left out.
    const auto without = data_arrays(sphere::vti_text(known_fields<Real>(false), time));
    CHECK(without.count("porosity_rate") == 0);
    CHECK(without.count("porosity") == 1);
}

TEMPLATE_TEST_CASE("vti: fields of the wrong size are refused", "[io][vti]", float, double)
{
    using Real = TestType;
    sphere::vti_fields<Real> f = known_fields<Real>(true);
    f.porosity.resize(f.grid.cell_count()); // the cells without the ghosts
    CHECK_THROWS_WITH(sphere::vti_text(f, 0.0), Catch::Contains("field 'porosity' has 24 entries") &&
                                                    Catch::Contains("needs 120"));
    f = known_fields<Real>(true);
    f.porosity_rate.pop_back();
    CHECK_THROWS_WITH(sphere::vti_text(f, 0.0), Catch::Contains("field 'porosity_rate' has 119 entries"));
}

TEMPLATE_TEST_CASE("vti: write_vti and vti_writer write the text atomically, number frames and keep the .pvd",
                   "[io][vti]", float, double)
{
    using Real = TestType;
    temp_folder dir;
    const sphere::vti_fields<Real> f = known_fields<Real>(false);
    sphere::write_vti(dir / "one.vti", f, 0.5);
    CHECK(read_bytes(dir / "one.vti") == sphere::vti_text(f, 0.5));
    CHECK_FALSE(fs::exists(dir / "one.vti.tmp"));

    sphere::vti_writer out(dir / "frames", "water");
    CHECK(out.write(f, 0.0) == dir / "frames/water_000000.vti");
    CHECK(out.write(f, 0.25) == dir / "frames/water_000001.vti");
    CHECK(out.frames() == 2);
    CHECK(read_bytes(dir / "frames/water_000001.vti") == sphere::vti_text(f, 0.25));
    const sphere::pvd_collection pvd = sphere::pvd_collection::load(dir / "frames/water.pvd");
    REQUIRE(pvd.entries().size() == 2);
    CHECK(pvd.entries()[0].file == "water_000000.vti");
    CHECK(pvd.entries()[1].file == "water_000001.vti");
    CHECK(pvd.entries()[1].time == 0.25);

    CHECK_THROWS_WITH(sphere::vti_writer(dir.path, "a/b"), Catch::Contains("without '/'"));
    CHECK_THROWS_WITH(sphere::write_vti(dir / "missing/x.vti", f, 0.0), Catch::Contains("missing/x.vti"));
}

TEMPLATE_TEST_CASE("vti: a Navier-Stokes solver writes its pressure, cell-centre velocity and porosity", "[io][vti]",
                   float, double)
{
    using Real = TestType;
    sphere::world<Real> box;
    box.lo = {0, 0, 0};
    box.hi = {Real(0.04), Real(0.02), Real(0.1)};
    box.axis[0] = box.axis[1] = sphere::boundary::periodic;
    const auto g = sphere::fluid_grid<Real>::make(box, 4, 2, 5);
    sphere::fluid_params<Real> prm;
    prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(Real(5));
    sphere::navier_stokes<Real, sphere::host> fluid(g, prm);
    // v_x = z (so the cell-centre value is the centre's z), v_y = 2, v_z = 0.
    fluid.set_velocity([](const vec3<Real>& x) { return vec3<Real>{x.z, Real(2), Real(0)}; });

    const std::string text = sphere::vti_text(sphere::fluid_fields(fluid), 1.5);
    const auto arrays = data_arrays(text);
    CHECK(attribute(text, "ImageData", "WholeExtent") == "0 4 0 2 0 5");
    CHECK(arrays.count("porosity_rate") == 0);
    check_scalars(arrays, "pressure", fluid.pressure(), g);
    check_vectors(arrays, "velocity", fluid.cell_velocity(), g);
    check_scalars(arrays, "porosity", fluid.porosity(), g);
    // Independently: the top layer holds the prescribed 5 Pa, the rest 0; v = (z_c, 2, 0); phi = 1.
    const auto& p = arrays.at("pressure").values;
    const auto& v = arrays.at("velocity").values;
    for (std::size_t c = 0; c < g.cell_count(); ++c) {
        int i, j, k;
        g.coordinates(c, i, j, k);
        CAPTURE(i, j, k);
        CHECK(p[c] == (k == 4 ? 5.0 : 0.0));
        CHECK(v[3 * c] == Approx(double(g.centre(i, j, k).z)).epsilon(1e-6));
        CHECK(v[3 * c + 1] == 2.0);
        CHECK(v[3 * c + 2] == 0.0);
        CHECK(arrays.at("porosity").values[c] == 1.0);
    }
    temp_folder dir;
    sphere::write_vti(dir / "ns.vti", fluid, 1.5);
    CHECK(read_bytes(dir / "ns.vti") == text);
}

TEMPLATE_TEST_CASE("vti: a coupled fluid also writes the porosity rate", "[io][vti]", float, double)
{
    using Real = TestType;
    const double cell = 5e-3;
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(4 * cell), Real(4 * cell), Real(10 * cell)};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.contact.k_n = s.wall.k_n = s.contact.k_t = s.wall.k_t = Real(100);
    s.gravity = {0, 0, Real(-9.81)};
    sphere::particle<Real> ball;
    ball.position = {Real(1.5 * cell), Real(1.5 * cell), Real(5.2 * cell)};
    ball.radius = Real(1e-3);
    ball.density = 2600;
    sphere::simulation<Real, sphere::host> sim(s, {ball});
    sphere::fluid_params<Real> prm;
    prm.density = 1000;
    prm.viscosity = Real(0.1);
    prm.gravity = s.gravity;
    prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    prm.poisson.tolerance = sizeof(Real) == 8 ? 1e-10 : 1e-4;
    sphere::coupling_options opt;
    opt.dem_steps = 20;
    sphere::fluid_coupling<Real, sphere::host, sphere::drag::wen_yu, sphere::cg_poisson<Real, sphere::host>> coupled(
        sphere::fluid_grid<Real>::make(s.box, 4, 4, 10), prm, opt);
    for (int n = 0; n < 5; ++n) coupled.step(sim);

    const auto& g = coupled.fluid().grid();
    const auto arrays = data_arrays(sphere::vti_text(sphere::fluid_fields(coupled), sim.time()));
    const auto rate = coupled.porosity().fields().dphi_dt;
    check_scalars(arrays, "porosity_rate", rate, g);
    check_scalars(arrays, "porosity", coupled.fluid().porosity(), g);
    // The falling ball changes the porosity of its cell.
    CHECK(rate[g.field_index(1, 1, 5)] != Real(0));
    CHECK(arrays.at("porosity").values[g.index(1, 1, 5)] < 1.0);
    temp_folder dir;
    sphere::vti_writer out(dir.path);
    out.write(coupled, sim.time());
    CHECK(read_bytes(dir / "fluid_000000.vti") == sphere::vti_text(sphere::fluid_fields(coupled), sim.time()));
    CHECK(fs::exists(dir / "fluid.pvd"));
}

} // namespace test_vti
