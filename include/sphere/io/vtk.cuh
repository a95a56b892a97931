#pragma once
/// \file
/// VTK XML output for ParaView (docs/io.md, "VTK files"): one UnstructuredGrid file (.vtu) per
/// output time with every particle as a VTK_VERTEX point and its fields as point data, and a
/// .pvd collection listing the files with their times so that ParaView steps through time.
/// ASCII, with enough digits to read every value back exactly (17 for double, 9 for float).
/// Every file is written atomically (io/atomic_file.cuh). Host-only code.
///
/// Usage: write a frame now and then every 100 steps, updating out/particles.pvd:
///
///     auto vtk = sphere::add_vtk_output(sim, "out", 100);
///     sim.run(10000);
#include <cstddef>
#include <fstream>
#include <iomanip>
#include <limits>
#include <locale>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include <filesystem>

#include "../core/error.cuh"
#include "../bonds/bond_table.cuh"
#include "../boundary/world.cuh"
#include "../core/vec.cuh"
#include "../particles/state.cuh"
#include "atomic_file.cuh"

namespace sphere {

namespace detail {
/// VTK's name of a floating-point type.
template <class Real>
const char* vtk_float_type()
{
    return sizeof(Real) == 8 ? "Float64" : "Float32";
}

/// `text` with the five XML special characters escaped, for attribute values.
inline std::string xml_escape(const std::string& text)
{
    std::string out;
    for (const char c : text) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        case '\'': out += "&apos;"; break;
        default: out += c;
        }
    }
    return out;
}

/// Undoes xml_escape (and the numeric references &#NN; for ASCII characters).
inline std::string xml_unescape(const std::string& text)
{
    std::string out;
    for (std::size_t k = 0; k < text.size(); ++k) {
        if (text[k] != '&') {
            out += text[k];
            continue;
        }
        const std::size_t end = text.find(';', k);
        if (end == std::string::npos) {
            out += text[k];
            continue;
        }
        const std::string name = text.substr(k + 1, end - k - 1);
        if (name == "amp") out += '&';
        else if (name == "lt") out += '<';
        else if (name == "gt") out += '>';
        else if (name == "quot") out += '"';
        else if (name == "apos") out += '\'';
        else if (name.size() > 1 && name[0] == '#') out += static_cast<char>(std::stoi(name.substr(1)));
        else out += text.substr(k, end - k + 1);
        k = end;
    }
    return out;
}

/// A string stream that writes numbers in the C locale with `digits` significant digits.
inline std::ostringstream number_stream(int digits)
{
    std::ostringstream out;
    out.imbue(std::locale::classic());
    out.precision(digits);
    return out;
}

template <class Real>
void vtk_scalars(std::ostream& out, const char* name, const std::vector<Real>& values)
{
    out << "        <DataArray type=\"" << vtk_float_type<Real>() << "\" Name=\"" << name << "\" format=\"ascii\">\n";
    for (const Real v : values) out << "          " << v << '\n';
    out << "        </DataArray>\n";
}

template <class Real>
void vtk_vectors(std::ostream& out, const char* name, const std::vector<vec3<Real>>& values)
{
    out << "        <DataArray type=\"" << vtk_float_type<Real>() << "\" Name=\"" << name
        << "\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const vec3<Real>& v : values) out << "          " << v.x << ' ' << v.y << ' ' << v.z << '\n';
    out << "        </DataArray>\n";
}

/// The start of a .vtu file up to its points: the time `time` (s) as field data, a piece of
/// the snapshot's particle centres as points (m) and `cells` cells.
template <class Real>
void vtu_points(std::ostream& out, const particle_snapshot<Real>& p, double time, std::size_t cells)
{
    const std::size_t n = p.size();
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        << "  <UnstructuredGrid>\n"
        << "    <FieldData>\n"
        << "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">"
        << std::setprecision(17) << time << std::setprecision(std::numeric_limits<Real>::max_digits10)
        << "</DataArray>\n"
        << "    </FieldData>\n"
        << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << cells << "\">\n"
        << "      <Points>\n"
        << "        <DataArray type=\"" << vtk_float_type<Real>()
        << "\" Name=\"position\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << "          " << p.x[i].x << ' ' << p.x[i].y << ' ' << p.x[i].z << '\n';
    out << "        </DataArray>\n"
        << "      </Points>\n";
}
} // namespace detail

