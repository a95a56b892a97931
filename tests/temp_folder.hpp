#pragma once
// Scratch files for the output tests (test_io, test_vti, test_fluid_restart): a temporary
// folder removed when the test leaves, a file's bytes read and written, and bytewise equality.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

namespace sphere_test {

/// A fresh folder under the system's temporary folder (named after `prefix`), removed when
/// the test leaves.
struct temp_folder {
    std::string path;
    explicit temp_folder(const std::string& prefix = "sphere_test")
    {
        std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
        REQUIRE(::mkdtemp(&pattern[0]) != nullptr);
        path = pattern;
    }
    ~temp_folder()
    {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    temp_folder(const temp_folder&) = delete;
    temp_folder& operator=(const temp_folder&) = delete;
    std::string operator/(const std::string& name) const { return path + "/" + name; }
};

/// The whole content of the file at `path` (empty when it cannot be read).
inline std::string read_bytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// Writes `bytes` to the file at `path`, replacing it.
inline void write_bytes(const std::string& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// Bytewise equality of two values without padding (scalars, vec3, vec4).
template <class T>
bool same_bits(const T& a, const T& b)
{
    return std::memcmp(&a, &b, sizeof(T)) == 0;
}

/// Bytewise equality of two arrays of padding-free values.
template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b)
{
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

} // namespace sphere_test
