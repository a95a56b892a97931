"""Figures of sphere's results with matplotlib (the Agg backend: no display needed): the energy
budget, the walls, a shear test, a triaxial test's stress path, a uniaxial test, a rose diagram,
a porosity profile, the pore fluid's pressure and velocity profiles and its pressure solver's
convergence. Each function draws on a new matplotlib Figure, saves it to `path`
(PNG, or any format matplotlib writes, by the extension) when given, and returns the Figure.
Import it as sphere.plot (matplotlib is loaded only then)."""

import os

import numpy as np
from matplotlib.figure import Figure

from ._sphere import Error
from .fluid import Fluid
from .analysis import PorosityProfile, Rose, contact_rose, porosity_profile as _profile
from .record import Recorder
from .settings import FACES
from .shear import Shear, ShearSeries
from .simulation import Simulation
from .triaxial import Triaxial, TriaxialSeries
from .uniaxial import Uniaxial, UniaxialSeries

ENERGY_TERMS = ["kinetic", "rotational", "potential", "elastic", "dissipated_viscous", "dissipated_friction",
                "boundary_work", "total"]


def _finish(fig, path):
    if path is not None:
        fig.savefig(os.fspath(path), dpi=100)
    return fig


def _wrong(what, value, expected):
    return Error(f"sphere: plot.{what}: {type(value).__name__} given; {expected} is needed")


def energy(source, path=None):
    """The energy budget (J): with a sphere.Recorder, each term and the balance total - total[0]
    against time; with a Simulation, its current terms as bars."""
    fig = Figure(figsize=(8, 6), layout="constrained")
    if isinstance(source, Simulation):
        e = source.energy()
        ax = fig.add_subplot()
        values = [getattr(e, name) for name in ENERGY_TERMS]
        ax.bar(range(len(values)), values)
        ax.set_xticks(range(len(values)), [n.replace("_", "\n") for n in ENERGY_TERMS], fontsize=8)
        ax.set_ylabel("energy (J)")
        ax.set_title(f"energy at t = {source.time:.4g} s")
        return _finish(fig, path)
    if not isinstance(source, Recorder):
        raise _wrong("energy", source, "a sphere.Recorder or a sphere.Simulation")
    t, e = source.time, source.energy
    top, bottom = fig.subplots(2, 1, sharex=True)
    for name in ENERGY_TERMS:
        top.plot(t, e[name], label=name.replace("_", " "))
    top.set_ylabel("energy (J)")
    top.legend(fontsize=7)
    bottom.plot(t, e["total"] - e["total"][0] if len(t) else t)
    bottom.set_ylabel("total - total(0) (J)")
    bottom.set_xlabel("time (s)")
    return _finish(fig, path)


