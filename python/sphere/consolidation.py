"""The C++ consolidation example (examples/consolidation/main.cpp) as a call: a sample poured
under gravity into a box periodic in x and y (granular.deposited_sample) or a saved one
(granular.saved_sample, the example's --sample), then loaded by the upper wall at a normal
stress, optionally sine-modulated (sphere's consolidate()). The same options give the example's
numbers to the last bit, in the same precision and with the same thread count: every value
below is computed in the same order as there (and, where the example casts to its precision,
by the library).
"""

from dataclasses import dataclass

from .granular import TOP, prepared_sample, sample_contact, stress_wall
from .simulation import Simulation


@dataclass
class Consolidation:
    """What consolidate() found: the simulation at the end, the time at which the loading began
    (s: the deposition's duration, or the saved sample's time), the sample's top (the upper
    wall's position) and porosity before loading (m), the upper wall's final position (m), the
    compression of the sample (m), the final porosity and void ratio, and the wall's mean
    normal stress over the second half of the loading (Pa)."""

    simulation: Simulation
    deposition_time: float
    sample_top: float
    initial_porosity: float
    wall_position: float
    compression: float
    porosity: float
    void_ratio: float
    mean_stress: float


def consolidate(particles=800, radius=0.01, spread=0.1, density=2500.0, k_n=1e5, friction=0.5, restitution=0.5,
                seed=1, wall_mass=0.1, stress=1e4, amplitude=0.0, frequency=0.0, duration=0.4, precision="double",
                checkpoint=None, verbose=True, sample=None):
    """The consolidation example: deposited_sample(...) (or, with `sample`, the saved sample at
    that path, as the example's --sample: its particles, contacts and world, the wall
    parameters of these options), then the upper wall held at the normal stress `stress` +
    `amplitude` sin(2 pi `frequency` t) (Pa) for `duration` s, the wall's mass `wall_mass` times
    the particles'. Prints the example's lines when `verbose`, writes the final checkpoint to
    `checkpoint` when given, and returns a Consolidation. The options are the example's
    (consolidation --help), with the same defaults."""
    sim = prepared_sample(sample, sample_contact(radius, density, k_n, friction, restitution), verbose,
                          particles=particles, radius=radius, spread=spread, density=density, k_n=k_n,
                          friction=friction, restitution=restitution, seed=seed, precision=precision)
    z0 = sim.walls().position[TOP]
    initial = sim.porosity()["porosity"]
    if verbose:
        print("consolidation: %d particles (%s), sample at t = %.3f s; sample top at %.6f m, porosity %.4f"
              % (sim.size, precision, sim.time, z0, initial))
    start = sim.time
    sim.set_wall_control(TOP, stress_wall(sim, stress, wall_mass, amplitude, frequency))

    # The time-average of the wall stress over the second half of the loading.
    t_half = sim.time + duration / 2
    stresses = []

    def second_half(s):
        if s.time >= t_half:
            stresses.append(s.wall_normal_stress(TOP))

    sim.add_observer(1, second_half)
    sim.run_for(duration)

    stress_sum = 0.0
    for value in stresses:  # in order, as the example sums
        stress_sum += value
    p = sim.porosity()
    wall = sim.walls().position[TOP]
    result = Consolidation(sim, start, z0, initial, wall, z0 - wall, p["porosity"], p["void_ratio"],
                           stress_sum / len(stresses))
    if verbose:
        print("%-34s %14.6f" % ("upper wall position (m)", result.wall_position))
        print("%-34s %14.6e" % ("compression of the sample (m)", result.compression))
        print("%-34s %14.6f" % ("porosity", result.porosity))
        print("%-34s %14.6f" % ("void ratio", result.void_ratio))
        print("%-34s %14.1f  (target %.1f)" % ("mean wall stress, 2nd half (Pa)", result.mean_stress, stress))
    if checkpoint is not None:
        sim.write_checkpoint(checkpoint)
    return result
