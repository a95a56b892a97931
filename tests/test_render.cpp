// The ray tracer (include/sphere/render/, io/png.cuh, io/render_png.cuh; docs/render.md), host
// backend, float and double: (a) the drawn pixels of a scene seen down an axis are the pixels
// whose centres lie inside the spheres' projected circles, up to pixels on the circles' edges;
// (b) a sphere's centre pixel has the colour map's colour of its value times the shading of a
// surface facing the viewer; (c) the nearer sphere hides the farther; (d) lower_cutoff removes
// a sphere; (e) a perspective camera draws a sphere on its axis as the circle of its angular
// radius; (f) the tiles miss no sphere (every pixel as the nearest hit over all spheres);
// (g) the colour bar and the methods' values; (h) PNG files read back by libpng with their
// size, pixels and text; (i) bad input raises clear errors.
// tests/png_read.py reads the PNG files of tests/png_writer_main.cpp with Pillow.
#include <catch2/catch.hpp>

#include "temp_folder.hpp"

#include <sphere/io/render_png.cuh>

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_render {

namespace {

using sphere::rgb;

/// An orthographic camera looking down -z at the origin, y up: 200 x 200 pixels of 0.05 m,
/// so pixel (x, y) has its centre at ((x - 99.5) 0.05, (99.5 - y) 0.05).
sphere::camera down_z()
{
    sphere::camera c;
    c.eye = {0, 0, 10};
    c.look_at = {0, 0, 0};
    c.up = {0, 1, 0};
    c.width = c.height = 200;
    c.view_width = 10;
    return c;
}

double pixel_x(std::size_t x) { return (double(x) - 99.5) * 0.05; }
double pixel_y(std::size_t y) { return (99.5 - double(y)) * 0.05; }

/// Three spheres, their centres at pixel centres: A's at pixel (59, 79), B's at (144, 125),
/// C's at (105, 43).
template <class Real>
sphere::sphere_scene<Real> three_spheres()
{
    sphere::sphere_scene<Real> s;
    s.spheres = {{Real(-2.025), Real(1.025), Real(0), Real(1.5)},
                 {Real(2.225), Real(-1.275), Real(0.5), Real(1.2)},
                 {Real(0.275), Real(2.825), Real(-1), Real(0.7)}};
    s.values = {Real(100), Real(500), Real(900)};
    return s;
}

/// The expected colour of a surface of value `value` whose shading factor is `shade`.
rgb mapped(double value, const sphere::render_style& style, double shade)
{
    const sphere::vec3<double> c = sphere::colour_map((value - style.lower_cutoff) / (style.max_val - style.lower_cutoff));
    return {sphere::to_byte(c.x * shade), sphere::to_byte(c.y * shade), sphere::to_byte(c.z * shade)};
}

/// The shading factor of a surface facing the viewer, for the style's light.
double facing_viewer(const sphere::render_style& style)
{
    return style.ambient + (1 - style.ambient) * style.light.z / sphere::norm(style.light);
}

void require_close(rgb got, rgb expected)
{
    INFO("got (" << int(got.r) << ", " << int(got.g) << ", " << int(got.b) << "), expected (" << int(expected.r)
                 << ", " << int(expected.g) << ", " << int(expected.b) << ")");
    REQUIRE(std::abs(int(got.r) - int(expected.r)) <= 1);
    REQUIRE(std::abs(int(got.g) - int(expected.g)) <= 1);
    REQUIRE(std::abs(int(got.b) - int(expected.b)) <= 1);
}

template <class Real>
sphere::particle_snapshot<Real> snapshot_of(const sphere::sphere_scene<Real>& scene)
{
    sphere::particle_snapshot<Real> s;
    s.x = scene.spheres;
    const std::size_t n = s.x.size();
    s.v_sync.resize(n);
    s.omega_sync.resize(n);
    s.pressure.resize(n);
    s.displacement.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        s.displacement[i] = {Real(0.5 * i), Real(7), Real(-1)}; // x: 0.5 i
        s.v_sync[i] = {Real(3 * i), Real(4 * i), Real(0)};  // |v| = 5 i
        s.omega_sync[i] = {Real(0), Real(i), Real(0)};    // |omega| = i
        s.pressure[i] = Real(100 * (i + 1));
    }
    return s;
}

/// The file's bytes decoded by libpng's simplified API as 8-bit RGB.
sphere::rgb_image read_png(const std::string& path)
{
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    REQUIRE(png_image_begin_read_from_file(&png, path.c_str()) != 0);
    png.format = PNG_FORMAT_RGB;
    sphere::rgb_image image;
    image.width = png.width;
    image.height = png.height;
    image.bytes.resize(PNG_IMAGE_SIZE(png));
    REQUIRE(png_image_finish_read(&png, nullptr, image.bytes.data(), 0, nullptr) != 0);
    return image;
}

} // namespace

