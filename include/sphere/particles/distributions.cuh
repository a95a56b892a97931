#pragma once
/// \file
/// Particle radii drawn from uniform, log-normal and bimodal distributions (sphere's
/// generateRadii and generateBimodalRadii), reproducibly: the same seed gives the same radii
/// with every compiler and standard library. The generator is std::mt19937_64, whose sequence
/// the C++ standard fixes; the transforms to uniform, normal and integer variates are this
/// library's own (std::*_distribution differ between standard libraries). Host-only.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "../core/constants.cuh"
#include "../core/error.cuh"

namespace sphere {

/// A seeded stream of random numbers with portable transforms.
class random_stream {
public:
    explicit random_stream(std::uint64_t seed) : engine_(seed) {}

    /// Uniform in [0, 1): the upper 53 bits of one 64-bit draw, times 2^-53.
    double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

    /// Uniform in [a, b): a + (b - a) uniform().
    double uniform(double a, double b) { return a + (b - a) * uniform(); }

    /// An integer uniform in [0, n), without bias (draws above the largest multiple of n
    /// are rejected). n must be at least 1.
    std::uint64_t below(std::uint64_t n)
    {
        if (n == 0) detail::fail("random_stream::below(0): the range [0, 0) is empty");
        const std::uint64_t limit = ~std::uint64_t(0) - (~std::uint64_t(0) % n + 1) % n; // largest k n - 1
        std::uint64_t v = engine_();
        while (v > limit) v = engine_();
        return v % n;
    }

    /// A standard normal variate by Marsaglia's polar method: pairs (u, v) uniform in
    /// (-1, 1)^2 are drawn until 0 < s = u^2 + v^2 < 1; then u sqrt(-2 ln s / s) is returned
    /// and v sqrt(-2 ln s / s) is kept for the next call.
    double normal()
    {
        if (has_spare_) {
            has_spare_ = false;
            return spare_;
        }
        double u, v, s;
        do {
            u = 2 * uniform() - 1;
            v = 2 * uniform() - 1;
            s = u * u + v * v;
        } while (!(s > 0 && s < 1));
        const double f = std::sqrt(-2 * std::log(s) / s);
        spare_ = v * f;
        has_spare_ = true;
        return u * f;
    }

private:
    std::mt19937_64 engine_;
    double spare_ = 0;
    bool has_spare_ = false;
};

/// Parameters of the normal distribution of ln r.
struct lognormal_parameters {
    double mu;    ///< mean of ln(r / 1 m)
    double sigma; ///< standard deviation of ln r
};

/// The (mu, sigma) of a log-normal distribution with the given mean (m, > 0) and standard
/// deviation (m, >= 0): sigma^2 = ln(1 + std^2 / mean^2), mu = ln(mean) - sigma^2 / 2, as
/// sphere's generateRadii(psd = 'logn') (whose radius_variance is std^2).
inline lognormal_parameters lognormal_from_moments(double mean, double stddev)
{
    if (!(mean > 0) || !std::isfinite(mean))
        detail::fail("log-normal radii: mean = ", mean, " m must be positive and finite");
    if (!(stddev >= 0) || !std::isfinite(stddev))
        detail::fail("log-normal radii: standard deviation = ", stddev, " m must be non-negative and finite");
    const double s2 = std::log1p(stddev * stddev / (mean * mean));
    return {std::log(mean) - s2 / 2, std::sqrt(s2)};
}

/// n radii uniform in [r_min, r_max] (m), 0 < r_min <= r_max (sphere's psd = 'uni' with
/// r_min = mean - variance, r_max = mean + variance).
template <class Real>
std::vector<Real> uniform_radii(std::size_t n, Real r_min, Real r_max, std::uint64_t seed)
{
    if (!(r_min > 0) || !std::isfinite(r_min) || !(r_max >= r_min) || !std::isfinite(r_max))
        detail::fail("uniform radii: [r_min, r_max] = [", r_min, ", ", r_max,
                     "] m must be finite with 0 < r_min <= r_max");
    random_stream rng(seed);
    std::vector<Real> r(n);
    for (std::size_t i = 0; i < n; ++i) {
        const Real v = static_cast<Real>(rng.uniform(double(r_min), double(r_max)));
        r[i] = v > r_max ? r_max : (v < r_min ? r_min : v); // rounding to float can step outside
    }
    return r;
}

/// n log-normal radii with the given mean and standard deviation (m): r = exp(mu + sigma z)
/// with z standard normal (random_stream::normal) and (mu, sigma) from lognormal_from_moments.
template <class Real>
std::vector<Real> lognormal_radii(std::size_t n, Real mean, Real stddev, std::uint64_t seed)
{
    const lognormal_parameters p = lognormal_from_moments(double(mean), double(stddev));
    random_stream rng(seed);
    std::vector<Real> r(n);
    for (std::size_t i = 0; i < n; ++i) r[i] = static_cast<Real>(std::exp(p.mu + p.sigma * rng.normal()));
    return r;
}

/// n radii of two sizes (sphere's generateBimodalRadii): r_large for
/// round(n ratio V_s / (V_l + ratio V_s)) particles chosen at random, r_small for the rest,
/// so that the volume of the large population over that of the small is close to `ratio`
/// (V_s, V_l the volumes of one small and one large sphere). 0 < r_small < r_large (m),
/// ratio >= 0.
template <class Real>
std::vector<Real> bimodal_radii(std::size_t n, Real r_small, Real r_large, double ratio, std::uint64_t seed)
{
    if (!(r_small > 0) || !(r_large > r_small) || !std::isfinite(r_large))
        detail::fail("bimodal radii: r_small = ", r_small, " m and r_large = ", r_large,
                     " m must be finite with 0 < r_small < r_large");
    if (!(ratio >= 0) || !std::isfinite(ratio))
        detail::fail("bimodal radii: volume ratio (large / small) = ", ratio, " must be non-negative and finite");
    const double vs = double(r_small) * double(r_small) * double(r_small);
    const double vl = double(r_large) * double(r_large) * double(r_large);
    const std::size_t large = static_cast<std::size_t>(std::llround(double(n) * ratio * vs / (vl + ratio * vs)));
    std::vector<std::size_t> index(n);
    for (std::size_t i = 0; i < n; ++i) index[i] = i;
    random_stream rng(seed);
    std::vector<Real> r(n, r_small);
    for (std::size_t k = 0; k < large; ++k) { // the first `large` steps of a Fisher-Yates shuffle
        const std::size_t pick = k + static_cast<std::size_t>(rng.below(n - k));
        const std::size_t chosen = index[pick];
        index[pick] = index[k];
        index[k] = chosen;
        r[chosen] = r_large;
    }
    return r;
}

} // namespace sphere
