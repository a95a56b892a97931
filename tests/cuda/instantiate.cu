// Instantiates every kernel of the DEM core for sphere::cuda in float, double and mixed
// precision, with every contact-law and integrator policy (Hertz-Mindlin, capillary
// cohesion and rolling resistance under it, and two materials in double), so that CI proves the CUDA backend compiles and links, and ptxas
// reports every kernel's resources (tests/check_ptxas.py); and the ray tracer's pixel kernel
// (render/trace.cuh) in float and double.
// It is built, not run: build machines have no GPU.
#include <sphere/dem.cuh>
#include <sphere/render/trace.cuh>

#include <cstdio>
#include <vector>

namespace {

template <class Real>
void stiffen(sphere::contact_params<Real>& p)
{
    p.k_n = Real(1e5);
    p.k_t = Real(1e5);
}

template <class Real>
void stiffen(sphere::hertz_params<Real>& p)
{
    p.youngs_modulus = Real(1e8);
    p.poisson_ratio = Real(0.3);
    p.restitution = Real(0.5);
}

template <class Real, class Base>
void stiffen(sphere::capillary_params<Real, Base>& p)
{
    stiffen(static_cast<Base&>(p));
    p.surface_tension = Real(0.072);
    p.bridge_volume = Real(1e-9);
}

template <class Real, class Base>
void stiffen(sphere::rolling_params<Real, Base>& p)
{
    stiffen(static_cast<Base&>(p));
    p.mu_r = p.mu_twist = Real(0.1);
    p.k_r = p.k_twist = Real(1);
}

template <class Params, unsigned Count>
void stiffen(sphere::material_params<Params, Count>& p)
{
    for (Params& m : p.material) stiffen(m);
}

template <class P, class Law, class Integrator>
double exercise()
{
    using Real = sphere::coord_t<P>;
    typename sphere::simulation<P, sphere::cuda, Law, Integrator>::settings_type s;
    s.box.lo = {0, 0, 0};
    s.box.hi = {Real(0.1), Real(0.1), Real(0.1)};
    s.box.axis[0] = sphere::boundary::periodic;
    stiffen(s.contact);
    s.wall = s.contact;
    std::vector<sphere::particle<Real>> particles(1);
    particles[0].position = {Real(0.05), Real(0.05), Real(0.05)};
    particles[0].radius = Real(0.01);
    particles[0].density = Real(2500);
    sphere::simulation<P, sphere::cuda, Law, Integrator> sim(s, particles);
    sim.step();
    sim.set_velocity(0, {1, 0, 0}, {0, 0, 0});
    const auto e = sim.energy();
    const auto p = sim.momentum();
    return static_cast<double>(e.total() + p.x) + static_cast<double>(sim.snapshot().x[0].x);
}

template <class P>
double exercise_all()
{
    using namespace sphere;
    using visco = contact::linear<tangential::visco_frictional, tangential::visco_frictional>;
    return exercise<P, contact::linear<>, integrate::semi_implicit_euler>() + exercise<P, visco, integrate::taylor2>() +
           exercise<P, contact::linear<>, integrate::explicit_euler>();
}

/// The step's two shapes (integration after the forces, and velocity Verlet's drift before
/// them) in precision P.
template <class P>
double exercise_step_shapes()
{
    using namespace sphere;
    return exercise<P, contact::linear<>, integrate::semi_implicit_euler>() +
           exercise<P, contact::linear<>, integrate::velocity_verlet>();
}

/// The ray tracer's pixel kernel on one sphere, in precision Real.
template <class Real>
double render_one()
{
    sphere::sphere_scene<Real> scene;
    scene.spheres = {{Real(0), Real(0), Real(0), Real(0.5)}};
    scene.values = {Real(1)};
    return double(sphere::render_scene<sphere::cuda>(scene, sphere::camera{}, sphere::render_style{}).bytes[0]);
}

} // namespace

int main()
{
    std::printf("%g\n", exercise_all<float>() + exercise_all<double>() +
                                exercise<double, sphere::contact::linear<>, sphere::integrate::velocity_verlet>() +
                                exercise<double, sphere::contact::hertz_mindlin<>, sphere::integrate::semi_implicit_euler>() +
                                exercise<double, sphere::contact::capillary<>, sphere::integrate::semi_implicit_euler>() +
                                exercise<double, sphere::contact::capillary<sphere::contact::rolling<>>,
                                         sphere::integrate::velocity_verlet>() +
                                exercise<double, sphere::contact::materials<>, sphere::integrate::semi_implicit_euler>() +
                                exercise_step_shapes<sphere::mixed>() + render_one<float>() + render_one<double>());
    return 0;
}