TEMPLATE_TEST_CASE("the drawn pixels are the spheres' projected circles", "[render]", float, double)
{
    using Real = TestType;
    const sphere::sphere_scene<Real> scene = three_spheres<Real>();
    const sphere::render_style style;
    const sphere::rgb_image image = sphere::render_scene<sphere::host>(scene, down_z(), style);
    REQUIRE(image.width == 200);
    REQUIRE(image.height == 200);
    REQUIRE(image.bytes.size() == 200 * 200 * 3);

    std::size_t silhouette = 0, mismatches = 0;
    for (std::size_t y = 0; y < 200; ++y)
        for (std::size_t x = 0; x < 200; ++x) {
            bool inside = false;
            double edge = 1e300; // distance of the pixel centre from the nearest circle
            for (const auto& s : scene.spheres) {
                const double d = std::hypot(pixel_x(x) - double(s.x), pixel_y(y) - double(s.y));
                inside = inside || d < double(s.w);
                edge = std::min(edge, std::abs(d - double(s.w)));
            }
            silhouette += inside;
            if (inside != (image.at(x, y) != style.background)) {
                ++mismatches;
                INFO("pixel (" << x << ", " << y << ") " << (inside ? "inside" : "outside") << ", " << edge
                               << " m from a circle");
                REQUIRE(edge < 0.05);
            }
        }
    REQUIRE(silhouette > 5000); // pi (1.5^2 + 1.2^2 + 0.7^2) / 0.05^2 = 5240 pixels
    REQUIRE(double(mismatches) < 0.02 * double(silhouette));
}

TEMPLATE_TEST_CASE("a sphere's centre pixel has its value's colour, shaded as a surface facing the viewer", "[render]",
                   float, double)
{
    using Real = TestType;
    const sphere::sphere_scene<Real> scene = three_spheres<Real>();
    sphere::render_style style;
    SECTION("the default light, above and behind the viewer")
    {
        const sphere::rgb_image image = sphere::render_scene<sphere::host>(scene, down_z(), style);
        require_close(image.at(59, 79), mapped(100, style, facing_viewer(style)));
        require_close(image.at(144, 125), mapped(500, style, facing_viewer(style)));
        require_close(image.at(105, 43), mapped(900, style, facing_viewer(style)));
        require_close(image.at(0, 0), style.background);
    }
    SECTION("a light behind the viewer: the full colour; lit from the side: the ambient part")
    {
        style.light = {0, 0, 1};
        require_close(sphere::render_scene<sphere::host>(scene, down_z(), style).at(59, 79), mapped(100, style, 1.0));
        style.light = {1, 0, 0};
        require_close(sphere::render_scene<sphere::host>(scene, down_z(), style).at(59, 79),
                      mapped(100, style, style.ambient));
    }
    SECTION("values beyond max_val take the top colour; the range runs from lower_cutoff")
    {
        style.lower_cutoff = 50;
        style.max_val = 450;
        style.light = {0, 0, 1};
        const sphere::rgb_image image = sphere::render_scene<sphere::host>(scene, down_z(), style);
        require_close(image.at(59, 79), mapped(100, style, 1.0));
        require_close(image.at(144, 125), rgb{128, 0, 0});
    }
    SECTION("a scene without values is drawn in one colour")
    {
        sphere::sphere_scene<Real> plain = scene;
        plain.values.clear();
        style.light = {0, 0, 1};
        style.colour = {10, 200, 30};
        const sphere::rgb_image image = sphere::render_scene<sphere::host>(plain, down_z(), style);
        require_close(image.at(59, 79), style.colour);
        require_close(image.at(105, 43), style.colour);
    }
}

