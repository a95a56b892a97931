// Test helper `vti_writer_for_test DIR`: writes, into DIR/float and DIR/double, two .vti
// frames of known fluid fields (fluid_000000.vti at t = 0, fluid_000001.vti at t = 0.25 s)
// and fluid.pvd through sphere::vti_writer. tests/read_vti.py reads them with VTK's own
// vtkXMLImageDataReader and checks the grid and every value against the same formulas:
// a 3 x 2 x 4 grid over [-0.1, 0.2] x [0.2, 0.4] x [0.3, 1.1] m (cells 0.1 x 0.1 x 0.2 m), and
// for cell (i, j, k) in frame f
//   pressure      = 1000 k + 100 j + 10 i + 1.5 + f
//   velocity      = (i + 0.25, -j, 0.125 k - 1)
//   porosity      = 0.5 + 0.0625 i + 0.125 j + 0.03125 k
//   porosity_rate = -0.5 (i + 2 j + 4 k)
// (every value exact in float). The ghost entries hold -999, which must not appear.
// Exit status 0 on success, 1 on an error (message on stderr), 2 on bad usage.
#include <sphere/io/vti.cuh>

#include <exception>
#include <iostream>
#include <string>

namespace {

template <class Real>
void write_frames(const std::string& folder)
{
    sphere::world<Real> box;
    box.lo = {Real(-0.1), Real(0.2), Real(0.3)};
    box.hi = {Real(0.2), Real(0.4), Real(1.1)};
    sphere::vti_fields<Real> f;
    f.grid = sphere::fluid_grid<Real>::make(box, 3, 2, 4);
    const std::size_t n = f.grid.field_size();
    f.pressure.assign(n, Real(-999));
    f.velocity.assign(n, sphere::vec3<Real>{Real(-999), Real(-999), Real(-999)});
    f.porosity.assign(n, Real(-999));
    f.porosity_rate.assign(n, Real(-999));
    sphere::vti_writer out(folder);
    for (int frame = 0; frame < 2; ++frame) {
        for (int k = 0; k < 4; ++k)
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 3; ++i) {
                    const std::size_t c = f.grid.field_index(i, j, k);
                    f.pressure[c] = Real(1000 * k + 100 * j + 10 * i + 1.5 + frame);
                    f.velocity[c] = {Real(i + 0.25), Real(-j), Real(0.125 * k - 1)};
                    f.porosity[c] = Real(0.5 + 0.0625 * i + 0.125 * j + 0.03125 * k);
                    f.porosity_rate[c] = Real(-0.5 * (i + 2 * j + 4 * k));
                }
        out.write(f, 0.25 * frame);
    }
}

} // namespace

int main(int argc, char** argv)
{
    if (argc != 2) {
        std::cerr << "usage: vti_writer_for_test DIR\n";
        return 2;
    }
    try {
        const std::string dir = argv[1];
        write_frames<float>(dir + "/float");
        write_frames<double>(dir + "/double");
    } catch (const std::exception& ex) {
        std::cerr << ex.what() << '\n';
        return 1;
    }
    return 0;
}
