#pragma once
/// \file
/// Inserting particles during a run, as LIGGGHTS users fill a silo: a region, a rate, radii
/// uniform or log-normal within a range, no overlap at insertion (simulation::insert does the
/// adding).
/// Host-only set-up code; the random choices use random_stream, so a seed and the same run
/// give the same particles.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "../core/error.cuh"
#include "../core/vec.cuh"
#include "../particles/distributions.cuh"
#include "../particles/particle.cuh"

namespace sphere {

/// How an inserter draws radii.
enum class radius_distribution : std::uint8_t {
    uniform = 0,   ///< uniform in [radius_min, radius_max]
    lognormal = 1, ///< log-normal with radius_mean and radius_stddev (lognormal_from_moments),
                   ///< drawn again until it lies in [radius_min, radius_max]
};

/// Where, how fast and which particles an inserter adds (SI units).
template <class Real>
struct insertion_settings {
    vec3<Real> lo{0, 0, 0}, hi{0, 0, 0}; ///< the region the particles are placed in (m): whole particles inside
    double rate = 0;                     ///< particles per second of simulated time, > 0
    Real radius_min = 0, radius_max = 0; ///< the range of the radii (m)
    radius_distribution distribution = radius_distribution::uniform;
    Real radius_mean = 0, radius_stddev = 0; ///< of the log-normal radii (m); the mean within the range
    Real density = 0;                    ///< (kg/m^3), > 0
    vec3<Real> velocity{0, 0, 0};        ///< initial velocity (m/s)
    std::size_t total = 0;               ///< particles to insert in all; 0: no limit
    std::uint64_t seed = 1;              ///< of the radii and positions
    unsigned tries = 1000;               ///< candidate positions per particle before it waits for the next call
};

/// Inserts particles into a simulation of type Sim at a rate. Call it as often as the
/// insertion should be resolved (e.g. an observer every 100 steps): each call inserts the
/// particles due by then, rate (t - t_start) of them rounded down less those already in
/// (capped by total), each of a radius drawn uniformly and at a centre drawn uniformly in the
/// region, r from its faces, where it overlaps neither a particle of the simulation nor one
/// inserted with it. A particle that finds no room in `tries` candidates (the region is full
/// for now) waits for a later call, with its radius kept; waiting() counts them.
template <class Sim>
class inserter {
public:
    using Real = typename Sim::real_type;

    /// Throws sphere::error for settings that cannot insert anything (a region that does not
    /// hold the largest particle, a rate, radius or density that is not positive and finite).
    inserter(const insertion_settings<Real>& s, double start_time) : s_(s), start_(start_time), rng_(s.seed)
    {
        if (!(s.rate > 0) || !std::isfinite(s.rate))
            detail::fail("insertion_settings.rate = ", s.rate, " particles/s: must be positive and finite");
        if (!(s.radius_min > 0) || !(s.radius_max >= s.radius_min) || !std::isfinite(s.radius_max))
            detail::fail("insertion_settings.radius_min = ", s.radius_min, " m, radius_max = ", s.radius_max,
                         " m: need 0 < radius_min <= radius_max, finite");
        if (!(s.density > 0) || !std::isfinite(s.density))
            detail::fail("insertion_settings.density = ", s.density, " kg/m^3: must be positive and finite");
        for (int a = 0; a < 3; ++a) {
            if (!std::isfinite(s.lo[a]) || !std::isfinite(s.hi[a]))
                detail::fail("insertion_settings: the region spans [", s.lo[a], ", ", s.hi[a], "] m on axis ", a,
                             ": its bounds must be finite");
            if (!(s.hi[a] - s.lo[a] >= 2 * s.radius_max))
                detail::fail("insertion_settings: the region spans [", s.lo[a], ", ", s.hi[a], "] m on axis ", a,
                             ", too little for a particle of radius ", s.radius_max, " m");
        }
        if (s.tries == 0) detail::fail("insertion_settings.tries = 0: at least one candidate is needed");
        if (s.distribution == radius_distribution::lognormal) {
            if (!(s.radius_mean >= s.radius_min && s.radius_mean <= s.radius_max))
                detail::fail("insertion_settings.radius_mean = ", s.radius_mean, " m lies outside [radius_min, radius_max] = [",
                             s.radius_min, ", ", s.radius_max, "] m");
            lognormal_ = lognormal_from_moments(double(s.radius_mean), double(s.radius_stddev));
        } else if (s.distribution != radius_distribution::uniform) {
            detail::fail("insertion_settings.distribution = ", unsigned(s.distribution), ": not a radius_distribution");
        }
    }

