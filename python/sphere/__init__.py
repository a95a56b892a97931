"""sphere: DEM simulation of spheres, from Python (docs/python.md).

The package binds sphere's C++ library (host backend, float and double precision, the linear
contact law): build a sample (Settings, the set-up helpers), run a Simulation, read and write
checkpoints, and get every field as NumPy arrays. Errors of the library are sphere.Error, with
the library's message.
"""

from ._sphere import Error, __version__, gamma_n_from_restitution
from .consolidation import Consolidation, consolidate, deposited_sample, sample_contact
from .fields import Contacts, Energy, Snapshot, Walls
from .samples import bimodal_radii, deposit, fit_world, lognormal_radii, random_packing, sample_top, uniform_radii
from .settings import FACES, ContactParams, Settings, WallControl
from .simulation import MOTION_KINDS, PRECISIONS, Simulation, read_checkpoint

__all__ = [
    "FACES", "MOTION_KINDS", "PRECISIONS", "Consolidation", "ContactParams", "Contacts", "Energy", "Error", "Settings",
    "Simulation", "Snapshot", "WallControl", "Walls", "__version__", "bimodal_radii", "consolidate", "deposit",
    "deposited_sample", "fit_world", "gamma_n_from_restitution", "lognormal_radii", "random_packing", "read_checkpoint",
    "sample_top", "uniform_radii",
]
