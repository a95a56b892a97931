// Instantiates every kernel of the pore fluid for sphere::cuda in float and double: the
// porosity estimator, the three Poisson solvers, the Navier-Stokes solver with each, and the
// coupling with each drag law (and once with velocity Verlet, whose coupled step predicts its
// next drift) with its snapshot and restore, and the Darcy model with CG and MG-PCG (the
// variable-coefficient operator), so that CI proves the fluid's CUDA backend compiles and links.
// It is built, not run: build machines have no GPU.
#include <sphere/dem.cuh>
#include <sphere/fluid.cuh>

#include <cstdio>
#include <vector>

namespace {

template <class Real, class Drag, class Poisson, class Integrator = sphere::integrate::semi_implicit_euler>
double exercise()
{
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(0.02), Real(0.02), Real(0.2)};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.contact.k_n = s.contact.k_t = Real(100);
    s.wall = s.contact;
    s.gravity = {0, 0, Real(-9.81)};
    std::vector<sphere::particle<Real>> particles(1);
    particles[0].position = {Real(0.0075), Real(0.0075), Real(0.15)};
    particles[0].radius = Real(5e-4);
    particles[0].density = Real(2600);
    sphere::simulation<Real, sphere::cuda, sphere::contact::linear<>, Integrator> sim(s, particles);
    sphere::fluid_params<Real> prm;
    prm.gravity = s.gravity;
    prm.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    sphere::fluid_coupling<Real, sphere::cuda, Drag, Poisson> coupled(sphere::fluid_grid<Real>::make(s.box, 4, 4, 40),
                                                                      prm);
    coupled.step(sim);
    coupled.restore(coupled.snapshot()); // a checkpoint's round trip (fluid/snapshot.cuh)
    const auto m = coupled.fluid().momentum();
    return m.z + double(coupled.fluid().pressure()[0]) + double(coupled.fluid().cell_velocity()[0].z);
}

template <class Real, class Poisson>
double exercise_darcy()
{
    sphere::settings<Real> s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(0.004), Real(0.004), Real(0.02)};
    s.box.axis[0] = s.box.axis[1] = sphere::boundary::periodic;
    s.contact.k_n = s.contact.k_t = Real(100);
    s.wall = s.contact;
    std::vector<sphere::particle<Real>> particles(1);
    particles[0].position = {Real(0.002), Real(0.002), Real(0.005)};
    particles[0].radius = Real(5e-4);
    particles[0].density = Real(2600);
    sphere::simulation<Real, sphere::cuda> sim(s, particles);
    sphere::darcy_params<Real> prm;
    prm.permeability_prefactor = Real(1e-6 / 180);
    prm.fluid.bottom = sphere::fluid_boundary<Real>::inflow(Real(1e-4));
    prm.fluid.top = sphere::fluid_boundary<Real>::prescribed_pressure(0);
    sphere::fluid_coupling<Real, sphere::cuda, sphere::drag::gidaspow, Poisson, sphere::darcy_flow> coupled(
        sphere::fluid_grid<Real>::make(s.box, 4, 4, 20), prm);
    coupled.step(sim);
    return double(coupled.fluid().pressure()[0]) + double(coupled.fluid().cell_velocity()[0].z);
}

template <class Real>
double exercise_all()
{
    namespace drag = sphere::drag;
    using jacobi = sphere::jacobi_poisson<Real, sphere::cuda>;
    using cg = sphere::cg_poisson<Real, sphere::cuda>;
    using mg = sphere::mg_poisson<Real, sphere::cuda>;
    return exercise<Real, drag::gidaspow, jacobi>() + exercise<Real, drag::gidaspow_blended, cg>() +
           exercise<Real, drag::ergun, cg>() + exercise<Real, drag::wen_yu, jacobi>() +
           exercise<Real, drag::gidaspow, mg>() +
           exercise<Real, drag::gidaspow, cg, sphere::integrate::velocity_verlet>() + exercise_darcy<Real, cg>() +
           exercise_darcy<Real, mg>();
}

} // namespace

int main()
{
    std::printf("%g\n", exercise_all<float>() + exercise_all<double>());
    return 0;
}