TEMPLATE_TEST_CASE("the nearer sphere hides the farther one", "[render]", float, double)
{
    using Real = TestType;
    sphere::render_style style;
    style.light = {0, 0, 1};
    // Two spheres overlapping in projection; pixel (99, 99) lies on the axis of both. Whichever
    // is nearer the eye (at z = 10) is seen there, in either order of the spheres.
    for (const bool first_near : {true, false}) {
        sphere::sphere_scene<Real> scene;
        const sphere::vec4<Real> near_one{Real(0.025), Real(0.025), Real(2), Real(1)};
        const sphere::vec4<Real> far_one{Real(0.525), Real(0.025), Real(-2), Real(1.5)};
        scene.spheres = first_near ? std::vector<sphere::vec4<Real>>{near_one, far_one}
                                   : std::vector<sphere::vec4<Real>>{far_one, near_one};
        scene.values = first_near ? std::vector<Real>{Real(900), Real(100)} : std::vector<Real>{Real(100), Real(900)};
        const sphere::rgb_image image = sphere::render_scene<sphere::host>(scene, down_z(), style);
        INFO("nearer sphere first: " << first_near);
        require_close(image.at(100, 99), mapped(900, style, 1.0));
        // Outside the nearer disc but inside the farther one: the farther sphere.
        REQUIRE(image.at(125, 99) != style.background);
        REQUIRE(image.at(125, 99) != image.at(100, 99));
    }
}

TEMPLATE_TEST_CASE("lower_cutoff removes the spheres of smaller values", "[render]", float, double)
{
    using Real = TestType;
    sphere::sphere_scene<Real> scene = three_spheres<Real>();
    // D, behind A (value 100) and larger, shows where A was once A is cut off.
    scene.spheres.push_back({Real(-2.025), Real(1.025), Real(-3), Real(1.6)});
    scene.values.push_back(Real(300));
    sphere::render_style style;
    style.light = {0, 0, 1};
    require_close(sphere::render_scene<sphere::host>(scene, down_z(), style).at(59, 79), mapped(100, style, 1.0));
    style.lower_cutoff = 200;
    const sphere::rgb_image image = sphere::render_scene<sphere::host>(scene, down_z(), style);
    require_close(image.at(59, 79), mapped(300, style, 1.0));
    scene.values.back() = Real(150);
    const sphere::rgb_image both_gone = sphere::render_scene<sphere::host>(scene, down_z(), style);
    require_close(both_gone.at(59, 79), style.background);
    require_close(both_gone.at(144, 125), mapped(500, style, 1.0));
    scene.values[1] = std::numeric_limits<Real>::quiet_NaN();
    require_close(sphere::render_scene<sphere::host>(scene, down_z(), style).at(144, 125), style.background);
}

TEMPLATE_TEST_CASE("a perspective camera draws a sphere on its axis as the circle of its angular radius", "[render]",
                   float, double)
{
    using Real = TestType;
    sphere::camera c = down_z();
    c.kind = sphere::projection::perspective;
    c.eye = {0, 0, 4};
    c.view_width = 4; // at the look-at distance 4: a pixel is 0.02 m there
    sphere::sphere_scene<Real> scene;
    scene.spheres = {{Real(0), Real(0), Real(-2), Real(1)}}; // 6 m from the eye
    const sphere::render_style style;
    const sphere::rgb_image image = sphere::render_scene<sphere::host>(scene, c, style);
    const double half_angle = std::asin(1.0 / 6.0);
    std::size_t inside_count = 0, mismatches = 0;
    for (std::size_t y = 0; y < 200; ++y)
        for (std::size_t x = 0; x < 200; ++x) {
            const double u = (double(x) - 99.5) * 0.02, v = (99.5 - double(y)) * 0.02;
            const double angle = std::atan(std::hypot(u, v) / 4.0);
            const bool inside = angle < half_angle;
            inside_count += inside;
            if (inside != (image.at(x, y) != style.background)) {
                ++mismatches;
                REQUIRE(std::abs(std::hypot(u, v) - 4.0 * std::tan(half_angle)) < 0.02);
            }
        }
    // The circle's radius is 4 tan(asin(1/6)) = 0.676 m: 33.8 pixels.
    REQUIRE(inside_count > 3500);
    REQUIRE(double(mismatches) < 0.02 * double(inside_count));
}

