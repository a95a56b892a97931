"""sphere: DEM simulation of spheres, from Python (docs/python.md).

The package binds sphere's C++ library (host backend, float and double precision, the linear
contact law): build a sample (Settings, the set-up helpers), run a Simulation, read and write
checkpoints, and get every field as NumPy arrays; couple the pore fluid (Fluid, its grid's
fields as arrays); the consolidation, shear, uniaxial and
triaxial examples as calls (consolidate, shear, uniaxial, triaxial), the sphere program
(run_program, status, read_output), the analyses (porosity, stresses, force chains, roses, shear
strain), time series (Recorder), figures (sphere.plot, with matplotlib: fluid profiles and the
pressure solver's convergence among them), pictures of the
particles (Simulation.render) and films of them (film, with ffmpeg). Errors of the library are sphere.Error, with the
library's message.
"""

from ._sphere import Error, __version__, gamma_n_from_restitution
from .analysis import (ForceChains, PorosityProfile, Rose, ShearTracker, contact_counts, contact_rose, coordination,
                       force_chains, orientations, porosity, porosity_profile, rose, stress_tensor, void_ratio,
                       volume_between_walls, wall_stresses)
from .consolidation import Consolidation, consolidate
from .fields import Contacts, Energy, Snapshot, Walls
from .film import film
from .fluid import Fluid, SolverHistory
from .granular import deposited_sample, frictional_wall_contact, sample_contact, saved_sample
from .program import ProgramRun, Status, find_program, outputs, read_output, run_program, status
from .record import Recorder, write_csv
from .samples import (bimodal_radii, cubic_lattice, deposit, fit_world, jittered_lattice, lognormal_radii,
                      random_packing, sample_top, uniform_radii)
from .settings import FACES, ContactParams, FluidBoundary, FluidSettings, Settings, WallControl
from .shear import Shear, ShearSeries, shear
from .simulation import MOTION_KINDS, PRECISIONS, Simulation, read_checkpoint
from .triaxial import Triaxial, TriaxialSeries, triaxial
from .uniaxial import Uniaxial, UniaxialSeries, uniaxial

__all__ = [
    "__version__", "bimodal_radii", "consolidate", "Consolidation", "contact_counts", "contact_rose", "ContactParams",
    "Contacts", "coordination", "cubic_lattice", "deposit", "deposited_sample", "Energy", "Error", "FACES", "film", "find_program",
    "fit_world", "Fluid", "FluidBoundary", "FluidSettings", "force_chains", "frictional_wall_contact", "ForceChains", "gamma_n_from_restitution", "jittered_lattice",
    "lognormal_radii", "MOTION_KINDS",
    "orientations", "outputs", "porosity", "porosity_profile", "PorosityProfile", "PRECISIONS", "ProgramRun",
    "random_packing", "read_checkpoint", "read_output", "Recorder", "Rose", "rose", "run_program", "sample_contact",
    "sample_top", "saved_sample", "Settings", "Shear", "shear", "ShearSeries", "ShearTracker", "Simulation",
    "Snapshot", "SolverHistory", "Status", "status", "stress_tensor", "uniform_radii", "void_ratio", "volume_between_walls",
    "wall_stresses", "WallControl", "Walls", "write_csv", "Triaxial", "TriaxialSeries", "triaxial", "Uniaxial", "UniaxialSeries",
    "uniaxial",
]


def __getattr__(name):
    """sphere.plot, imported on first use (it loads matplotlib)."""
    if name == "plot":
        import importlib

        return importlib.import_module(".plot", __name__)
    raise AttributeError(f"module 'sphere' has no attribute {name!r}")
