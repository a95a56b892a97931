// Test helper `png_writer_for_test DIR`: renders three spheres (speeds 0, 5 and 10 m/s, in float)
// with sphere::render_png into DIR/frame.png, coloured by speed from 0 to 12 m/s on a 120 x 90
// pixel orthographic view, and writes the same picture's raw RGB bytes (render_particles, rows
// from the top) into DIR/frame.rgb. tests/png_read.py reads the PNG file with Pillow and
// compares. Exit status 0 on success, 1 on an error (message on stderr), 2 on bad usage.
#include <sphere/io/atomic_file.cuh>
#include <sphere/io/render_png.cuh>

#include <exception>
#include <iostream>
#include <string>

int main(int argc, char** argv)
{
    if (argc != 2) {
        std::cerr << "usage: png_writer_for_test DIR\n";
        return 2;
    }
    try {
        const std::string dir = argv[1];
        sphere::particle_snapshot<float> s;
        s.x = {{-2, 1, 0, 1.5f}, {2.2f, -1.3f, 0.5f, 1.2f}, {0.3f, 2.8f, -1, 0.7f}};
        s.v_sync = {{0, 0, 0}, {3, 4, 0}, {0, 6, 8}};
        s.omega_sync = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
        s.pressure = {0, 0, 0};
        sphere::render_options options;
        sphere::camera view;
        view.eye = {0, 0, 10};
        view.up = {0, 1, 0};
        view.width = 120;
        view.height = 90;
        view.view_width = 10;
        options.view = view;
        options.max_val = 12;
        sphere::render_png(dir + "/frame.png", s, sphere::render_method::vel, options);
        const sphere::rgb_image image = sphere::render_particles<sphere::host>(s, sphere::render_method::vel, options);
        sphere::write_file_atomically(dir + "/frame.rgb", reinterpret_cast<const char*>(image.bytes.data()),
                                      image.bytes.size());
    } catch (const std::exception& e) {
        std::cerr << e.what() << "\n";
        return 1;
    }
    return 0;
}
