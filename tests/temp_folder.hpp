#pragma once
// Scratch files for the output tests (test_io, test_vti): a temporary folder removed when the
// test leaves, and a file's bytes.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

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

} // namespace sphere_test
