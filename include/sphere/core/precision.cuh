#pragma once
/// \file
/// Precision policies: the first template argument of `simulation` is `float`, `double` or
/// `sphere::mixed`. A policy P names two types: `real_t<P>`, in which particle fields other
/// than positions, contact histories and the contact laws compute, and `coord_t<P>`, in which
/// positions, walls, the world, the time step and every value the simulation takes from or
/// hands to the user are held (docs/architecture.md, "Precision").

namespace sphere {

/// Positions (and radii), walls and everything user-facing in double; velocities, forces,
/// masses, contact histories and the contact laws in float. Relative positions are formed in
/// double, so overlaps of 1e-8 m between particles 0.05 m from the origin stay resolved.
struct mixed {};

template <class P>
struct precision_traits {
    using real = P;
    using coord = P;
};

template <>
struct precision_traits<mixed> {
    using real = float;
    using coord = double;
};

/// The type of particle fields other than positions and of the contact laws' arithmetic.
template <class P> using real_t = typename precision_traits<P>::real;
/// The type of positions, walls and user-facing values.
template <class P> using coord_t = typename precision_traits<P>::coord;

} // namespace sphere