TEMPLATE_TEST_CASE("the tiles miss no sphere: every pixel shows the nearest hit over all spheres", "[render]", float,
                   double)
{
    using Real = TestType;
    std::mt19937 random(7);
    std::uniform_real_distribution<double> position(-4, 4), radius(0.05, 0.6);
    sphere::sphere_scene<Real> scene;
    for (int i = 0; i < 400; ++i) {
        scene.spheres.push_back({Real(position(random)), Real(position(random)), Real(position(random)), Real(radius(random))});
        scene.values.push_back(Real(i * 2.5));
    }
    scene.spheres.push_back({Real(0), Real(0), Real(-30), Real(25)}); // larger than the view
    scene.values.push_back(Real(999));
    sphere::render_style style;
    style.background = {1, 2, 3};
    for (const auto kind : {sphere::projection::orthographic, sphere::projection::perspective}) {
        sphere::camera c = down_z();
        c.kind = kind;
        c.eye = {1, -2, 12};
        c.look_at = {0.5, 0.2, 0};
        c.up = {0.3, 1, 0};
        c.width = 230;
        c.height = 170;
        const sphere::rgb_image image = sphere::render_scene<sphere::host>(scene, c, style);
        const auto frame = sphere::camera_frame<Real>::of(c);
        const Real miss = std::numeric_limits<Real>::infinity();
        std::size_t hits = 0;
        for (unsigned y = 0; y < c.height; ++y)
            for (unsigned x = 0; x < c.width; ++x) {
                const sphere::ray<Real> r = frame.through(x, y);
                Real nearest = miss;
                for (const auto& s : scene.spheres) nearest = std::min(nearest, sphere::entry_distance(r, s, miss));
                INFO("pixel (" << x << ", " << y << ")");
                REQUIRE((nearest < miss) == (image.at(x, y) != style.background));
                hits += nearest < miss;
            }
        REQUIRE(hits > 0);
    }
}

TEMPLATE_TEST_CASE("render_particles shows the methods' values and draws the colour bar", "[render]", float, double)
{
    using Real = TestType;
    const sphere::particle_snapshot<Real> s = snapshot_of(three_spheres<Real>());
    REQUIRE(sphere::particle_values(s, sphere::render_method::normal).empty());
    REQUIRE(sphere::particle_values(s, sphere::render_method::pres) == std::vector<Real>{100, 200, 300});
    REQUIRE(sphere::particle_values(s, sphere::render_method::vel) == std::vector<Real>{0, 5, 10});
    REQUIRE(sphere::particle_values(s, sphere::render_method::angvel) == std::vector<Real>{0, 1, 2});
    REQUIRE(sphere::particle_values(s, sphere::render_method::xdisp) == std::vector<Real>{0, 0.5, 1});
    REQUIRE(sphere::render_method_named("angvel") == sphere::render_method::angvel);
    REQUIRE(sphere::render_method_named("xdisp") == sphere::render_method::xdisp);
    REQUIRE_THROWS_WITH(sphere::render_method_named("ydisp"), Catch::Contains("unknown method 'ydisp'"));

    sphere::render_options options;
    options.view = down_z();
    options.max_val = 400;
    options.light = {0, 0, 1};
    const sphere::rgb_image with_bar = sphere::render_particles<sphere::host>(s, sphere::render_method::pres, options);
    require_close(with_bar.at(144, 125), mapped(200, options, 1.0));
    // The bar: 1/40 of the width wide (5 pixels), 1/50 from the right edge (4 pixels), over the
    // middle 80% of the height: its top row is the map's top, its bottom row the map's bottom.
    require_close(with_bar.at(193, 20), mapped(400, options, 1.0));
    require_close(with_bar.at(193, 179), mapped(0, options, 1.0));
    require_close(with_bar.at(193, 10), options.background);
    // The labels ("400", "0") are black pixels left of the bar.
    std::size_t ink = 0;
    for (std::size_t y = 0; y < 200; ++y)
        for (std::size_t x = 150; x < 190; ++x) ink += with_bar.at(x, y) == rgb{0, 0, 0};
    REQUIRE(ink > 10);

    options.colour_bar = false;
    const sphere::rgb_image without = sphere::render_particles<sphere::host>(s, sphere::render_method::pres, options);
    require_close(without.at(193, 20), options.background);
    // The normal method draws no bar; without a camera, the particles fill the picture's middle.
    options.colour_bar = true;
    options.view.reset();
    const sphere::rgb_image framed = sphere::render_particles<sphere::host>(s, sphere::render_method::normal, options);
    REQUIRE(framed.width == 800);
    REQUIRE(framed.height == 800);
    require_close(framed.at(400, 400), options.background); // between the spheres seen along y
    std::size_t drawn = 0;
    for (std::size_t y = 0; y < 800; ++y)
        for (std::size_t x = 0; x < 800; ++x) drawn += framed.at(x, y) != options.background;
    REQUIRE(drawn > 800 * 800 / 10);
    REQUIRE(framed.at(5, 5) == options.background);
}