/// The text of a .vtu file (VTK XML UnstructuredGrid, ASCII) holding the particles of a
/// snapshot at time `time` (s); see write_vtu.
template <class Real>
std::string vtu_text(const particle_snapshot<Real>& p, double time)
{
    const std::size_t n = p.size();
    std::ostringstream out = detail::number_stream(std::numeric_limits<Real>::max_digits10);
    detail::vtu_points(out, p, time, n);
    out << "      <Cells>\n"
        << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << "          " << i << '\n';
    out << "        </DataArray>\n"
        << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << "          " << i + 1 << '\n';
    out << "        </DataArray>\n"
        << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << "          1\n"; // VTK_VERTEX
    out << "        </DataArray>\n"
        << "      </Cells>\n"
        << "      <PointData Scalars=\"radius\" Vectors=\"velocity\">\n";
    std::vector<Real> radius(n);
    for (std::size_t i = 0; i < n; ++i) radius[i] = p.x[i].w;
    detail::vtk_scalars(out, "radius", radius);
    detail::vtk_vectors(out, "velocity", p.v_sync);
    detail::vtk_vectors(out, "angular_velocity", p.omega_sync);
    detail::vtk_vectors(out, "angular_position", p.angpos);
    detail::vtk_vectors(out, "force", p.force);
    detail::vtk_vectors(out, "torque", p.torque);
    detail::vtk_scalars(out, "mass", p.mass);
    detail::vtk_scalars(out, "pressure", p.pressure);
    detail::vtk_scalars(out, "dissipated_viscous", p.e_visc);
    detail::vtk_scalars(out, "dissipated_frictional", p.e_fric);
    // zeros for a snapshot made without the field (one built by hand)
    detail::vtk_vectors(out, "accumulated_displacement",
                        p.displacement.size() == n ? p.displacement : std::vector<vec3<Real>>(n, vec3<Real>{0, 0, 0}));
    out << "        <DataArray type=\"UInt8\" Name=\"kind\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << "          " << unsigned(p.kind[i]) << '\n';
    out << "        </DataArray>\n";
    out << "        <DataArray type=\"UInt8\" Name=\"material\" format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << "          " << unsigned(p.material[i]) << '\n';
    out << "        </DataArray>\n"
        << "      </PointData>\n"
        << "    </Piece>\n"
        << "  </UnstructuredGrid>\n"
        << "</VTKFile>\n";
    return out.str();
}

/// Writes the particles of a snapshot at time `time` (s) to the .vtu file `path`, atomically.
/// Points are the particle centres (m); point data: radius (m), velocity (m/s) and
/// angular_velocity (rad/s) at the time of the positions (v_sync, omega_sync), angular_position
/// (rad), force (N) and torque (N m) of the last step's contacts, mass (kg), pressure (Pa),
/// dissipated_viscous and dissipated_frictional (J), accumulated_displacement (m, sum of v dt:
/// settings.accumulated_displacement), kind (0 free, 1 prescribed, 2 fixed, 3 prescribed_horizontal),
/// material (the material index, contact::materials);
/// field data TimeValue (s). Throws sphere::error naming the file when it cannot be written.
template <class Real>
void write_vtu(const std::string& path, const particle_snapshot<Real>& p, double time)
{
    write_file_atomically(path, vtu_text(p, time));
}

/// Writes the particles of a simulation at its current time to `path` (see above).
template <class Sim>
void write_vtu(const std::string& path, const Sim& sim)
{
    write_vtu(path, sim.snapshot(), sim.time());
}

