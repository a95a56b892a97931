#pragma once
/// \file
/// Versioned binary checkpoints (docs/io.md, "Checkpoints"): everything a simulation needs to
/// continue, the settings with the time step actually used and every evolving field including
/// the contact history and the walls. Little-endian, every floating value stored as a double
/// (as sphere did), so a float run can continue a double one and vice versa. The file ends with
/// an FNV-1a 64 checksum, is written atomically (io/atomic_file.cuh), and a missing, truncated,
/// corrupt, wrong-version or inconsistent file is refused with a sphere::error naming the file
/// and what is wrong. Host-only code.
///
/// Restarting from the same precision on the host backend with the same thread count continues
/// bit-identically to the uninterrupted run:
///
///     sphere::write_checkpoint("run.ck", sim);
///     ...
///     auto sim2 = sphere::restart<sphere::simulation<double>>("run.ck");
///
/// A run coupled to the pore fluid stores the coupling's state too (format version 7, its
/// optional fluid section) and restarts bit-identically with a coupling built as before:
///
///     sphere::write_checkpoint("run.ck", sim, coupling);
///     ...
///     auto sim2 = sphere::restart<sphere::simulation<double>>("run.ck", coupling2);
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <ios>
#include <iterator>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "../boundary/wall_control.cuh"
#include "../boundary/walls.cuh"
#include "../boundary/world.cuh"
#include "../contact/params.cuh"
#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../fluid/snapshot.cuh"
#include "../particles/particle.cuh"
#include "../particles/state.cuh"
#include "../settings.cuh"
#include "../simulation.cuh"
#include "atomic_file.cuh"

namespace sphere {

/// The checkpoint format version this build writes. It also reads version 7, which predates
/// the accumulated displacement, version 6, which predates
/// the fluid section, version 5, which predates the bonds, and version 4, which predates the
/// contact-law interface and holds the linear law's parameters without the law's name.
inline constexpr std::uint32_t checkpoint_format_version = 8;
/// The oldest format version this build reads (the linear law's only).
inline constexpr std::uint32_t oldest_checkpoint_format_version = 4;

/// The first 8 bytes of every checkpoint.
inline constexpr char checkpoint_magic[9] = "SPHERECK";

/// The contents of a checkpoint, in the reader's precision, for a simulation with the contact
/// law `Law`.
template <class Real, class Law = contact::linear<>>
struct checkpoint_data {
    settings<Real, typename Law::template params<Real>> config; ///< the settings; config.dt is the time step the run used (s)
    simulation_state<Real> state;      ///< every evolving field
    std::uint32_t written_precision = 0; ///< sizeof the writer's Real: 4 (float) or 8 (double)
    std::uint32_t version = 0;           ///< the file's format version
    /// The pore fluid's state (a fluid_coupling's snapshot()), where the file has a fluid
    /// section (write_checkpoint(path, sim, coupling)); give it to the coupling's restore().
    std::optional<fluid_snapshot<Real>> fluid;

    /// Particle descriptions from which a simulation with these settings is built before
    /// restore(state) (particle_snapshot::descriptions).
    std::vector<particle<Real>> particles() const { return state.particles.descriptions(); }
};

namespace detail {

/// Bytes before the payload: magic (8), version (u32), writer precision (u32), payload size (u64).
inline constexpr std::size_t checkpoint_header_bytes = 24;
/// Bytes after the payload: the checksum (u64).
inline constexpr std::size_t checkpoint_checksum_bytes = 8;

/// FNV-1a, 64 bit, of `size` bytes.
inline std::uint64_t fnv1a64(const char* data, std::size_t size)
{
    std::uint64_t h = 14695981039346656037ull;
    for (std::size_t k = 0; k < size; ++k) {
        h ^= static_cast<unsigned char>(data[k]);
        h *= 1099511628211ull;
    }
    return h;
}

/// Appends little-endian values to a byte string.
class checkpoint_encoder {
public:
    std::string bytes;

    void u8(std::uint8_t v) { bytes += static_cast<char>(v); }
    void u32(std::uint32_t v)
    {
        char b[4];
        for (int k = 0; k < 4; ++k) b[k] = static_cast<char>((v >> (8 * k)) & 0xffu);
        bytes.append(b, 4);
    }
    void u64(std::uint64_t v)
    {
        char b[8];
        for (int k = 0; k < 8; ++k) b[k] = static_cast<char>((v >> (8 * k)) & 0xffu);
        bytes.append(b, 8);
    }
    void f64(double d)
    {
        std::uint64_t v;
        std::memcpy(&v, &d, sizeof v);
        u64(v);
    }
    template <class Real>
    void v3(const vec3<Real>& a)
    {
        f64(double(a.x));
        f64(double(a.y));
        f64(double(a.z));
    }
    template <class Real>
    void v4(const vec4<Real>& a)
    {
        f64(double(a.x));
        f64(double(a.y));
        f64(double(a.z));
        f64(double(a.w));
    }
    /// A contact law's parameters, field by field (Params::fields): floating values as f64,
    /// flags and enumerations as u32.
    template <class Params>
    void params(const Params& p)
    {
        Params::fields(p, [&](const char*, const auto& v, const char*) {
            using T = std::decay_t<decltype(v)>;
            if constexpr (std::is_floating_point_v<T>) f64(double(v));
            else if constexpr (std::is_same_v<T, bool>) u32(v ? 1u : 0u);
            else u32(static_cast<std::uint32_t>(v));
        });
    }
    /// A text: its length (u64), then its bytes.
    void text(const std::string& t)
    {
        u64(t.size());
        bytes += t;
    }
    /// An array: its element count (u64), then each element through `put`.
    template <class T, class Put>
    void array(const std::vector<T>& values, Put put)
    {
        u64(values.size());
        for (const T& v : values) put(*this, v);
    }
};

/// Reads little-endian values from a checksummed payload; a read past its end or a value out
/// of range means the contents do not fit together: a sphere::error naming the file.
class checkpoint_decoder {
public:
    checkpoint_decoder(const std::string& bytes, std::size_t begin, std::size_t end, const std::string& path)
        : bytes_(bytes), at_(begin), end_(end), path_(path)
    {
    }

