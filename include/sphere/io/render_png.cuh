#pragma once
/// \file
/// `render_png(path, snapshot, field, options)`: a picture of the particles (render/particles.cuh)
/// written as a PNG file (io/png.cuh), as the original sphere's `render(method, max_val,
/// lower_cutoff)`. The file's text chunks name the field and the colour bar's range.
#include <string>
#include <utility>
#include <vector>

#include "../core/error.cuh"
#include "../exec/policy.cuh"
#include "../particles/state.cuh"
#include "../render/fields.cuh"
#include "../render/particles.cuh"
#include "png.cuh"

namespace sphere {

/// Writes the snapshot's particles coloured by `values` (one per particle, called `field` in
/// the file's text; empty: all in options.colour) to the PNG file `path`, rendered by Policy's
/// kernels (host by default). Throws sphere::error for bad options or values, or when the file
/// cannot be written.
template <class Policy = host, class Real>
void render_png(const std::string& path, const particle_snapshot<Real>& s, const std::vector<Real>& values,
                const render_options& options = {}, const std::string& field = "values")
{
    const rgb_image image = render_particles<Policy>(s, values, options);
    std::vector<std::pair<std::string, std::string>> text{{"Software", "sphere"}, {"sphere field", field}};
    if (!values.empty()) {
        text.push_back({"sphere lower_cutoff", detail::text(options.lower_cutoff)});
        text.push_back({"sphere max_val", detail::text(options.max_val)});
    }
    write_png(path, image, text);
}

/// Writes the snapshot's particles as method m shows them (render/fields.cuh: normal, pres,
/// vel, angvel, xdisp) to the PNG file `path`.
template <class Policy = host, class Real>
void render_png(const std::string& path, const particle_snapshot<Real>& s, render_method m, const render_options& options = {})
{
    render_png<Policy>(path, s, particle_values(s, m), options, method_name(m));
}

} // namespace sphere
