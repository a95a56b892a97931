"""A time series of a running simulation (sphere's time series of energy and walls): a
Recorder observes a Simulation every few steps and keeps the time, the energy budget, the
walls' positions and forces and their normal stresses, as NumPy arrays for analysis and for
sphere.plot."""

import os
from dataclasses import fields

import numpy as np

from . import _sphere
from .fields import Energy

# The library's names of the energy terms in the diagnostics CSV (sphere::diagnostics_columns).
_CSV_ENERGY = [("kinetic", "kinetic_J"), ("rotational", "rotational_J"), ("potential", "potential_J"),
               ("elastic", "elastic_J"), ("dissipated_viscous", "dissipated_visc_J"),
               ("dissipated_friction", "dissipated_fric_J"), ("boundary_work", "boundary_work_J"),
               ("total", "total_J")]


def write_csv(path, columns):
    """Writes `columns` (a dict of column name to equally long sequences of numbers, in column
    order; names by the project's convention name_unit, e.g. time_s) to the CSV file `path`
    atomically, as the C++ programs write theirs (sphere::csv_series: 17 significant digits;
    scripts/plot_series.py plots it). Raises sphere.Error for a bad name or unequal lengths."""
    names = list(columns)
    values = [np.asarray(columns[n], dtype=np.float64).ravel() for n in names]
    lengths = {len(v) for v in values}
    if len(lengths) > 1:
        raise _sphere.Error("sphere: write_csv: the columns have different lengths: "
                            + ", ".join(f"{n} {len(v)}" for n, v in zip(names, values)))
    rows = np.column_stack(values) if values else np.zeros((0, 0))
    _sphere.write_csv(os.fspath(path), names, rows.reshape(-1, len(names)) if names else rows)


class Recorder:
    """Records sim every `every` steps from now on (an observer; also once now when `now`):
    `time` (s), `energy` (a dict of arrays, one per sphere.Energy field, J or W), `wall_position`
    (T, 6) (m), `wall_force` (T, 6) (N, the particles' force along each axis) and `wall_stress`
    (T, 6) (Pa, compressive positive; NaN on periodic axes), `wall_velocity` (T, 6) (m/s). Arrays are
    built when read; write_csv writes them as the C++ diagnostics series."""

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
        self._rows.append((sim.time, sim.energy(), w.position, w.force, np.array(stress), w.velocity))

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
    def wall_velocity(self):
        return np.array([r[5] for r in self._rows], dtype=np.float64).reshape(-1, 6)

    def write_csv(self, path):
        """Writes the rows to the CSV file `path` (atomically) with the columns of the C++
        diagnostics series (sphere::diagnostics_series): time_s, kinetic_J, rotational_J,
        potential_J, elastic_J, dissipated_visc_J, dissipated_fric_J, boundary_work_J, total_J,
        then for each active wall face wall_<face>_position_m, wall_<face>_velocity_m/s and
        wall_<face>_force_N (faces xlo, xhi, ylo, yhi, zlo, zhi)."""
        columns = {"time_s": self.time}
        energy = self.energy
        for name, column in _CSV_ENERGY:
            columns[column] = energy[name]
        position, velocity, force = self.wall_position, self.wall_velocity, self.wall_force
        for f in np.flatnonzero(self._active):
            face = "wall_" + ("x", "y", "z")[f // 2] + ("lo", "hi")[f % 2]
            columns[face + "_position_m"] = position[:, f]
            columns[face + "_velocity_m/s"] = velocity[:, f]
            columns[face + "_force_N"] = force[:, f]
        write_csv(path, columns)

    @property
    def active(self):
        """Which faces are walls (False on periodic axes)."""
        return self._active.copy()
