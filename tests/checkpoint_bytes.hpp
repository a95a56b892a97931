#pragma once
// Checkpoint bytes rewritten as an older format (test_io, test_fluid_restart): what a file of
// that version holds, for the readers' backward-compatibility tests.
#include <sphere/io/checkpoint.cuh>

#include <cstddef>
#include <cstdint>
#include <string>

namespace sphere_test {

/// The bytes of a checkpoint as format version `version`, without `count` payload bytes from
/// `at` (the header's version and payload size and the checksum rewritten).
inline std::string as_version(std::string b, std::uint32_t version, std::size_t at, std::size_t count)
{
    b.erase(at, count);
    b.resize(b.size() - 8);
    b[8] = static_cast<char>(version);
    const std::uint64_t payload = b.size() - 24;
    for (int k = 0; k < 8; ++k) b[16 + k] = static_cast<char>((payload >> (8 * k)) & 0xffu);
    const std::uint64_t sum = sphere::detail::fnv1a64(b.data(), b.size());
    for (int k = 0; k < 8; ++k) b += static_cast<char>((sum >> (8 * k)) & 0xffu);
    return b;
}

} // namespace sphere_test
