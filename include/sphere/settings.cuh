#pragma once
/// \file
/// Everything a DEM simulation needs besides its particles.
#include <cstddef>

#include "boundary/wall_control.cuh"
#include "boundary/walls.cuh"
#include "bonds/bond_params.cuh"
#include "boundary/world.cuh"
#include "contact/params.cuh"
#include "contact/summation.cuh"
#include "core/vec.cuh"

namespace sphere {

/// `Params` is the contact law's parameter type (`Law::params<Real>`, contact/law.cuh); the
/// default is the linear law's.
template <class Real, class Params = contact_params<Real>>
struct settings {
    using params_type = Params;
    world<Real> box;                ///< world box and per-axis boundaries
    Params contact;                 ///< particle-particle contacts
    Params wall;                    ///< particle-wall contacts (linear law: sphere's k_n, gamma_wn, gamma_wt, mu_ws, mu_wd)
    bond_params<Real> bond;         ///< the parallel bonds, if the simulation has any (docs/physics.md, "Bonds")
    vec3<Real> gravity{0, 0, 0};    ///< (m/s^2)
    Real dt = 0;                    ///< time step (s); 0 selects the contact law's rule (linear: 0.075 min sqrt(m / max(k_n, k_t)))
    Real skin = 0;                  ///< contact-list skin (m); 0 rebuilds the lists every step, as sphere
    /// The largest overlap two particles (or a particle and a wall) may start with, as a
    /// fraction of the smaller radius; a deeper one is refused, naming both (docs/physics.md,
    /// "Initial overlaps"). Raise it (to 1 or infinity) to accept deeper ones:
    /// simulation::initial_overlap() reports the deepest. Coincident centres are always refused.
    /// Not stored in checkpoints: a restart accepts the state it restores, as an insertion does
    /// the particles already there.
    Real max_initial_overlap = Real(0.5);
    /// Keep each contact's force of the last step (for the stress and contact-network analyses
    /// of analysis/stress.cuh); off saves 32 B (double) per listed pair and their stores.
    bool contact_forces = true;
    /// Book each particle's contact pressure, dissipation rates and dissipated energies every
    /// step, so that energy().total() closes; off leaves them at zero, saves their work and
    /// does not allocate their five arrays (40 B per particle in double).
    bool energy_audit = true;
    /// Integrate each particle's angular position (rad; the VTK field angular_position, as the
    /// original sphere); off leaves it at zero and does not allocate it (24 B per particle in
    /// double).
    bool angular_position = true;
    /// Integrate each particle's displacement since its simulation began, sum of v dt (m; the
    /// VTK field accumulated_displacement, the original sphere's xysum: how far a sheared layer
    /// has travelled, unwrapped across periodic boundaries); off leaves it at zero and does not
    /// allocate it (24 B per particle in double and mixed, 12 B in float).
    bool accumulated_displacement = true;
    /// Store the particles in the neighbour grid's cell order, permuted at every rebuild (nearby
    /// particles sit nearby in memory: about 2x faster on a large, spatially unsorted input);
    /// false keeps the user's order. Results are the same bits either way: every sum follows
    /// the grid's ranks, not the storage order (docs/architecture.md).
    bool reorder = true;
    /// How pair forces reach the particles (contact/summation.cuh): the default picks the
    /// backend's fast schedule; both give the same physics to round-off.
    sphere::pair_summation pair_summation = sphere::pair_summation::automatic;
    Real cell_size = 0;             ///< neighbour-grid cell width (m); 0 selects at least the largest diameter plus skin (grid/geometry.cuh)
    /// Motion of each wall face f (axis f / 2, lower face when f is even; the upper wall is
    /// walls[5]); all fixed by default.
    wall_control<Real> walls[wall_set<Real>::count];
};

} // namespace sphere