    template <class... Parts>
    [[noreturn]] void inconsistent(const Parts&... parts) const
    {
        fail("checkpoint '", path_, "': inconsistent contents: ", parts...);
    }

    std::uint8_t u8(const char* what)
    {
        need(1, what);
        return static_cast<std::uint8_t>(bytes_[at_++]);
    }
    std::uint32_t u32(const char* what)
    {
        need(4, what);
        std::uint32_t v = 0;
        for (int k = 0; k < 4; ++k) v |= std::uint32_t(static_cast<unsigned char>(bytes_[at_ + k])) << (8 * k);
        at_ += 4;
        return v;
    }
    std::uint64_t u64(const char* what)
    {
        need(8, what);
        std::uint64_t v = 0;
        for (int k = 0; k < 8; ++k) v |= std::uint64_t(static_cast<unsigned char>(bytes_[at_ + k])) << (8 * k);
        at_ += 8;
        return v;
    }
    double f64(const char* what)
    {
        const std::uint64_t v = u64(what);
        double d;
        std::memcpy(&d, &v, sizeof d);
        return d;
    }
    /// A u32 that must be at most `max` (an enumeration or a flag).
    std::uint32_t choice(const char* what, std::uint32_t max)
    {
        const std::uint32_t v = u32(what);
        if (v > max) inconsistent(what, " = ", v, ", at most ", max, " is valid");
        return v;
    }
    template <class Real>
    vec3<Real> v3(const char* what)
    {
        const double x = f64(what), y = f64(what), z = f64(what);
        return {Real(x), Real(y), Real(z)};
    }
    template <class Real>
    vec4<Real> v4(const char* what)
    {
        const double x = f64(what), y = f64(what), z = f64(what), w = f64(what);
        return {Real(x), Real(y), Real(z), Real(w)};
    }
    /// A contact law's parameters (checkpoint_encoder::params); `what` names them.
    template <class Params>
    Params params(const char* what)
    {
        Params p;
        Params::fields(p, [&](const char* name, auto& v, const char*) {
            using T = std::decay_t<decltype(v)>;
            const std::string field = std::string(what) + "." + name;
            if constexpr (std::is_floating_point_v<T>) v = T(f64(field.c_str()));
            else if constexpr (std::is_same_v<T, bool>) v = choice(field.c_str(), 1) == 1;
            else if constexpr (std::is_integral_v<T>) v = static_cast<T>(choice(field.c_str(), std::numeric_limits<T>::max()));
            else v = static_cast<T>(choice(field.c_str(), largest_value(T{})));
        });
        return p;
    }
    /// A text of at most `max` bytes (checkpoint_encoder::text).
    std::string text(const char* what, std::uint64_t max)
    {
        const std::uint64_t size = u64(what);
        if (size > max) inconsistent(what, " is ", size, " bytes long, at most ", max, " are valid");
        need(static_cast<std::size_t>(size), what);
        std::string t = bytes_.substr(at_, static_cast<std::size_t>(size));
        at_ += static_cast<std::size_t>(size);
        return t;
    }
    /// An array of `expected` elements of `element_bytes` bytes each, read by `get`.
    template <class T, class Get>
    std::vector<T> array(const char* what, std::uint64_t expected, std::size_t element_bytes, Get get)
    {
        const std::uint64_t n = u64(what);
        if (n != expected) inconsistent(what, ": ", n, " entries, expected ", expected);
        if (n > (end_ - at_) / element_bytes)
            inconsistent(what, ": ", n, " entries of ", element_bytes, " bytes do not fit in the ", end_ - at_,
                         " bytes left");
        std::vector<T> out(static_cast<std::size_t>(n));
        for (T& v : out) v = get(*this);
        return out;
    }

    std::size_t left() const { return end_ - at_; }

private:
    void need(std::size_t k, const char* what) const
    {
        if (end_ - at_ < k) inconsistent("the payload ends before ", what);
    }

