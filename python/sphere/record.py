"""A time series of a running simulation (sphere's time series of energy and walls): a
Recorder observes a Simulation every few steps and keeps the time, the energy budget, the
walls' positions and forces and their normal stresses, as NumPy arrays for analysis and for
sphere.plot."""

from dataclasses import fields

import numpy as np

from .fields import Energy


class Recorder:
    """Records sim every `every` steps from now on (an observer; also once now when `now`):
    `time` (s), `energy` (a dict of arrays, one per sphere.Energy field, J or W), `wall_position`
    (T, 6) (m), `wall_force` (T, 6) (N, the particles' force along each axis) and `wall_stress`
    (T, 6) (Pa, compressive positive; NaN on periodic axes). Arrays are built when read."""

    def __init__(self, sim, every=100, now=True):
        self._rows = []
        self._active = sim.walls().active.copy()
        if now:
            self.record(sim)
        sim.add_observer(every, self.record)

    def record(self, sim):
        """Appends sim's current values (the observer; call it to add a row yourself)."""
        w = sim.walls()
        stress = [sim.wall_normal_stress(f) if self._active[f] else np.nan for f in range(6)]
        self._rows.append((sim.time, sim.energy(), w.position, w.force, np.array(stress)))

    def __len__(self):
        return len(self._rows)

    @property
    def time(self):
        return np.array([r[0] for r in self._rows], dtype=np.float64)

    @property
    def energy(self):
        return {f.name: np.array([getattr(r[1], f.name) for r in self._rows], dtype=np.float64)
                for f in fields(Energy)}

    @property
    def wall_position(self):
        return np.array([r[2] for r in self._rows], dtype=np.float64).reshape(-1, 6)

    @property
    def wall_force(self):
        return np.array([r[3] for r in self._rows], dtype=np.float64).reshape(-1, 6)

    @property
    def wall_stress(self):
        return np.array([r[4] for r in self._rows], dtype=np.float64).reshape(-1, 6)

    @property
    def active(self):
        """Which faces are walls (False on periodic axes)."""
        return self._active.copy()
