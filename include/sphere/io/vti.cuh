#pragma once
/// \file
/// VTK XML ImageData output (.vti) of the fluid grid for ParaView (docs/io.md, "Fluid VTK
/// files"): one file per output time with one VTK cell per fluid cell (the ghost layers are
/// left out) and the fluid fields as cell data, and a .pvd collection (io/vtk.cuh's
/// pvd_collection) listing the frames with their times. ASCII, with enough digits to read
/// every value back exactly (17 for double, 9 for float), written atomically
/// (io/atomic_file.cuh), in the style of the particles' .vtu files (io/vtk.cuh). Host-only code.
///
/// Usage: a frame of a coupled run every so often, updating out/fluid.pvd:
///
///     sphere::vti_writer fluid_out("out");            // out/fluid_NNNNNN.vti + out/fluid.pvd
///     fluid_out.write(coupling, sim.time());          // or fluid_out.write(solver, t)
#include <cstddef>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <filesystem>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../fluid/coupling.cuh"
#include "../fluid/darcy.cuh"
#include "../fluid/grid.cuh"
#include "../fluid/navier_stokes.cuh"
#include "atomic_file.cuh"
#include "vtk.cuh"

namespace sphere {

/// Host copies of the fluid fields of one output time, every vector in the fluid grid's field
/// layout (fluid_grid::field_index, one ghost layer: field_size() entries), as the solver's
/// accessors return them. Only the cells are written. An empty `porosity_rate` is left out of
/// the file (a solver on its own does not know it; the coupling does).
template <class Real>
struct vti_fields {
    fluid_grid<Real> grid;
    std::vector<Real> pressure;          ///< p (Pa)
    std::vector<vec3<Real>> velocity;    ///< fluid velocity at the cell centres (m/s)
    std::vector<Real> porosity;          ///< phi (-)
    std::vector<Real> porosity_rate;     ///< dphi/dt (1/s); empty: not written
};

/// The fields of a Navier-Stokes solver: pressure(), cell_velocity(), porosity(); no
/// porosity rate.
template <class Real, class Policy, class Poisson>
vti_fields<Real> fluid_fields(const navier_stokes<Real, Policy, Poisson>& fluid)
{
    return {fluid.grid(), fluid.pressure(), fluid.cell_velocity(), fluid.porosity(), {}};
}

/// The fields of the Darcy model: pressure(), cell_velocity() (the fluid's, v_s + q / phi),
/// porosity(); no porosity rate.
template <class Real, class Policy, class Poisson>
vti_fields<Real> fluid_fields(darcy_flow<Real, Policy, Poisson>& fluid)
{
    return {fluid.grid(), fluid.pressure(), fluid.cell_velocity(), fluid.porosity(), {}};
}

/// The fields of a coupled fluid: its model's, and the porosity rate of the coupling's
/// porosity estimator (the rate the last fluid step used).
template <class Real, class Policy, class Drag, class Poisson, template <class, class, class> class Model>
vti_fields<Real> fluid_fields(fluid_coupling<Real, Policy, Drag, Poisson, Model>& coupling)
{
    vti_fields<Real> f = fluid_fields(coupling.fluid());
    f.porosity_rate = coupling.porosity().fields().dphi_dt;
    return f;
}

namespace detail {
/// The cell entries (not the ghosts) of a field in field layout, in VTK's cell order (x
/// fastest, then y, then z: fluid_grid::index order). Throws when the field has the wrong size.
template <class T, class Real>
std::vector<T> vti_cells(const std::vector<T>& field, const fluid_grid<Real>& g, const char* name)
{
    if (field.size() != g.field_size())
        fail("vti: field '", name, "' has ", field.size(), " entries; the fluid grid of ", g.n[0], " x ", g.n[1], " x ",
             g.n[2], " cells needs ", g.field_size(), " (cells and ghost layers, fluid_grid::field_index)");
    std::vector<T> out;
    out.reserve(g.cell_count());
    for (int k = 0; k < int(g.n[2]); ++k)
        for (int j = 0; j < int(g.n[1]); ++j)
            for (int i = 0; i < int(g.n[0]); ++i) out.push_back(field[g.field_index(i, j, k)]);
    return out;
}
} // namespace detail

/// The text of a .vti file (VTK XML ImageData, ASCII) of the fluid fields at time `time` (s);
/// see write_vti. Throws sphere::error when a field's size does not match the grid.
template <class Real>
std::string vti_text(const vti_fields<Real>& f, double time)
{
    const fluid_grid<Real>& g = f.grid;
    const std::vector<Real> pressure = detail::vti_cells(f.pressure, g, "pressure");
    const std::vector<vec3<Real>> velocity = detail::vti_cells(f.velocity, g, "velocity");
    const std::vector<Real> porosity = detail::vti_cells(f.porosity, g, "porosity");
    std::vector<Real> rate;
    if (!f.porosity_rate.empty()) rate = detail::vti_cells(f.porosity_rate, g, "porosity_rate");

    std::ostringstream out = detail::number_stream(std::numeric_limits<Real>::max_digits10);
    std::ostringstream extent;
    extent << "0 " << g.n[0] << " 0 " << g.n[1] << " 0 " << g.n[2];
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"ImageData\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <ImageData WholeExtent=\"" << extent.str() << "\" Origin=\"" << g.box.lo.x << ' ' << g.box.lo.y << ' '
        << g.box.lo.z << "\" Spacing=\"" << g.width.x << ' ' << g.width.y << ' ' << g.width.z << "\">\n"
        << "    <FieldData>\n"
        << "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">"
        << std::setprecision(17) << time << std::setprecision(std::numeric_limits<Real>::max_digits10)
        << "</DataArray>\n"
        << "    </FieldData>\n"
        << "    <Piece Extent=\"" << extent.str() << "\">\n"
        << "      <PointData>\n"
        << "      </PointData>\n"
        << "      <CellData Scalars=\"pressure\" Vectors=\"velocity\">\n";
    detail::vtk_scalars(out, "pressure", pressure);
    detail::vtk_vectors(out, "velocity", velocity);
    detail::vtk_scalars(out, "porosity", porosity);
    if (!rate.empty()) detail::vtk_scalars(out, "porosity_rate", rate);
    out << "      </CellData>\n"
        << "    </Piece>\n"
        << "  </ImageData>\n"
        << "</VTKFile>\n";
    return out.str();
}

/// Writes the fluid fields at time `time` (s) to the .vti file `path`, atomically: an
/// ImageData with WholeExtent "0 nx 0 ny 0 nz" (points; nx x ny x nz cells), Origin the lower
/// corner of the fluid grid's box (m) and Spacing the cell widths (m); cell data pressure
/// (Pa), velocity (m/s, cell centre: the mean of the two faces per axis), porosity (-) and,
/// when given, porosity_rate (1/s); field data TimeValue (s). Throws sphere::error naming the
/// file when it cannot be written, or when a field's size does not match the grid.
template <class Real>
void write_vti(const std::string& path, const vti_fields<Real>& f, double time)
{
    write_file_atomically(path, vti_text(f, time));
}

/// Writes the fields of a Navier-Stokes solver (no porosity_rate) at time `time` (s).
template <class Real, class Policy, class Poisson>
void write_vti(const std::string& path, const navier_stokes<Real, Policy, Poisson>& fluid, double time)
{
    write_vti(path, fluid_fields(fluid), time);
}

/// Writes the fields of the Darcy model (no porosity_rate) at time `time` (s).
template <class Real, class Policy, class Poisson>
void write_vti(const std::string& path, darcy_flow<Real, Policy, Poisson>& fluid, double time)
{
    write_vti(path, fluid_fields(fluid), time);
}

/// Writes the fields of a coupled fluid (either model), with the porosity rate, at time `time` (s).
template <class Real, class Policy, class Drag, class Poisson, template <class, class, class> class Model>
void write_vti(const std::string& path, fluid_coupling<Real, Policy, Drag, Poisson, Model>& coupling, double time)
{
    write_vti(path, fluid_fields(coupling), time);
}

/// Writes numbered .vti frames `<folder>/<prefix>_<NNNNNN>.vti` (NNNNNN = 0, 1, 2, ... in the
/// order of the write calls, six digits or more) and keeps `<folder>/<prefix>.pvd` listing
/// them with their times. Creates the folder.
class vti_writer {
public:
    /// Throws sphere::error when `prefix` is empty or holds a '/', the folder is empty, or it
    /// cannot be created.
    explicit vti_writer(std::string folder, std::string prefix = "fluid")
        : folder_(std::move(folder)), prefix_(std::move(prefix)), collection_(folder_ + "/" + prefix_ + ".pvd")
    {
        if (prefix_.empty() || prefix_.find('/') != std::string::npos)
            detail::fail("vti_writer: prefix '", prefix_, "' must be a non-empty file name without '/'");
        if (folder_.empty()) detail::fail("vti_writer: empty output folder");
        std::error_code ec;
        std::filesystem::create_directories(folder_, ec);
        if (ec) detail::fail("vti_writer: cannot create the output folder '", folder_, "': ", ec.message());
    }

    /// Writes the next frame of `source` (vti_fields, a navier_stokes or darcy_flow solver or a
    /// fluid_coupling) at time `time` (s), adds it to the .pvd and rewrites that; returns the
    /// .vti path.
    template <class Source>
    std::string write(Source& source, double time)
    {
        const std::string name = frame_name(frames_);
        const std::string path = folder_ + "/" + name;
        write_vti(path, source, time);
        collection_.add(time, name);
        ++frames_;
        return path;
    }

    /// The file name (without folder) of frame `frame`.
    std::string frame_name(std::size_t frame) const
    {
        std::ostringstream name;
        name << prefix_ << '_' << std::setw(6) << std::setfill('0') << frame << ".vti";
        return name.str();
    }

    /// Frames written so far.
    std::size_t frames() const { return frames_; }
    const std::string& folder() const { return folder_; }
    const pvd_collection& collection() const { return collection_; }

private:
    std::string folder_, prefix_;
    pvd_collection collection_;
    std::size_t frames_ = 0;
};

} // namespace sphere