TEMPLATE_TEST_CASE("render_png writes a PNG file that libpng reads back", "[render][io]", float, double)
{
    using Real = TestType;
    sphere_test::temp_folder folder("sphere_render");
    const sphere::particle_snapshot<Real> s = snapshot_of(three_spheres<Real>());
    sphere::render_options options;
    options.view = down_z();
    options.view->width = 120; // not square, not a multiple of the tiles
    options.max_val = 12;
    const std::string path = folder / "vel.png";
    sphere::render_png(path, s, sphere::render_method::vel, options);
    const sphere::rgb_image back = read_png(path);
    const sphere::rgb_image expected = sphere::render_particles<sphere::host>(s, sphere::render_method::vel, options);
    REQUIRE(back.width == 120);
    REQUIRE(back.height == 200);
    REQUIRE(back.bytes == expected.bytes);
    const std::string bytes = sphere_test::read_bytes(path);
    REQUIRE(bytes.find(std::string("tEXtsphere field\0vel", 20)) != std::string::npos);
    REQUIRE(bytes.find(std::string("tEXtsphere max_val\0" "12", 21)) != std::string::npos);
    REQUIRE(!std::filesystem::exists(path + ".tmp"));

    // Any per-particle values: named in the file.
    sphere::render_png(path, s, std::vector<Real>{1, 2, 3}, options, "xdisp");
    REQUIRE(sphere_test::read_bytes(path).find(std::string("tEXtsphere field\0xdisp", 22)) != std::string::npos);
    REQUIRE(read_png(path).width == 120);
}

TEST_CASE("bad input to the renderer raises clear errors", "[render][errors]")
{
    sphere_test::temp_folder folder("sphere_render");
    const sphere::sphere_scene<double> scene = three_spheres<double>();
    const sphere::render_style style;
    sphere::camera c = down_z();
    c.width = 0;
    REQUIRE_THROWS_WITH(sphere::render_scene<sphere::host>(scene, c, style),
                        Catch::Contains("render: camera image size 0 x 200 px"));
    c = down_z();
    c.up = {0, 0, 2};
    REQUIRE_THROWS_WITH(sphere::render_scene<sphere::host>(scene, c, style), Catch::Contains("parallel to the view"));
    c = down_z();
    c.view_width = -1;
    REQUIRE_THROWS_WITH(sphere::render_scene<sphere::host>(scene, c, style), Catch::Contains("view_width = -1"));
    REQUIRE_THROWS_WITH(sphere::render_scene<sphere::host>(sphere::sphere_scene<double>{}, down_z(), style),
                        Catch::Contains("render: the scene has no spheres"));
    sphere::sphere_scene<double> bad = scene;
    bad.spheres[2].w = 0;
    REQUIRE_THROWS_WITH(sphere::render_scene<sphere::host>(bad, down_z(), style),
                        Catch::Contains("render: sphere 2: radius = 0 must be positive"));
    bad = scene;
    bad.values.pop_back();
    REQUIRE_THROWS_WITH(sphere::render_scene<sphere::host>(bad, down_z(), style),
                        Catch::Contains("2 values for 3 spheres"));
    sphere::render_style flat;
    flat.max_val = flat.lower_cutoff;
    REQUIRE_THROWS_WITH(sphere::render_scene<sphere::host>(scene, down_z(), flat),
                        Catch::Contains("max_val = 0 must be finite and above lower_cutoff = 0"));

    const sphere::particle_snapshot<double> s = snapshot_of(scene);
    sphere::render_options options;
    options.view = down_z();
    const std::string missing = folder / "no/such/folder/frame.png";
    REQUIRE_THROWS_WITH(sphere::render_png(missing, s, sphere::render_method::pres, options),
                        Catch::Contains("cannot write '" + missing + "'") && Catch::Contains("No such file or directory"));
    REQUIRE_THROWS_WITH(sphere::render_png(folder / "empty.png", sphere::particle_snapshot<double>{},
                                           sphere::render_method::pres, options),
                        Catch::Contains("render: the snapshot has no particles"));
    REQUIRE_THROWS_WITH(sphere::render_png(folder / "short.png", s, std::vector<double>{1, 2}, options),
                        Catch::Contains("render: 2 values for 3 particles"));
    REQUIRE_THROWS_WITH(sphere::frame_particles(s, 100, 100, 1.0), Catch::Contains("keeps 1 of the width free"));
    sphere::particle_snapshot<double> no_audit = s;
    no_audit.pressure.clear();
    REQUIRE_THROWS_WITH(sphere::render_png(folder / "pres.png", no_audit, sphere::render_method::pres, options),
                        Catch::Contains("render: the snapshot holds 0 values of pres for 3 particles"));
    REQUIRE_THROWS_WITH(sphere::write_png(folder / "zero.png", sphere::rgb_image{}),
                        Catch::Contains("cannot write '" + folder / "zero.png" + "': the image is 0 x 0 pixels"));
    REQUIRE(!std::filesystem::exists(folder / "zero.png"));
}

} // namespace test_render