def walls(recorder, path=None):
    """The walls of a sphere.Recorder against time: positions (m), the particles' forces (N)
    and normal stresses (Pa) of every active wall face."""
    if not isinstance(recorder, Recorder):
        raise _wrong("walls", recorder, "a sphere.Recorder")
    fig = Figure(figsize=(8, 8), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    t = recorder.time
    for f in np.flatnonzero(recorder.active):
        axes[0].plot(t, recorder.wall_position[:, f], label=FACES[f])
        axes[1].plot(t, recorder.wall_force[:, f], label=FACES[f])
        axes[2].plot(t, recorder.wall_stress[:, f], label=FACES[f])
    for ax, label in zip(axes, ["position (m)", "force (N)", "normal stress (Pa)"]):
        ax.set_ylabel(label)
        ax.legend(fontsize=7)
    axes[-1].set_xlabel("time (s)")
    return _finish(fig, path)


def shear(result, path=None):
    """A shear test (a sphere.Shear or its ShearSeries) against shear strain: shear and normal
    stress (Pa), tau/sigma and dilation (m)."""
    series = result.series if isinstance(result, Shear) else result
    if not isinstance(series, ShearSeries):
        raise _wrong("shear", result, "a sphere.Shear or sphere.ShearSeries")
    fig = Figure(figsize=(8, 8), layout="constrained")
    axes = fig.subplots(3, 1, sharex=True)
    axes[0].plot(series.strain, series.shear_stress, label="shear stress tau")
    axes[0].plot(series.strain, series.normal_stress, label="normal stress sigma")
    axes[0].set_ylabel("stress (Pa)")
    axes[0].legend(fontsize=7)
    axes[1].plot(series.strain, series.friction)
    axes[1].set_ylabel("tau / sigma")
    axes[2].plot(series.strain, series.dilation)
    axes[2].set_ylabel("dilation (m)")
    axes[2].set_xlabel("shear strain")
    return _finish(fig, path)


def triaxial(result, path=None):
    """A triaxial test (a sphere.Triaxial or its TriaxialSeries): the stress path, deviatoric
    stress q against mean stress p (Pa), over both phases (the isotropic one dashed); and the
    stress ratio q/p against axial strain in the axial compression."""
    series = result.series if isinstance(result, Triaxial) else result
    if not isinstance(series, TriaxialSeries):
        raise _wrong("triaxial", result, "a sphere.Triaxial or sphere.TriaxialSeries")
    fig = Figure(figsize=(10, 5), layout="constrained")
    path_ax, ratio_ax = fig.subplots(1, 2)
    iso, axial = ~series.axial, series.axial
    path_ax.plot(series.mean_stress[iso], series.deviatoric_stress[iso], "--o", markersize=3, label="isotropic")
    path_ax.plot(series.mean_stress[axial], series.deviatoric_stress[axial], "-o", markersize=3,
                 label="axial compression")
    path_ax.set_xlabel("mean stress p (Pa)")
    path_ax.set_ylabel("deviatoric stress q (Pa)")
    path_ax.legend(fontsize=7)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = series.deviatoric_stress[axial] / series.mean_stress[axial]
    ratio_ax.plot(series.axial_strain[axial], ratio, "-o", markersize=3)
    ratio_ax.set_xlabel("axial strain")
    ratio_ax.set_ylabel("q / p")
    return _finish(fig, path)


def uniaxial(result, path=None):
    """A uniaxial test (a sphere.Uniaxial or its UniaxialSeries): axial stress (Pa) and porosity
    against axial strain."""
    series = result.series if isinstance(result, Uniaxial) else result
    if not isinstance(series, UniaxialSeries):
        raise _wrong("uniaxial", result, "a sphere.Uniaxial or sphere.UniaxialSeries")
    fig = Figure(figsize=(8, 7), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    axes[0].plot(series.axial_strain, series.axial_stress, "-o", markersize=3)
    axes[0].set_ylabel("axial stress (Pa)")
    axes[1].plot(series.axial_strain, series.porosity, "-o", markersize=3)
    axes[1].set_ylabel("porosity")
    axes[1].set_xlabel("axial strain")
    return _finish(fig, path)


def rose(source, path=None, trend_bins=36, plunge_bins=9):
    """A rose diagram: counts by trend (a polar histogram, north up, clockwise) and by plunge,
    of a sphere.Rose or of a Simulation's contact network (contact_rose)."""
    if isinstance(source, Simulation):
        source = contact_rose(source, trend_bins, plunge_bins)
    if not isinstance(source, Rose):
        raise _wrong("rose", source, "a sphere.Rose or a sphere.Simulation")
    fig = Figure(figsize=(10, 5), layout="constrained")
    polar = fig.add_subplot(1, 2, 1, projection="polar")
    polar.set_theta_zero_location("N")
    polar.set_theta_direction(-1)
    width = 2 * np.pi / len(source.trend)
    polar.bar(np.radians(source.trend_edges[:-1]) + width / 2, source.trend, width=width, edgecolor="k")
    polar.set_title("trend")
    ax = fig.add_subplot(1, 2, 2)
    ax.bar(source.plunge_edges[:-1], source.plunge, width=np.diff(source.plunge_edges), align="edge", edgecolor="k")
    ax.set_xlabel("plunge (degrees)")
    ax.set_ylabel("count")
    return _finish(fig, path)


def porosity_profile(source, path=None, slices=10):
    """Porosity against height (m) of a sphere.PorosityProfile or of a Simulation (its profile
    in `slices` slices between the walls)."""
    if isinstance(source, Simulation):
        source = _profile(source, slices)
    if not isinstance(source, PorosityProfile):
        raise _wrong("porosity_profile", source, "a sphere.PorosityProfile or a sphere.Simulation")
    fig = Figure(figsize=(5, 7), layout="constrained")
    ax = fig.add_subplot()
    z = np.column_stack([source.z_lo, source.z_hi]).ravel()
    ax.plot(np.repeat(source.porosity, 2), z)
    ax.set_xlabel("porosity")
    ax.set_ylabel("height z (m)")
    return _finish(fig, path)


def _fluid(what, fluid):
    if not isinstance(fluid, Fluid):
        raise _wrong(what, fluid, "a sphere.Fluid")
    return fluid


def fluid_pressure(fluid, path=None):
    """The pore pressure (Pa) of a sphere.Fluid against height z (m): the mean of each cell
    layer, its least and largest cell, and, when the top holds a prescribed pressure, the
    hydrostatic pressure (dashed) and the excess over it (right)."""
    p = _fluid("fluid_pressure", fluid).pressure()
    z = fluid.centres()
    hydrostatic = fluid.hydrostatic()
    fig = Figure(figsize=(9 if hydrostatic is not None else 5, 7), layout="constrained")
    axes = fig.subplots(1, 2 if hydrostatic is not None else 1, sharey=True, squeeze=False)[0]
    axes[0].plot(Fluid.profile(p), z, label="layer mean")
    axes[0].fill_betweenx(z, p.min(axis=(0, 1)), p.max(axis=(0, 1)), alpha=0.3, label="least to largest cell")
    if hydrostatic is not None:
        axes[0].plot(hydrostatic, z, "--", label="hydrostatic")
        axes[1].plot(Fluid.profile(p) - hydrostatic, z)
        axes[1].set_xlabel("excess pressure (Pa)")
    axes[0].set_xlabel("pressure (Pa)")
    axes[0].set_ylabel("height z (m)")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"pore pressure at t = {fluid.time:.4g} s")
    return _finish(fig, path)


def fluid_velocity(fluid, path=None):
    """The flow of a sphere.Fluid against height z (m): the layer means of the x, y and z
    components (m/s) of its velocity (Navier-Stokes) or Darcy flux (Darcy), and of the
    particles' mean velocity, and the layers' porosity."""
    v = _fluid("fluid_velocity", fluid).flow()
    z = fluid.centres()
    name = "fluid velocity" if fluid.model == "navier_stokes" else "Darcy flux"
    fig = Figure(figsize=(9, 7), layout="constrained")
    flow_ax, porosity_ax = fig.subplots(1, 2, sharey=True, width_ratios=[2, 1])
    mean, particles = Fluid.profile(v), Fluid.profile(fluid.particle_velocity())
    for a, axis in enumerate("xyz"):
        line, = flow_ax.plot(mean[:, a], z, label=f"{name} {axis}")
        flow_ax.plot(particles[:, a], z, ":", color=line.get_color(), label=f"particles {axis}")
    flow_ax.set_xlabel("velocity (m/s)")
    flow_ax.set_ylabel("height z (m)")
    flow_ax.legend(fontsize=7)
    porosity_ax.plot(Fluid.profile(fluid.porosity()), z)
    porosity_ax.set_xlabel("porosity")
    fig.suptitle(f"{name} at t = {fluid.time:.4g} s")
    return _finish(fig, path)


def solver_convergence(fluid, path=None):
    """The pressure solver of a sphere.Fluid against time (s): the iterations of each coupled
    step's solve (the steps this Fluid object took) and the residual it stopped at (the
    criterion's value, with the tolerance dashed; steps that did not converge marked)."""
    history = _fluid("solver_convergence", fluid).solver_history
    fig = Figure(figsize=(8, 6), layout="constrained")
    iterations_ax, residual_ax = fig.subplots(2, 1, sharex=True)
    iterations_ax.plot(history.time, history.iterations, "-o", markersize=3)
    iterations_ax.set_ylabel("iterations")
    residual_ax.semilogy(history.time, np.maximum(history.residual, np.finfo(float).tiny), "-o", markersize=3)
    failed = ~history.converged
    if failed.any():
        residual_ax.semilogy(history.time[failed], history.residual[failed], "rx", label="not converged")
        residual_ax.legend(fontsize=7)
    residual_ax.axhline(fluid.settings.tolerance, linestyle="--", color="gray")
    residual_ax.set_ylabel("residual")
    residual_ax.set_xlabel("time (s)")
    return _finish(fig, path)
