#pragma once
/// \file
/// Shear strain and shear velocity of a shear experiment (sphere's shearStrain and shearVel).
/// The sample lies between a rough bottom of fixed particles (motion::fixed) and a top layer
/// of prescribed particles (motion::prescribed or prescribed_horizontal) moved along a
/// horizontal axis. sphere takes
/// the top particles' displacement (time times their velocity) over the upper wall's height
/// above the floor. Here the displacement is measured (periodic wraps unfolded) relative to the
/// bottom layer, and divided by the distance between the two layers' mean centres: the height
/// over which the velocity difference is imposed, so gamma = displacement / height is the
/// mean shear strain of the material between them. (sphere's height also counts the half
/// particles above and below the layer centres; with a top layer that moves at a prescribed
/// velocity and an upper wall that moves under a stress, the layers are what shears.)
/// Host-side, on particle snapshots.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "../boundary/world.cuh"
#include "../core/error.cuh"
#include "../particles/particle.cuh"
#include "../particles/state.cuh"

namespace sphere {

/// The two driving layers of a shear experiment: particle indices.
struct shear_layers {
    std::vector<std::size_t> top;    ///< prescribed particles, either kind (moved at the shear velocity)
    std::vector<std::size_t> bottom; ///< fixed particles (the rough bottom)
};

/// The prescribed or horizontally prescribed (top) and fixed (bottom) particles of a snapshot;
/// throws when either set is empty.
template <class Real>
shear_layers find_shear_layers(const particle_snapshot<Real>& s)
{
    shear_layers l;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const auto kind = static_cast<motion>(s.kind[i]);
        if (kind == motion::prescribed || kind == motion::prescribed_horizontal) l.top.push_back(i);
        if (s.kind[i] == static_cast<std::uint8_t>(motion::fixed)) l.bottom.push_back(i);
    }
    if (l.top.empty() || l.bottom.empty())
        detail::fail("shear layers: ", l.top.size(), " prescribed (top) and ", l.bottom.size(),
                     " fixed (bottom) particles; a shear experiment needs both");
    return l;
}

namespace detail {
template <class Real>
double layer_mean(const std::vector<std::size_t>& layer, const std::vector<vec3<Real>>& field, int axis)
{
    double sum = 0;
    for (std::size_t i : layer) sum += double(field[i][axis]);
    return sum / double(layer.size());
}

template <class Real>
double layer_mean_position(const std::vector<std::size_t>& layer, const std::vector<vec4<Real>>& x, int axis)
{
    double sum = 0;
    for (std::size_t i : layer) sum += double(x[i].xyz()[axis]);
    return sum / double(layer.size());
}

inline void check_shear_axis(int axis)
{
    if (axis != 0 && axis != 1) fail("shear axis ", axis, ": must be 0 (x) or 1 (y), horizontal");
}
} // namespace detail

/// Shear velocity (m/s): the mean velocity along `axis` (0 = x, 1 = y) of the top layer less
/// that of the bottom layer.
template <class Real>
double shear_velocity(const particle_snapshot<Real>& s, const shear_layers& layers, int axis = 0)
{
    detail::check_shear_axis(axis);
    return detail::layer_mean(layers.top, s.v, axis) - detail::layer_mean(layers.bottom, s.v, axis);
}

/// Height of the sheared sample (m): mean z of the top layer's centres less the bottom's.
template <class Real>
double shear_height(const particle_snapshot<Real>& s, const shear_layers& layers)
{
    return detail::layer_mean_position(layers.top, s.x, 2) - detail::layer_mean_position(layers.bottom, s.x, 2);
}

/// Shear stress (Pa) on the sample: the force along `axis` (0 = x, 1 = y) that drives the top
/// layer, which cancels the contact forces on it (docs/physics.md, "Driven particles"), over
/// the horizontal area `area` (m^2): tau = -sum_top f_axis / area. Sampled after a step, it is
/// that step's stress; average over many steps for a steady value.
template <class Real>
double shear_stress(const particle_snapshot<Real>& s, const shear_layers& layers, double area, int axis = 0)
{
    detail::check_shear_axis(axis);
    if (!(area > 0) || !std::isfinite(area)) detail::fail("shear_stress: area = ", area, " m^2 must be positive and finite");
    double sum = 0;
    for (std::size_t i : layers.top) sum -= double(s.force[i][axis]);
    return sum / area;
}

/// Follows the shear strain from a reference state on: call update() at least once per
/// interval in which no layer particle moves half a period along the shear axis (a periodic
/// wrap is unfolded as the shortest move).
template <class Real>
class shear_tracker {
public:
    /// Starts from snapshot `s` (strain 0) of a world `box`, shearing along `axis` (0 or 1).
    shear_tracker(const particle_snapshot<Real>& s, const world<Real>& box, int axis = 0)
        : box_(box), axis_(axis), layers_(find_shear_layers(s))
    {
        detail::check_shear_axis(axis);
        for (std::size_t i : layers_.top) last_.push_back(double(s.x[i].xyz()[axis]));
        for (std::size_t i : layers_.bottom) last_.push_back(double(s.x[i].xyz()[axis]));
        moved_.assign(last_.size(), 0.0);
        height_ = shear_height(s, layers_);
        velocity_ = shear_velocity(s, layers_, axis);
    }

    /// Starts from the current state of a simulation.
    template <class Sim>
    explicit shear_tracker(const Sim& sim, int axis = 0) : shear_tracker(sim.snapshot(), sim.config().box, axis)
    {
    }

    /// Accumulates each layer particle's move along the axis since the last update.
    void update(const particle_snapshot<Real>& s)
    {
        std::size_t k = 0;
        for (const std::vector<std::size_t>* layer : {&layers_.top, &layers_.bottom})
            for (std::size_t i : *layer) {
                const double now = double(s.x[i].xyz()[axis_]);
                double d = now - last_[k];
                if (box_.periodic(axis_)) {
                    const double L = double(box_.length(axis_));
                    d -= L * std::nearbyint(d / L);
                }
                moved_[k] += d;
                last_[k] = now;
                ++k;
            }
        height_ = shear_height(s, layers_);
        velocity_ = shear_velocity(s, layers_, axis_);
    }

    /// update() from a simulation's current state.
    template <class Sim>
    void update(const Sim& sim)
    {
        update(sim.snapshot());
    }

    /// Mean displacement of the top layer less that of the bottom layer along the axis since
    /// the start (m).
    double displacement() const
    {
        double top = 0, bottom = 0;
        const std::size_t nt = layers_.top.size();
        for (std::size_t k = 0; k < moved_.size(); ++k) (k < nt ? top : bottom) += moved_[k];
        return top / double(nt) - bottom / double(moved_.size() - nt);
    }

    /// Height between the layers at the last update (m), shear_height.
    double height() const { return height_; }
    /// Shear strain gamma = displacement() / height() (sphere's shearStrain).
    double strain() const { return displacement() / height_; }
    /// Shear velocity at the last update (m/s), shear_velocity (sphere's shearVel).
    double velocity() const { return velocity_; }
    /// Shear strain rate at the last update, velocity() / height() (1/s).
    double strain_rate() const { return velocity_ / height_; }
    /// The layers it follows.
    const shear_layers& layers() const { return layers_; }

private:
    world<Real> box_;
    int axis_;
    shear_layers layers_;
    std::vector<double> last_, moved_; ///< per layer particle (top, then bottom): last position, total move
    double height_ = 0, velocity_ = 0;
};

} // namespace sphere