/// The text of a .vtu file holding the bonds of a snapshot at time `time` (s): the particle
/// centres as points (m) and each intact bond as a line cell (VTK_LINE) from its particle i to
/// its particle j; cell data bond (its index in the bond table), axis (m, from i's centre to
/// j's, the nearest image in `box`), stretch (m, the axis' length less the rest length) and
/// force (N, on particle i).
template <class Real>
std::string bonds_vtu_text(const particle_snapshot<Real>& p, const bond_table<Real>& b, const world<Real>& box,
                           double time)
{
    std::vector<std::size_t> intact;
    for (std::size_t k = 0; k < b.size(); ++k)
        if (!b.broken[k]) intact.push_back(k);
    std::ostringstream out = detail::number_stream(std::numeric_limits<Real>::max_digits10);
    detail::vtu_points(out, p, time, intact.size());
    out << "      <Cells>\n"
        << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (std::size_t k : intact) out << "          " << b.i[k] << ' ' << b.j[k] << '\n';
    out << "        </DataArray>\n"
        << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t c = 0; c < intact.size(); ++c) out << "          " << 2 * (c + 1) << '\n';
    out << "        </DataArray>\n"
        << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
    for (std::size_t c = 0; c < intact.size(); ++c) out << "          3\n"; // VTK_LINE
    out << "        </DataArray>\n"
        << "      </Cells>\n"
        << "      <CellData Scalars=\"stretch\" Vectors=\"force\">\n"
        << "        <DataArray type=\"Int64\" Name=\"bond\" format=\"ascii\">\n";
    for (std::size_t k : intact) out << "          " << k << '\n';
    out << "        </DataArray>\n";
    std::vector<Real> stretch;
    std::vector<vec3<Real>> axis, force;
    for (std::size_t k : intact) {
        axis.push_back(box.nearest_image_inside(p.position(b.j[k]) - p.position(b.i[k])));
        stretch.push_back(Real(std::sqrt(double(norm2(axis.back()))) - double(b.rest[k])));
        force.push_back(b.force[k]);
    }
    detail::vtk_vectors(out, "axis", axis);
    detail::vtk_scalars(out, "stretch", stretch);
    detail::vtk_vectors(out, "force", force);
    out << "      </CellData>\n"
        << "    </Piece>\n"
        << "  </UnstructuredGrid>\n"
        << "</VTKFile>\n";
    return out.str();
}

/// Writes the bonds of a simulation at its current time to the .vtu file `path`, atomically
/// (bonds_vtu_text; a bond across a periodic boundary is drawn between the two centres as
/// stored, across the box). Throws sphere::error naming the file when it cannot be written.
template <class Sim>
void write_bonds_vtu(const std::string& path, const Sim& sim)
{
    write_file_atomically(path, bonds_vtu_text(sim.snapshot(), sim.bonds(), sim.config().box, sim.time()));
}

/// A ParaView collection file (.pvd): a list of (time, data file) entries. Every add()
/// rewrites the file atomically, so the .pvd on disk always lists complete frames only.
/// File names are written as given; ParaView resolves relative names against the .pvd's folder.
class pvd_collection {
public:
    /// One data file and its time (s).
    struct entry {
        double time;
        std::string file;
    };

    /// An empty collection to be written to `path`; nothing is written before the first add().
    explicit pvd_collection(std::string path) : path_(std::move(path)) {}

    /// Reads the entries of a .pvd file written by pvd_collection (for continuing a restarted
    /// run). Throws sphere::error naming the file when it cannot be read or holds no Collection.
    static pvd_collection load(const std::string& path)
    {
        std::ifstream in(path, std::ios::binary);
        if (!in) detail::fail("cannot read the ParaView collection '", path, "'");
        std::ostringstream text;
        text << in.rdbuf();
        const std::string s = text.str();
        if (s.find("<Collection") == std::string::npos)
            detail::fail("'", path, "' is not a ParaView collection: no <Collection> element");
        pvd_collection c(path);
        for (std::size_t at = s.find("<DataSet"); at != std::string::npos; at = s.find("<DataSet", at + 1)) {
            const std::size_t end = s.find('>', at);
            if (end == std::string::npos) break;
            const std::string element = s.substr(at, end - at);
            const std::string t = attribute(element, "timestep"), file = attribute(element, "file");
            std::istringstream number(t);
            number.imbue(std::locale::classic());
            double time = 0;
            if (!(number >> time) || file.empty())
                detail::fail("'", path, "': DataSet entry '", element, ">' has no valid timestep and file");
            c.entries_.push_back({time, file});
        }
        return c;
    }

    /// Appends (time (s), file), replacing an earlier entry for the same file, and rewrites the
    /// .pvd atomically. Throws sphere::error naming the file when it cannot be written.
    void add(double time, const std::string& file)
    {
        for (std::size_t k = 0; k < entries_.size(); ++k)
            if (entries_[k].file == file) {
                entries_.erase(entries_.begin() + static_cast<std::ptrdiff_t>(k));
                break;
            }
        entries_.push_back({time, file});
        write();
    }

    /// Forgets the entries at or after `time` (s) (a restarted run rewrites them); does not write.
    void drop_from(double time)
    {
        std::vector<entry> kept;
        for (const entry& e : entries_)
            if (e.time < time) kept.push_back(e);
        entries_.swap(kept);
    }

    /// Writes the .pvd file atomically.
    void write() const { write_file_atomically(path_, text()); }