    const std::string& bytes_;
    std::size_t at_, end_;
    const std::string& path_;
};

/// The fluid section of a version 7 checkpoint after its flag (encode_checkpoint): a
/// fluid_snapshot, its values converted to Real. Refuses, naming what, a grid that
/// fluid_grid::make would refuse and entries that do not fit in the payload or share a name.
template <class Real>
fluid_snapshot<Real> decode_fluid_section(checkpoint_decoder& d)
{
    fluid_snapshot<Real> f;
    f.model = d.text("the fluid model's name", 4096);
    std::uint64_t cells = 1;
    for (int a = 0; a < 3; ++a) {
        f.n[a] = d.u32("the fluid grid's cell counts");
        if (f.n[a] < 1) d.inconsistent("the fluid grid has ", f.n[a], " cells along axis ", a, ", at least 1 is valid");
        cells *= f.n[a];
        if (cells > (std::uint64_t(1) << 28)) d.inconsistent("the fluid grid has more than 2^28 cells");
    }
    for (int a = 0; a < 3; ++a) f.lo[a] = d.f64("the fluid grid's box");
    for (int a = 0; a < 3; ++a) {
        f.hi[a] = d.f64("the fluid grid's box");
        if (!(std::isfinite(f.lo[a]) && std::isfinite(f.hi[a]) && f.lo[a] < f.hi[a]))
            d.inconsistent("the fluid grid spans [", f.lo[a], ", ", f.hi[a], "] m along axis ", a);
    }
    // Each entry takes at least its name's length (8 bytes) and 8 bytes of value or count.
    const auto entries = [&d](const char* what) {
        const std::uint64_t n = d.u64(what);
        if (n > d.left() / 16) d.inconsistent(what, " is ", n, ", but ", d.left(), " bytes are left");
        return static_cast<std::size_t>(n);
    };
    const auto unique = [&d](const auto& list, const std::string& name, const char* kind) {
        for (const auto& e : list)
            if (e.name == name) d.inconsistent("the fluid section holds two ", kind, " named \"", name, "\"");
    };
    const std::size_t arrays = entries("the fluid array count");
    for (std::size_t k = 0; k < arrays; ++k) {
        const std::string name = d.text("a fluid array's name", 4096);
        unique(f.arrays, name, "arrays");
        const std::string what = "the fluid array \"" + name + "\"";
        const std::uint64_t n = d.u64(what.c_str());
        if (n > d.left() / 8)
            d.inconsistent(what, ": ", n, " values of 8 bytes do not fit in the ", d.left(), " bytes left");
        std::vector<Real> values(static_cast<std::size_t>(n));
        for (Real& v : values) v = Real(d.f64(what.c_str()));
        f.arrays.push_back({name, std::move(values)});
    }
    const std::size_t numbers = entries("the fluid number count");
    for (std::size_t k = 0; k < numbers; ++k) {
        const std::string name = d.text("a fluid number's name", 4096);
        unique(f.numbers, name, "numbers");
        f.numbers.push_back({name, d.f64(("the fluid number \"" + name + "\"").c_str())});
    }
    const std::size_t counts = entries("the fluid count count");
    for (std::size_t k = 0; k < counts; ++k) {
        const std::string name = d.text("a fluid count's name", 4096);
        unique(f.counts, name, "counts");
        f.counts.push_back({name, d.u64(("the fluid count \"" + name + "\"").c_str())});
    }
    return f;
}

} // namespace detail

/// The bytes of a checkpoint (the layout of docs/io.md) for a simulation with the contact law
/// `Law`, its settings `config`, the time step `dt` (s) the run uses (stored in place of
/// config.dt) and a state, and, unless `fluid` is null, the pore fluid's state (a
/// fluid_coupling's snapshot()) in the fluid section.
template <class Law = contact::linear<>, class Real>
std::string encode_checkpoint(const settings<Real, typename Law::template params<Real>>& config, Real dt,
                              const simulation_state<Real>& s, const fluid_snapshot<Real>* fluid = nullptr)
{
    using detail::checkpoint_encoder;
    const std::size_t n = s.particles.size();
    checkpoint_encoder e;
    e.bytes.reserve(detail::checkpoint_header_bytes + 1024 + n * (32 * 8 + 1 + 4 + 32 + 6 * 32) +
                    s.contacts.partner.size() * (4 + 32) + detail::checkpoint_checksum_bytes);
    e.bytes.append(checkpoint_magic, 8);
    e.u32(checkpoint_format_version);
    e.u32(static_cast<std::uint32_t>(sizeof(Real)));
    e.u64(0); // payload size, patched below

    // The contact law, then the settings.
    e.text(Law::name());
    e.text(Law::history_layout);
    e.v3(config.box.lo);
    e.v3(config.box.hi);
    for (int a = 0; a < 3; ++a) e.u32(static_cast<std::uint32_t>(config.box.axis[a]));
    e.params(config.contact);
    e.params(config.wall);
    e.v3(config.gravity);
    e.f64(double(dt));
    e.f64(double(config.skin));
    e.u32(config.contact_forces ? 1u : 0u);
    e.u32(config.energy_audit ? 1u : 0u);
    e.u32(config.angular_position ? 1u : 0u);
    e.f64(double(config.cell_size));
    for (const wall_control<Real>& c : config.walls) {
        e.u32(static_cast<std::uint32_t>(c.mode));
        e.f64(double(c.velocity));
        e.f64(double(c.stress));
        e.f64(double(c.amplitude));
        e.f64(double(c.frequency));
        e.f64(double(c.phase));
        e.f64(double(c.mass));
    }

    // State.
    e.u64(n);
    e.u64(s.steps);
    e.u64(s.rebuilds);
    e.u32(s.needs_rebuild ? 1u : 0u);
    for (const wall_face<Real>& w : s.walls.face) {
        e.u32(w.active ? 1u : 0u);
        e.f64(double(w.position));
        e.f64(double(w.velocity));
        e.f64(double(w.force));
        e.f64(double(w.work));
    }
    for (const wall_face<Real>& w : s.walls_at_build.face) e.f64(w.position);
    e.f64(s.drive_work);
    const auto put_v4 = [](checkpoint_encoder& out, const vec4<Real>& v) { out.v4(v); };
    const auto put_v3 = [](checkpoint_encoder& out, const vec3<Real>& v) { out.v3(v); };
    const auto put_real = [](checkpoint_encoder& out, Real v) { out.f64(double(v)); };
    const auto put_u32 = [](checkpoint_encoder& out, unsigned v) { out.u32(v); };
    const particle_snapshot<Real>& p = s.particles;
    e.array(p.x, put_v4);
    for (const auto* field : {&p.v, &p.omega, &p.v_sync, &p.omega_sync, &p.angpos, &p.force, &p.torque})
        e.array(*field, put_v3);
    for (const auto* field : {&p.mass, &p.pressure, &p.e_visc, &p.e_fric, &p.p_visc, &p.p_fric})
        e.array(*field, put_real);
    e.array(p.kind, [](checkpoint_encoder& out, std::uint8_t v) { out.u8(v); });
    if (law_material_count<Law>::value > 1) // only a law with materials stores them (docs/io.md)
        e.array(p.material, [](checkpoint_encoder& out, std::uint8_t v) { out.u8(v); });
    std::vector<unsigned> counts(n);
    for (std::size_t i = 0; i < n; ++i) counts[i] = static_cast<unsigned>(s.contacts.end(i) - s.contacts.begin(i));
    e.array(counts, put_u32);
    e.array(s.contacts.partner, put_u32);
    e.array(s.contacts.history, put_v4);
    if (s.contacts.shape.lanes != law_history_shape<Law>::value.lanes)
        detail::fail("checkpoint: the contact table's histories have ", s.contacts.shape.lanes,
                     " lanes beside the base, ", Law::name(), "'s have ", law_history_shape<Law>::value.lanes);
    if (s.contacts.shape.lanes) e.array(s.contacts.lane, put_real); // the law's own lanes (history_layout)
    e.array(s.x_at_build, put_v4);
    e.array(s.storage, put_u32);

    // The bonds (format 6): their settings, then each bond's particles, state and last loads.
    const bond_table<Real>& b = s.bonds;
    e.params(config.bond);
    e.u64(b.size());
    e.array(b.i, put_u32);
    e.array(b.j, put_u32);
    e.array(b.rest, put_real);
    e.array(b.shear, put_v4);
    e.array(b.bend, put_v3);
    e.array(b.broken, [](checkpoint_encoder& out, std::uint8_t v) { out.u8(v); });
    for (const auto* field : {&b.released, &b.dissipated}) e.array(*field, put_real);
    for (const auto* field : {&b.force, &b.torque_i, &b.torque_j}) e.array(*field, put_v3);

    // The pore fluid (format 7): a flag, then the snapshot's model, grid and named entries.
    e.u32(fluid ? 1u : 0u);
    if (fluid) {
        e.text(fluid->model);
        for (int a = 0; a < 3; ++a) e.u32(fluid->n[a]);
        for (int a = 0; a < 3; ++a) e.f64(fluid->lo[a]);
        for (int a = 0; a < 3; ++a) e.f64(fluid->hi[a]);
        e.u64(fluid->arrays.size());
        for (const auto& a : fluid->arrays) {
            e.text(a.name);
            e.array(a.values, put_real);
        }
        e.u64(fluid->numbers.size());
        for (const auto& x : fluid->numbers) {
            e.text(x.name);
            e.f64(x.value);
        }
        e.u64(fluid->counts.size());
        for (const auto& x : fluid->counts) {
            e.text(x.name);
            e.u64(x.value);
        }
    }
    // The accumulated displacement (format 8): settings.accumulated_displacement, and with it
    // each particle's.
    e.u32(config.accumulated_displacement ? 1u : 0u);
    if (config.accumulated_displacement) e.array(p.displacement, put_v3);

    const std::uint64_t payload = e.bytes.size() - detail::checkpoint_header_bytes;
    for (int k = 0; k < 8; ++k) e.bytes[16 + k] = static_cast<char>((payload >> (8 * k)) & 0xffu);
    e.u64(detail::fnv1a64(e.bytes.data(), e.bytes.size()));
    return e.bytes;
}

/// What a checkpoint says before its settings: the format version, the writer's precision and
/// (from version 5 on; empty before) the contact law's name and history layout.
struct checkpoint_header {
    std::uint32_t version = 0;           ///< the file's format version
    std::uint32_t written_precision = 0; ///< sizeof the writer's Real: 4 (float) or 8 (double)
    std::string law;                     ///< Law::name() of the writer's contact law
    std::string history_layout;          ///< Law::history_layout of the writer's contact law
};

namespace detail {

/// "8, 7, 6 and 5": the versions this build reads for every contact law, newest first.
inline std::string versions_for_every_law()
{
    std::string text;
    for (std::uint32_t v = checkpoint_format_version; v > oldest_checkpoint_format_version; --v)
        text += (text.empty() ? "" : v == oldest_checkpoint_format_version + 1 ? " and " : ", ") + std::to_string(v);
    return text;
}

/// Checks the bytes of a checkpoint as far as its contact law's name: magic, a format version
/// this build reads (oldest_checkpoint_format_version to checkpoint_format_version), size,
/// checksum and precision. Fills `header` and returns a decoder at the settings. Throws
/// sphere::error naming `path` and what is wrong.
inline checkpoint_decoder open_checkpoint(const std::string& bytes, const std::string& path, checkpoint_header& header)
{
    constexpr std::size_t head_bytes = checkpoint_header_bytes, tail = checkpoint_checksum_bytes;
    const std::size_t size = bytes.size();
    const std::size_t magic_seen = size < 8 ? size : 8;
    if (bytes.compare(0, magic_seen, checkpoint_magic, magic_seen) != 0)
        fail("checkpoint '", path, "': not a sphere checkpoint: the file does not start with \"", checkpoint_magic,
             "\"");
    if (size < head_bytes + tail)
        fail("checkpoint '", path, "': truncated: the file has ", size, " bytes, fewer than the ", head_bytes + tail,
             " of a header and checksum");
    checkpoint_decoder head(bytes, 8, head_bytes, path);
    const std::uint32_t version = head.u32("the format version");
    if (version < oldest_checkpoint_format_version || version > checkpoint_format_version)
        fail("checkpoint '", path, "': format version ", version, ", but this build reads versions ",
             versions_for_every_law(), ", and ", oldest_checkpoint_format_version, " for the linear contact law");
    const std::uint32_t precision = head.u32("the writer's precision");
    const std::uint64_t payload = head.u64("the payload size");
    if (payload > std::numeric_limits<std::uint64_t>::max() - head_bytes - tail)
        fail("checkpoint '", path, "': corrupt: the header gives an impossible payload size of ", payload, " bytes");
    const std::uint64_t expected = head_bytes + payload + tail;
    if (size < expected)
        fail("checkpoint '", path, "': truncated: the file has ", size, " bytes, a complete checkpoint has ", expected);
    if (size > expected)
        fail("checkpoint '", path, "': corrupt: the file has ", size, " bytes, a complete checkpoint has ", expected,
             " (trailing data)");
    std::uint64_t stored = 0;
    for (int k = 0; k < 8; ++k)
        stored |= std::uint64_t(static_cast<unsigned char>(bytes[size - tail + k])) << (8 * k);
    const std::uint64_t computed = fnv1a64(bytes.data(), size - tail);
    if (stored != computed) {
        std::ostringstream hex;
        hex << std::hex << "stored 0x" << stored << ", computed 0x" << computed;
        fail("checkpoint '", path, "': corrupt: checksum mismatch (", hex.str(), ")");
    }
    checkpoint_decoder d(bytes, head_bytes, size - tail, path);
    if (precision != 4 && precision != 8)
        d.inconsistent("the writer's precision is ", precision, " bytes, neither 4 (float) nor 8 (double)");
    header.version = version;
    header.written_precision = precision;
    if (version >= 5) {
        header.law = d.text("the contact law's name", 4096);
        header.history_layout = d.text("the contact history's layout", 4096);
    }
    return d;
}

/// The whole file at `path`; throws sphere::error `checkpoint '<path>': ...` when it cannot be
/// opened or read.
inline std::string checkpoint_bytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        const int code = errno;
        fail("checkpoint '", path, "': cannot open: ", std::strerror(code));
    }
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) fail("checkpoint '", path, "': cannot read the file");
    return bytes;
}

} // namespace detail

