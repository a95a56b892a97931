#pragma once
/// \file
/// The colour bar: a vertical strip of the colour map near the image's right edge, its top
/// labelled with the value at the top of the map and its bottom with the value at the bottom
/// (printf's %.4g, in the tiny font of render/font.cuh). Drawn over the image on the host.
#include <algorithm>
#include <cstdio>
#include <string>

#include "colour_map.cuh"
#include "font.cuh"
#include "image.cuh"

namespace sphere {

/// The share of the image's width, at its right, that the bar and its labels take (and that
/// frame_particles keeps free of particles, render/particles.cuh).
inline constexpr double colour_bar_share = 0.2;

/// A value as the bar's label.
inline std::string bar_label(double value)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", value);
    return text;
}

/// Black on a light background, white on a dark one.
inline rgb text_colour(rgb background)
{
    const int luma = (299 * background.r + 587 * background.g + 114 * background.b) / 1000;
    return luma >= 128 ? rgb{0, 0, 0} : rgb{255, 255, 255};
}

/// Draws the bar for values from `lo` (bottom) to `hi` (top) into `image`, whose background
/// colour is `background`. The bar spans the middle 80% of the height, 1/40 of the width wide,
/// 1/50 of the width from the right edge; images too small to hold it are left unchanged.
inline void draw_colour_bar(rgb_image& image, double lo, double hi, rgb background)
{
    const long w = long(image.width), h = long(image.height);
    const long margin = std::max(2L, w / 50), bar = std::max(3L, w / 40);
    const long x1 = w - margin, x0 = x1 - bar, top = h / 10, bottom = h - h / 10;
    if (x0 < 0 || bottom - top < 2) return;
    for (long y = top; y < bottom; ++y) {
        const vec3<double> c = colour_map(double(bottom - 1 - y) / double(bottom - 1 - top));
        for (long x = x0; x < x1; ++x) image.set(std::size_t(x), std::size_t(y), {to_byte(c.x), to_byte(c.y), to_byte(c.z)});
    }
    const std::string high = bar_label(hi), low = bar_label(lo);
    // The labels' scale: a 200th of the height, less where the wider label would not fit in
    // the rest of the bar's share of the width.
    const long room = long(colour_bar_share * double(w)) - (w - x0) - margin;
    const long widest = std::max(text_width(high, 1), text_width(low, 1));
    const long scale = std::max(1L, std::min(h / 200, widest > 0 ? room / widest : 1L));
    const rgb ink = text_colour(background);
    draw_text(image, x0 - margin - text_width(high, scale), top - 5 * scale / 2, high, scale, ink);
    draw_text(image, x0 - margin - text_width(low, scale), bottom - 5 * scale / 2, low, scale, ink);
}

} // namespace sphere
