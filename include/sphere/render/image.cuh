#pragma once
/// \file
/// `rgb_image`: an 8-bit RGB picture in host memory, rows from the top, three bytes a pixel;
/// what the ray tracer returns (render/trace.cuh) and io/png.cuh writes.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sphere {

/// One pixel's colour, 0-255 per channel.
struct rgb {
    std::uint8_t r, g, b;
};

inline bool operator==(const rgb& a, const rgb& b) { return a.r == b.r && a.g == b.g && a.b == b.b; }
inline bool operator!=(const rgb& a, const rgb& b) { return !(a == b); }

struct rgb_image {
    std::size_t width = 0, height = 0;
    std::vector<std::uint8_t> bytes; ///< width * height * 3: row y, column x at 3 (y width + x)

    rgb at(std::size_t x, std::size_t y) const
    {
        const std::size_t k = 3 * (y * width + x);
        return {bytes[k], bytes[k + 1], bytes[k + 2]};
    }
    void set(std::size_t x, std::size_t y, rgb c)
    {
        const std::size_t k = 3 * (y * width + x);
        bytes[k] = c.r;
        bytes[k + 1] = c.g;
        bytes[k + 2] = c.b;
    }
};

} // namespace sphere