    /// Inserts the particles due by sim.time(); returns how many it inserted.
    std::size_t operator()(Sim& sim)
    {
        std::size_t due = static_cast<std::size_t>(std::floor(s_.rate * (sim.time() - start_)));
        if (s_.total && due > s_.total) due = s_.total;
        if (due <= inserted_) return 0;
        // The particles that may touch one in the region: the region grown by the largest
        // radius of either (a particle's reach), in the nearest image.
        const auto at = sim.positions();
        const auto& box = sim.config().box;
        std::vector<vec4<Real>> near;
        const Real largest = sim.largest_radius();
        const vec3<Real> middle = (s_.lo + s_.hi) * Real(0.5), half = (s_.hi - s_.lo) * Real(0.5);
        for (std::size_t i = 0; i < at.size(); ++i) {
            const vec3<Real> d = box.nearest_image_inside(at[i].xyz() - middle);
            bool close = true;
            for (int a = 0; a < 3; ++a) close = close && std::fabs(d[a]) < half[a] + s_.radius_max + largest;
            if (close) near.push_back(at[i]);
        }
        std::vector<particle<Real>> added;
        for (std::size_t k = inserted_; k < due; ++k) {
            if (!has_radius_) {
                radius_ = draw_radius();
                has_radius_ = true;
            }
            vec3<Real> centre{0, 0, 0};
            bool placed = false;
            for (unsigned t = 0; t < s_.tries && !placed; ++t) {
                Real c[3];
                for (int a = 0; a < 3; ++a) c[a] = Real(rng_.uniform(double(s_.lo[a] + radius_), double(s_.hi[a] - radius_)));
                centre = {c[0], c[1], c[2]};
                placed = true;
                for (const vec4<Real>& o : near) {
                    const vec3<Real> d = box.nearest_image_inside(centre - o.xyz());
                    if (norm2(d) < (radius_ + o.w) * (radius_ + o.w)) {
                        placed = false;
                        break;
                    }
                }
            }
            if (!placed) break; // the region is full for now: this particle waits
            particle<Real> p;
            p.position = centre;
            p.radius = radius_;
            p.density = s_.density;
            p.velocity = s_.velocity;
            added.push_back(p);
            near.push_back({centre.x, centre.y, centre.z, radius_});
            has_radius_ = false;
        }
        sim.insert(added);
        inserted_ += added.size();
        waiting_ = due - inserted_;
        return added.size();
    }

    std::size_t inserted() const { return inserted_; }
    /// Particles due that found no room at the last call.
    std::size_t waiting() const { return waiting_; }

private:
    Real draw_radius()
    {
        if (s_.distribution == radius_distribution::uniform)
            return Real(rng_.uniform(double(s_.radius_min), double(s_.radius_max)));
        for (;;) { // the mean lies in the range, so a draw lands there with probability > 0
            const Real r = Real(std::exp(lognormal_.mu + lognormal_.sigma * rng_.normal()));
            if (r >= s_.radius_min && r <= s_.radius_max) return r;
        }
    }

    insertion_settings<Real> s_;
    lognormal_parameters lognormal_{0, 0};
    double start_;
    random_stream rng_;
    std::size_t inserted_ = 0, waiting_ = 0;
    Real radius_ = 0;         ///< the radius drawn for the next particle
    bool has_radius_ = false;
};

} // namespace sphere
