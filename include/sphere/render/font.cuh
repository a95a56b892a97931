#pragma once
/// \file
/// A tiny bitmap font for the colour bar's numbers: the digits, '.', '-', '+' and 'e' (what
/// printf's %g writes) as 3 x 5 pixel glyphs, drawn at a whole-number scale into an image
/// (host code; pixels outside the image are left out).
#include <cstddef>
#include <cstdint>
#include <string>

#include "image.cuh"

namespace sphere {

/// The glyph of c: 15 bits, the top row in the highest three, each row's left pixel its
/// highest bit; 0 (blank) for a character the font lacks.
inline std::uint16_t glyph(char c)
{
    // Written row by row, top first: 0b111'101'101'101'111 is a zero.
    switch (c) {
    case '0': return 0b111'101'101'101'111;
    case '1': return 0b010'110'010'010'111;
    case '2': return 0b111'001'111'100'111;
    case '3': return 0b111'001'111'001'111;
    case '4': return 0b101'101'111'001'001;
    case '5': return 0b111'100'111'001'111;
    case '6': return 0b111'100'111'101'111;
    case '7': return 0b111'001'001'001'001;
    case '8': return 0b111'101'111'101'111;
    case '9': return 0b111'101'111'001'111;
    case '.': return 0b000'000'000'000'010;
    case '-': return 0b000'000'111'000'000;
    case '+': return 0b000'010'111'010'000;
    case 'e': return 0b000'111'111'100'111;
    default: return 0;
    }
}

/// Width in pixels of `text` at `scale`: 3 pixels a glyph and 1 between glyphs, times scale.
inline long text_width(const std::string& text, long scale)
{
    return text.empty() ? 0 : (4 * long(text.size()) - 1) * scale;
}

/// Draws `text` with its top-left corner at (x, y) (which may lie outside the image).
inline void draw_text(rgb_image& image, long x, long y, const std::string& text, long scale, rgb colour)
{
    for (std::size_t k = 0; k < text.size(); ++k) {
        const std::uint16_t bits = glyph(text[k]);
        for (long row = 0; row < 5 * scale; ++row)
            for (long col = 0; col < 3 * scale; ++col) {
                const long px = x + 4 * scale * long(k) + col, py = y + row;
                const bool on = (bits >> (14 - 3 * (row / scale) - col / scale)) & 1u;
                if (on && px >= 0 && py >= 0 && px < long(image.width) && py < long(image.height))
                    image.set(std::size_t(px), std::size_t(py), colour);
            }
    }
}

} // namespace sphere
