#pragma once
/// \file
/// The orientations of the intact bonds as trend and plunge (the seeds' bondsRose), and their
/// rose histogram. Host-side, on a simulation.
#include <cmath>
#include <cstddef>
#include <vector>

#include "../core/constants.cuh"
#include "../core/error.cuh"
#include "../simulation.cuh"

namespace sphere {

/// A bond's axis as a geologist gives a line: the trend (degrees clockwise from +y, the north,
/// to the horizontal projection, in [0, 360)) and the plunge (degrees below the horizontal, in
/// [0, 90]) of the axis pointing downwards (+z up; a horizontal axis points either way and
/// is taken with a trend below 180 degrees).
struct bond_orientation {
    double trend;
    double plunge;
};

/// The orientation of the axis d (m).
inline bond_orientation orientation_of(vec3<double> d)
{
    if (d.z > 0 || (d.z == 0 && (d.x < 0 || (d.x == 0 && d.y < 0)))) d = -d;
    const double degrees = 180 / pi<double>;
    double trend = std::atan2(d.x, d.y) * degrees;
    if (trend < 0) trend += 360;
    if (trend >= 360) trend -= 360;
    return {trend, std::atan2(-d.z, std::hypot(d.x, d.y)) * degrees};
}

/// The orientation of every intact bond of `sim`, in the order of its bonds() table.
template <class Sim>
std::vector<bond_orientation> bond_orientations(const Sim& sim)
{
    const auto at = sim.positions();
    const auto bonds = sim.bonds();
    const auto& box = sim.config().box;
    std::vector<bond_orientation> out;
    for (std::size_t k = 0; k < bonds.size(); ++k)
        if (!bonds.broken[k])
            out.push_back(orientation_of(vec_cast<double>(box.nearest_image_inside(at[bonds.j[k]].xyz() -
                                                                                    at[bonds.i[k]].xyz()))));
    return out;
}

/// A rose histogram: bond counts by trend in `trend.size()` equal sectors of [0, 360) degrees
/// and by plunge in `plunge.size()` equal bins of [0, 90] degrees.
struct bond_rose {
    std::vector<std::size_t> trend;
    std::vector<std::size_t> plunge;
};

/// The rose histogram of `orientations` with `trend_bins` sectors and `plunge_bins` bins.
inline bond_rose rose_of(const std::vector<bond_orientation>& orientations, std::size_t trend_bins = 36,
                         std::size_t plunge_bins = 9)
{
    if (trend_bins == 0 || plunge_bins == 0)
        detail::fail("rose_of: ", trend_bins, " trend and ", plunge_bins, " plunge bins: each must be at least 1");
    bond_rose out{std::vector<std::size_t>(trend_bins, 0), std::vector<std::size_t>(plunge_bins, 0)};
    for (const bond_orientation& o : orientations) {
        const std::size_t t = std::size_t(o.trend / 360 * double(trend_bins));
        const std::size_t p = std::size_t(o.plunge / 90 * double(plunge_bins));
        ++out.trend[t < trend_bins ? t : trend_bins - 1];
        ++out.plunge[p < plunge_bins ? p : plunge_bins - 1];
    }
    return out;
}

} // namespace sphere