    /// The XML text of the collection.
    std::string text() const
    {
        std::ostringstream out = detail::number_stream(17);
        out << "<?xml version=\"1.0\"?>\n"
            << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
            << "  <Collection>\n";
        for (const entry& e : entries_)
            out << "    <DataSet timestep=\"" << e.time << "\" group=\"\" part=\"0\" file=\""
                << detail::xml_escape(e.file) << "\"/>\n";
        out << "  </Collection>\n"
            << "</VTKFile>\n";
        return out.str();
    }

    const std::vector<entry>& entries() const { return entries_; }
    const std::string& path() const { return path_; }

private:
    /// The value of attribute `name` in an element's text, unescaped; empty when absent.
    static std::string attribute(const std::string& element, const std::string& name)
    {
        const std::string key = " " + name + "=\"";
        const std::size_t at = element.find(key);
        if (at == std::string::npos) return {};
        const std::size_t begin = at + key.size(), end = element.find('"', begin);
        if (end == std::string::npos) return {};
        return detail::xml_unescape(element.substr(begin, end - begin));
    }

    std::string path_;
    std::vector<entry> entries_;
};

/// Writes numbered .vtu frames `<folder>/<prefix>_<NNNNNN>.vtu` (NNNNNN = steps / every, six
/// digits or more) and keeps `<folder>/<prefix>.pvd` listing them. Creates the folder.
class vtk_writer {
public:
    /// Throws sphere::error when `prefix` is empty or holds a '/', `every` is 0, or the folder
    /// cannot be created. With `resume`, an existing `<prefix>.pvd` is read and its entries
    /// before the first frame this writer writes are kept (continuing a restarted run);
    /// without, the collection starts empty.
    vtk_writer(std::string folder, std::string prefix = "particles", std::size_t every = 1, bool resume = false)
        : folder_(std::move(folder)), prefix_(std::move(prefix)), every_(every),
          collection_(folder_ + "/" + prefix_ + ".pvd"), resume_(resume)
    {
        if (prefix_.empty() || prefix_.find('/') != std::string::npos)
            detail::fail("vtk_writer: prefix '", prefix_, "' must be a non-empty file name without '/'");
        if (every_ == 0) detail::fail("vtk_writer: output interval 0: must be at least 1 step");
        if (folder_.empty()) detail::fail("vtk_writer: empty output folder");
        std::error_code ec;
        std::filesystem::create_directories(folder_, ec);
        if (ec) detail::fail("vtk_writer: cannot create the output folder '", folder_, "': ", ec.message());
        if (resume_ && std::filesystem::exists(collection_.path())) collection_ = pvd_collection::load(collection_.path());
    }

    /// Writes the frame of the simulation's current step, adds it to the .pvd and rewrites
    /// that; returns the .vtu path. Call it at multiples of every(): the frame number is
    /// steps / every, and a frame written again replaces the earlier one.
    template <class Sim>
    std::string write(const Sim& sim)
    {
        if (resume_) { // entries from the run this one continues, at or after this time, are stale
            collection_.drop_from(sim.time());
            resume_ = false;
        }
        const std::string name = frame_name(sim.steps() / every_);
        const std::string path = folder_ + "/" + name;
        write_vtu(path, sim);
        collection_.add(sim.time(), name);
        return path;
    }

    /// The file name (without folder) of frame `frame`.
    std::string frame_name(std::size_t frame) const
    {
        std::ostringstream name;
        name << prefix_ << '_' << std::setw(6) << std::setfill('0') << frame << ".vtu";
        return name.str();
    }

    std::size_t every() const { return every_; }
    const std::string& folder() const { return folder_; }
    const pvd_collection& collection() const { return collection_; }

private:
    std::string folder_, prefix_;
    std::size_t every_;
    pvd_collection collection_;
    bool resume_;
};

/// Writes the simulation's current state as a frame now and then every `every` steps through
/// a vtk_writer (see there for names, `resume` and errors), registered as an observer of the
/// simulation. Returns the writer, which the observer shares.
template <class Sim>
std::shared_ptr<vtk_writer> add_vtk_output(Sim& sim, const std::string& folder, std::size_t every,
                                           const std::string& prefix = "particles", bool resume = false)
{
    auto writer = std::make_shared<vtk_writer>(folder, prefix, every, resume);
    writer->write(sim);
    sim.add_observer(every, [writer](const Sim& s) { writer->write(s); });
    return writer;
}

} // namespace sphere