/// Decodes the bytes of a checkpoint into the precision Real; `path` names the file in
/// errors. Throws sphere::error (message `checkpoint '<path>': ...`, see docs/io.md) when the
/// bytes are not a checkpoint, have another format version, are truncated or longer than the
/// header says, fail the checksum, or hold contents that do not fit together.
template <class Real, class Law = contact::linear<>>
checkpoint_data<Real, Law> decode_checkpoint(const std::string& bytes, const std::string& path)
{
    using detail::checkpoint_decoder;
    using params = typename Law::template params<Real>;
    constexpr bool linear_params = std::is_same_v<params, contact_params<Real>>;
    checkpoint_header header;
    checkpoint_decoder d = detail::open_checkpoint(bytes, path, header);
    const std::uint32_t version = header.version;
    if (version == oldest_checkpoint_format_version && !linear_params)
        detail::fail("checkpoint '", path, "': format version 4, but this build reads versions ",
                     detail::versions_for_every_law(), ", and 4 only for the linear contact law, which version 4 "
                     "describes");
    if (version >= 5 && (header.law != Law::name() || header.history_layout != Law::history_layout))
        detail::fail("checkpoint '", path, "': written with the contact law ", header.law, " (history: ",
                     header.history_layout, "), but the reader uses ", Law::name(), " (history: ", Law::history_layout,
                     "); restart it with the same law");

    checkpoint_data<Real, Law> c;
    c.written_precision = header.written_precision;
    c.version = version;
    settings<Real, params>& s = c.config;
    s.box.lo = d.v3<Real>("settings.box.lo");
    s.box.hi = d.v3<Real>("settings.box.hi");
    for (int a = 0; a < 3; ++a) s.box.axis[a] = static_cast<boundary>(d.choice("settings.box.axis", 1));
    s.contact = d.params<params>("settings.contact");
    s.wall = d.params<params>("settings.wall");
    s.gravity = d.v3<Real>("settings.gravity");
    s.dt = Real(d.f64("the time step"));
    s.skin = Real(d.f64("settings.skin"));
    s.contact_forces = d.choice("settings.contact_forces", 1) == 1;
    s.energy_audit = d.choice("settings.energy_audit", 1) == 1;
    s.angular_position = d.choice("settings.angular_position", 1) == 1;
    s.cell_size = Real(d.f64("settings.cell_size"));
    for (wall_control<Real>& w : s.walls) {
        w.mode = static_cast<wall_mode>(d.choice("settings.walls[].mode", 2));
        w.velocity = Real(d.f64("settings.walls[].velocity"));
        w.stress = Real(d.f64("settings.walls[].stress"));
        w.amplitude = Real(d.f64("settings.walls[].amplitude"));
        w.frequency = Real(d.f64("settings.walls[].frequency"));
        w.phase = Real(d.f64("settings.walls[].phase"));
        w.mass = Real(d.f64("settings.walls[].mass"));
    }

    simulation_state<Real>& st = c.state;
    const std::uint64_t n = d.u64("the particle count");
    if (n < 1 || n >= std::numeric_limits<unsigned>::max())
        d.inconsistent("the particle count ", n, " is out of range (1 to 2^32 - 2)");
    st.steps = static_cast<std::size_t>(d.u64("the step count"));
    st.rebuilds = static_cast<std::size_t>(d.u64("the rebuild count"));
    st.needs_rebuild = d.choice("the rebuild flag", 1) == 1;
    for (int f = 0; f < wall_set<Real>::count; ++f) {
        wall_face<Real>& w = st.walls.face[f];
        w.active = d.choice("a wall's active flag", 1) == 1;
        // Converted to the type wall_face keeps its state in.
        w.position = static_cast<decltype(w.position)>(d.f64("a wall position"));
        w.velocity = static_cast<decltype(w.velocity)>(d.f64("a wall velocity"));
        w.force = static_cast<decltype(w.force)>(d.f64("a wall force"));
        w.work = static_cast<decltype(w.work)>(d.f64("a wall's work"));
        if (w.active == s.box.periodic(f / 2))
            d.inconsistent("wall face ", f, " is ", w.active ? "active" : "inactive", " but axis ", f / 2, " is ",
                           s.box.periodic(f / 2) ? "periodic" : "closed by walls");
    }
    for (int f = 0; f < wall_set<Real>::count; ++f) {
        st.walls_at_build.face[f] = st.walls.face[f];
        st.walls_at_build.face[f].position = d.f64("a wall position at the last rebuild");
    }
    st.drive_work = d.f64("the drive work");
    const auto get_v4 = [](checkpoint_decoder& in) { return in.v4<Real>("a 4-vector"); };
    const auto get_v3 = [](checkpoint_decoder& in) { return in.v3<Real>("a 3-vector"); };
    const auto get_real = [](checkpoint_decoder& in) { return Real(in.f64("a particle value")); };
    const auto get_u32 = [](checkpoint_decoder& in) { return static_cast<unsigned>(in.u32("a contact entry")); };
    particle_snapshot<Real>& p = st.particles;
    p.x = d.array<vec4<Real>>("the positions", n, 32, get_v4);
    const char* vector_names[7] = {"the velocities",      "the angular velocities", "the synchronous velocities",
                                   "the synchronous angular velocities", "the angular positions", "the forces",
                                   "the torques"};
    std::vector<vec3<Real>>* vectors[7] = {&p.v, &p.omega, &p.v_sync, &p.omega_sync, &p.angpos, &p.force, &p.torque};
    for (int k = 0; k < 7; ++k) *vectors[k] = d.array<vec3<Real>>(vector_names[k], n, 24, get_v3);
    const char* scalar_names[6] = {"the masses", "the pressures", "the viscous dissipation",
                                   "the frictional dissipation", "the viscous power", "the frictional power"};
    std::vector<Real>* scalars[6] = {&p.mass, &p.pressure, &p.e_visc, &p.e_fric, &p.p_visc, &p.p_fric};
    for (int k = 0; k < 6; ++k) *scalars[k] = d.array<Real>(scalar_names[k], n, 8, get_real);
    p.kind = d.array<std::uint8_t>("the motion kinds", n, 1,
                                   [](checkpoint_decoder& in) { return in.u8("a motion kind"); });
    for (std::size_t i = 0; i < p.kind.size(); ++i)
        if (p.kind[i] > last_motion)
            d.inconsistent("particle ", i, " has motion kind ", unsigned(p.kind[i]), ", at most ", unsigned(last_motion),
                           " is valid");
    constexpr unsigned materials = law_material_count<Law>::value;
    if (materials > 1) {
        p.material = d.array<std::uint8_t>("the materials", n, 1, [](checkpoint_decoder& in) { return in.u8("a material"); });
        for (std::size_t i = 0; i < n; ++i)
            if (p.material[i] >= materials)
                d.inconsistent("particle ", i, " has material ", unsigned(p.material[i]), ", but ", Law::name(), " has ",
                               materials);
    } else {
        p.material.assign(n, 0);
    }
    const std::vector<unsigned> counts = d.array<unsigned>("the contact counts", n, 4, get_u32);
    contact_table<Real>& t = st.contacts;
    t.offset.assign(n + 1, 0);
    for (std::size_t i = 0; i < n; ++i) t.offset[i + 1] = t.offset[i] + counts[i];
    t.partner = d.array<unsigned>("the contact partners", t.offset[n], 4, get_u32);
    t.history = d.array<vec4<Real>>("the contact histories", t.offset[n], 32, get_v4);
    t.shape = law_history_shape<Law>::value;
    if (t.shape.lanes)
        t.lane = d.array<Real>("the contact histories' lanes", t.offset[n] * t.shape.lanes, 8,
                               [](checkpoint_decoder& in) { return Real(in.f64("a history lane")); });
    st.x_at_build = d.array<vec4<Real>>("the positions at the last rebuild", n, 32, get_v4);
    st.storage = d.array<unsigned>("the storage order", n, 4, get_u32);
    if (version >= 6) {
        s.bond = d.params<bond_params<Real>>("settings.bond");
        bond_table<Real>& b = st.bonds;
        const std::uint64_t bonds = d.u64("the bond count");
        b.i = d.array<unsigned>("the bonds' first particles", bonds, 4, get_u32);
        b.j = d.array<unsigned>("the bonds' second particles", bonds, 4, get_u32);
        b.rest = d.array<Real>("the bonds' rest lengths", bonds, 8, get_real);
        b.shear = d.array<vec4<Real>>("the bonds' shear and twist", bonds, 32, get_v4);
        b.bend = d.array<vec3<Real>>("the bonds' bending", bonds, 24, get_v3);
        b.broken = d.array<std::uint8_t>("the bonds' broken flags", bonds, 1,
                                         [](checkpoint_decoder& in) { return in.u8("a bond's broken flag"); });
        b.released = d.array<Real>("the bonds' released energy", bonds, 8, get_real);
        b.dissipated = d.array<Real>("the bonds' dissipated energy", bonds, 8, get_real);
        b.force = d.array<vec3<Real>>("the bonds' forces", bonds, 24, get_v3);
        b.torque_i = d.array<vec3<Real>>("the bonds' torques on i", bonds, 24, get_v3);
        b.torque_j = d.array<vec3<Real>>("the bonds' torques on j", bonds, 24, get_v3);
        for (std::size_t k = 0; k < bonds; ++k)
            if (b.i[k] >= n || b.j[k] >= n || b.i[k] == b.j[k] || b.broken[k] > 1)
                d.inconsistent("bond ", k, " joins particles ", b.i[k], " and ", b.j[k], " (", n,
                               " particles) with broken flag ", unsigned(b.broken[k]), " (0 or 1)");
    }
    if (version >= 7 && d.choice("the fluid section's flag", 1) == 1) c.fluid = detail::decode_fluid_section<Real>(d);
    // A file before format 8 holds no accumulated displacement: it restarts without one.
    s.accumulated_displacement = version >= 8 && d.choice("settings.accumulated_displacement", 1) == 1;
    if (s.accumulated_displacement) p.displacement = d.array<vec3<Real>>("the accumulated displacements", n, 24, get_v3);
    else p.displacement.assign(n, vec3<Real>{0, 0, 0});
    if (d.left() != 0) d.inconsistent(d.left(), " bytes follow the last array");
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t e = t.begin(i); e < t.end(i); ++e) {
            const unsigned j = t.partner[e];
            const bool wall = j >= wall_partner_base && j < wall_partner_base + unsigned(wall_set<Real>::count) &&
                              st.walls.face[j - wall_partner_base].active;
            if (!wall && (j >= n || j == i))
                d.inconsistent("particle ", i, " lists partner ", j, " (", n, " particles, or an active wall face)");
        }
    std::vector<char> seen(n, 0);
    for (std::size_t k = 0; k < n; ++k) {
        if (st.storage[k] >= n || seen[st.storage[k]])
            d.inconsistent("the storage order is not a permutation: slot ", k, " holds particle ", st.storage[k]);
        seen[st.storage[k]] = 1;
    }
    return c;
}

