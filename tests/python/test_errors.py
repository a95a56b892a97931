"""Bad input: the library's sphere::error reaches Python as sphere.Error with its message."""

import re

import numpy as np
import pytest

import sphere
from conftest import linear_settings


def refused(message, call, *args, **kw):
    """Checks that call(*args, **kw) raises sphere.Error whose message starts with `message`."""
    with pytest.raises(sphere.Error, match="^" + re.escape(message)):
        call(*args, **kw)


def test_bad_particles(precision):
    s = linear_settings()
    refused("sphere: particle 1: radius = -0.25 m must be positive and finite", sphere.Simulation, s,
            [[0.2, 0.2, 0.2], [0.5, 0.5, 0.5]], [0.01, -0.25], 2500, precision=precision)
    refused("sphere: particle 0: position[2] = 1.5 m lies outside the world [0, 1] m on a wall axis", sphere.Simulation,
            s, [[0.5, 0.5, 1.5]], 0.01, 2500, precision=precision)
    refused("sphere: positions has shape (2, 2); (N, 3) is needed", sphere.Simulation, s, [[0.5, 0.5], [0.2, 0.2]],
            0.01, 2500, precision=precision)
    refused("sphere: radii has shape (3,); (2,) is needed", sphere.Simulation, s, np.full((2, 3), 0.5),
            [0.01, 0.01, 0.01], 2500, precision=precision)
    refused("sphere: velocities has shape (3,); (1, 3) is needed", sphere.Simulation, s, [[0.5, 0.5, 0.5]], 0.01, 2500,
            velocities=[1, 0, 0], precision=precision)
    refused("sphere: kinds[0] = 'stuck': not one of 'free', 'prescribed', 'fixed', 'prescribed_horizontal'",
            sphere.Simulation, s, [[0.5, 0.5, 0.5]], 0.01, 2500, kinds=["stuck"], precision=precision)
    refused("sphere: no particles: a simulation needs at least one", sphere.Simulation, s, np.zeros((0, 3)), 0.01, 2500,
            precision=precision)
    refused("sphere: particles 0 and 1 have the same centre", sphere.Simulation, s, [[0.5, 0.5, 0.5]] * 2, 0.01, 2500,
            precision=precision)


def test_bad_settings(precision):
    def build(s):
        return sphere.Simulation(s, [[0.5, 0.5, 0.5]], 0.01, 2500, precision=precision)

    refused("sphere: settings.boundary[0] = 'walls': not one of 'wall', 'periodic'", build,
            linear_settings(boundary=("walls", "wall", "wall")))
    refused("sphere: settings.contact.k_n = 0 N/m: must be positive and finite", build, sphere.Settings())
    refused("sphere: settings.box: axis 1 spans [0, 0] m; it must be finite with hi > lo", build,
            linear_settings(hi=(1, 0, 1)))
    refused("sphere: settings.dt = 1 s exceeds the stable bound", build, linear_settings(dt=1.0))
    refused("sphere: settings.gravity = 'down': three numbers (x, y, z) are needed", build,
            linear_settings(gravity="down"))
    refused("sphere: settings.skin = 'wide': not a number", build, linear_settings(skin="wide"))
    viscous = linear_settings()
    viscous.contact.damping = "viscous"
    refused("sphere: settings.contact.damping = 'viscous': not one of 'absolute', 'mass_scaled', 'damping_ratio'",
            build, viscous)
    stress_without_mass = linear_settings()
    stress_without_mass.walls[5] = sphere.WallControl(mode="stress", stress=1e3)
    refused("sphere: settings.walls[5].mass = 0 kg: a stress-controlled wall needs a positive, finite mass", build,
            stress_without_mass)
    refused("sphere: precision = 'half': not one of 'float', 'double'", sphere.Simulation, linear_settings(),
            [[0.5, 0.5, 0.5]], 0.01, 2500, precision="half")


def test_bad_calls(precision):
    s = linear_settings()
    sim = sphere.Simulation(s, [[0.5, 0.5, 0.5]], 0.01, 2500, precision=precision)
    refused("sphere: observer interval 0: must be at least 1 step", sim.add_observer, 0, print)
    refused("sphere: settings.walls[5].mass = 0 kg", sim.set_wall_control, "z+", sphere.WallControl(mode="stress"))
    refused("sphere: face 'top': not one of 'x-', 'x+', 'y-', 'y+', 'z-', 'z+' or an index 0 to 5", sim.set_wall_control,
            "top", sphere.WallControl())
    refused("sphere: set_wall_control: face 6 out of range [0, 6)", sim.set_wall_control, 6, sphere.WallControl())
    refused("sphere: set_wall_position: particle 0 at 0.5 m on axis 2 would lie outside face 5 at 0.375 m",
            sim.set_wall_position, 5, 0.375)
    refused("sphere: set_velocity: particle index 3 out of range (1 particles)", sim.set_velocity, 3, (0, 0, 0))
    refused("sphere: deposit: settings.gravity is zero; deposition needs gravity", sphere.deposit, sim, 1e-6, 100)
    refused("sphere: uniform radii: [r_min, r_max] = [0.5, 0.25] m must be finite with 0 < r_min <= r_max",
            sphere.uniform_radii, 10, 0.5, 0.25, 1, precision=precision)
