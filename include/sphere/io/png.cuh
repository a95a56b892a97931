#pragma once
/// \file
/// `write_png(path, image, text)`: an RGB image (render/image.cuh) as an 8-bit PNG file through
/// libpng, with text chunks (key and value), written atomically (io/atomic_file.cuh). Host-only;
/// a program that includes it links libpng (CMake: the target sphere::png).
#include <png.h>

#include <csetjmp>
#include <cstddef>
#include <cstring>
#include <new>
#include <string>
#include <utility>
#include <vector>

#include "../core/error.cuh"
#include "../render/image.cuh"
#include "atomic_file.cuh"

namespace sphere {

namespace detail {
/// The encoder's output and the message of a libpng error.
struct png_sink {
    std::string bytes;
    char message[256] = "";
};

inline void png_append(png_structp png, png_bytep data, std::size_t size)
{
    png_sink* sink = static_cast<png_sink*>(png_get_io_ptr(png));
    bool grown = true;
    try {
        sink->bytes.append(reinterpret_cast<const char*>(data), size);
    } catch (const std::bad_alloc&) {
        grown = false;
    }
    if (!grown) png_error(png, "out of memory");
}

inline void png_flush_nothing(png_structp) {}

/// libpng's error handler: keeps the message and returns to run_libpng's setjmp.
inline void png_failed(png_structp png, png_const_charp message)
{
    png_sink* sink = static_cast<png_sink*>(png_get_error_ptr(png));
    std::strncpy(sink->message, message, sizeof sink->message - 1);
    png_longjmp(png, 1);
}

inline void png_warned(png_structp, png_const_charp) {}

/// The encoding between libpng's setjmp and its longjmp: only libpng calls and no object with a
/// destructor, which a longjmp would skip. True on success.
inline bool run_libpng(png_sink& sink, png_uint_32 width, png_uint_32 height, png_bytep* rows, png_text* text, int texts)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &sink, png_failed, png_warned);
    if (!png) return false;
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return false;
    }
    png_set_write_fn(png, &sink, png_append, png_flush_nothing);
    png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    if (texts > 0) png_set_text(png, info, text, texts);
    png_set_rows(png, info, rows);
    png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
}
} // namespace detail

/// The PNG file's bytes of `image`, with tEXt chunks `text` (keys of 1 to 79 Latin-1
/// characters). Throws sphere::error naming `what` (the file) for an empty image or a libpng
/// failure.
inline std::string encode_png(const rgb_image& image, const std::vector<std::pair<std::string, std::string>>& text,
                              const std::string& what)
{
    if (image.width == 0 || image.height == 0)
        detail::fail("cannot write '", what, "': the image is ", image.width, " x ", image.height, " pixels");
    if (image.bytes.size() != image.width * image.height * 3)
        detail::fail("cannot write '", what, "': ", image.bytes.size(), " bytes for ", image.width, " x ",
                     image.height, " RGB pixels");
    for (const auto& [key, value] : text)
        if (key.empty() || key.size() > 79)
            detail::fail("cannot write '", what, "': the PNG text key '", key, "' must have 1 to 79 characters");
    std::vector<png_bytep> rows(image.height);
    for (std::size_t y = 0; y < image.height; ++y)
        rows[y] = const_cast<png_bytep>(image.bytes.data() + 3 * image.width * y);
    std::vector<png_text> chunks(text.size());
    for (std::size_t k = 0; k < text.size(); ++k) {
        chunks[k].compression = PNG_TEXT_COMPRESSION_NONE;
        chunks[k].key = const_cast<png_charp>(text[k].first.c_str());
        chunks[k].text = const_cast<png_charp>(text[k].second.c_str());
        chunks[k].text_length = text[k].second.size();
    }
    detail::png_sink sink;
    if (!detail::run_libpng(sink, png_uint_32(image.width), png_uint_32(image.height), rows.data(), chunks.data(),
                            int(chunks.size())))
        detail::fail("cannot write '", what, "': libpng failed: ", sink.message[0] ? sink.message : "cannot start");
    return std::move(sink.bytes);
}

/// Writes `image` to `path` as a PNG file with tEXt chunks `text`, atomically: the previous
/// file stays whole until the new one is complete. Throws sphere::error naming `path` (an empty
/// image, a missing folder, a full disk: the messages of io/atomic_file.cuh).
inline void write_png(const std::string& path, const rgb_image& image,
                      const std::vector<std::pair<std::string, std::string>>& text = {})
{
    if (path.empty()) detail::fail("cannot write a PNG file with an empty path");
    write_file_atomically(path, encode_png(image, text, path));
}

} // namespace sphere