/// Writes a checkpoint of settings `config`, time step `dt` (s) and a state to `path`
/// atomically; throws sphere::error naming the file when it cannot be written.
template <class Law = contact::linear<>, class Real>
void write_checkpoint(const std::string& path, const settings<Real, typename Law::template params<Real>>& config, Real dt,
                      const simulation_state<Real>& state)
{
    write_file_atomically(path, encode_checkpoint<Law>(config, dt, state));
}

/// Writes a checkpoint of a simulation (its settings, time step and state) to `path`
/// atomically; throws sphere::error naming the file when it cannot be written.
template <class Sim>
void write_checkpoint(const std::string& path, const Sim& sim)
{
    write_checkpoint<typename Sim::law_type>(path, sim.config(), sim.dt(), sim.state());
}

/// Writes a checkpoint of a simulation and the pore fluid coupled to it (a fluid_coupling:
/// its snapshot(), in the fluid section) to `path` atomically; sphere::restart(path, coupling)
/// continues both. Throws sphere::error naming the file when it cannot be written.
template <class Sim, class Coupling>
void write_checkpoint(const std::string& path, const Sim& sim, Coupling& coupling)
{
    const auto fluid = coupling.snapshot();
    static_assert(std::is_same_v<std::decay_t<decltype(fluid)>, fluid_snapshot<typename Sim::real_type>>,
                  "write_checkpoint(path, sim, coupling): the coupling's precision must be the simulation's");
    write_file_atomically(path, encode_checkpoint<typename Sim::law_type>(sim.config(), sim.dt(), sim.state(), &fluid));
}

/// Reads a checkpoint into the precision Real (values converted when the writer used the
/// other one). Throws sphere::error `checkpoint '<path>': ...` when the file cannot be opened or
/// read, or for any of the reasons of decode_checkpoint.
template <class Real, class Law = contact::linear<>>
checkpoint_data<Real, Law> read_checkpoint(const std::string& path)
{
    return decode_checkpoint<Real, Law>(detail::checkpoint_bytes(path), path);
}

/// The header of the checkpoint at `path` (format version, writer's precision, contact law),
/// after the checks of the whole file that read_checkpoint makes before the settings: a
/// program that runs checkpoints of several laws reads it to pick the simulation type. Throws
/// sphere::error `checkpoint '<path>': ...` as read_checkpoint does.
inline checkpoint_header read_checkpoint_header(const std::string& path)
{
    checkpoint_header header;
    detail::open_checkpoint(detail::checkpoint_bytes(path), path, header);
    return header;
}

namespace detail {
/// A simulation of type Sim built from a checkpoint's settings and particles, then restored
/// to its state (restart).
template <class Sim>
Sim restart_from(const checkpoint_data<typename Sim::real_type, typename Sim::law_type>& c)
{
    using Real = typename Sim::real_type;
    typename Sim::settings_type config = c.config;
    config.max_initial_overlap = std::numeric_limits<Real>::infinity(); // the state was accepted when it began
    Sim sim(config, c.particles());
    sim.restore(c.state);
    return sim;
}
} // namespace detail

/// A simulation of type Sim (e.g. sphere::simulation<float>) continuing from the checkpoint
/// at `path`: built from its settings and particles, then restored to its state. Observers
/// are not part of a checkpoint; add them again. Throws sphere::error for an unreadable
/// checkpoint (read_checkpoint) or settings the simulation refuses.
template <class Sim>
Sim restart(const std::string& path)
{
    using Real = typename Sim::real_type;
    return detail::restart_from<Sim>(read_checkpoint<Real, typename Sim::law_type>(path));
}

/// restart(path), and the pore fluid coupled to the simulation restored from the checkpoint's
/// fluid section (write_checkpoint(path, sim, coupling)). With `coupling` built as the written
/// run's was (grid, model and its parameters, options, drag law and pressure solver; none of
/// them is stored; the grid and the model are checked), the two continue bit-identically on the
/// host backend with the same precision and thread count (docs/fluid.md, *Restarting a coupled
/// run*). Throws sphere::error `checkpoint '<path>': ...` for the reasons of restart(path),
/// for a file without a fluid section, and for a fluid section the coupling's restore()
/// refuses (another model or grid, entries missing or unknown, arrays of another length);
/// the coupling is unchanged then.
template <class Sim, class Coupling>
Sim restart(const std::string& path, Coupling& coupling)
{
    using Real = typename Sim::real_type;
    const checkpoint_data<Real, typename Sim::law_type> c = read_checkpoint<Real, typename Sim::law_type>(path);
    if (!c.fluid)
        detail::fail("checkpoint '", path, "': no fluid section (format version ", c.version,
                     c.version >= 7 ? ", written without a coupling" : ", which has none",
                     "); a coupled run is written by write_checkpoint(path, sim, coupling)");
    Sim sim = detail::restart_from<Sim>(c);
    try {
        coupling.restore(*c.fluid);
    } catch (const error& e) {
        const std::string message = e.what(), prefix = "sphere: ";
        detail::fail("checkpoint '", path, "': ",
                     message.compare(0, prefix.size(), prefix) == 0 ? message.substr(prefix.size()) : message);
    }
    return sim;
}

} // namespace sphere
