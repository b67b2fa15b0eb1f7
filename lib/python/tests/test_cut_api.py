"""Simulation.cut() and Simulation.rest_positions() (fcm_simulation_cut(),
fcm_simulation_rest_positions()): a cut between steps in the reference frame gives the same
displacement bits as the same blade file as a scene's cut effect; rest positions of the body
at rest are the points themselves; refusals raise."""

import numpy as np
import pytest

import fcm

BOX = """{"version": 1, "name": "py_cut",
 "background": {"element": "hex8", "box": {"min": [-0.25, -0.25, -0.25],
  "max": [1.25, 0.75, 0.75]}, "cells": [3, 2, 2]},
 "geometry": {"shape": "box", "min": [0, 0, 0], "max": [1, 0.5, 0.5], "cells": [2, 1, 1]},
 "material": {"model": "snh", "young": 1e5, "poisson": 0.3, "density": 1000},
 "time": {"dt": 0.02, "steps": 4},
 "effects": [{"initial_velocity": {"angular_velocity": [0, 0, 4]}}%s]}"""

CUT = """, {"cut": {"time": 0.04, "surface": {"mesh": "%s"}}}"""


def blade_file(scratch):
    """A square across the body at x = 0.55, as an OBJ file."""
    path = scratch / "py_cut_blade.obj"
    path.write_text("v 0.55 -1.25 -1.25\nv 0.55 1.75 -1.25\nv 0.55 1.75 1.75\n"
                    "v 0.55 -1.25 1.75\nf 1 2 3\nf 1 3 4\n")
    return path


def rectangle(ctx, scratch):
    return fcm.Surface.from_file(ctx, blade_file(scratch))


def test_cut_between_steps_is_the_effect(ctx, scratch):
    path = blade_file(scratch)
    a = fcm.Simulation(ctx, fcm.Scene.from_string(ctx, BOX % (CUT % path), "a"))
    b = fcm.Simulation(ctx, fcm.Scene.from_string(ctx, BOX % "", "b"), host_cuts=True)
    a.run()
    b.step()
    b.step()
    info = b.cut(fcm.Surface.from_file(ctx, path))
    assert not info["missed"] and info["dofs_after"] > info["dofs_before"]
    assert info["cells_integrated"] > 0 and info["seconds"] >= info["seconds_rules"]
    b.run()
    ua, ub = a.state()[0], b.state()[0]
    assert ua.shape == ub.shape
    assert np.array_equal(ua, ub)
    # at rest, where the body is its reference, points stay where they are
    c = fcm.Simulation(ctx, fcm.Scene.from_string(ctx, BOX % "", "c"))
    x = np.array([[0.5, 0.25, 0.25], [0.9, 0.1, 0.45], [3.0, -2.0, 1.0]])
    assert np.allclose(c.rest_positions(x), x, rtol=0, atol=1e-12)
    assert c.rest_positions(np.zeros((0, 3))).shape == (0, 3)


def test_refusals(ctx, scratch):
    sim = fcm.Simulation(ctx, fcm.Scene.from_string(ctx, BOX % "", "r"))
    with pytest.raises(ValueError, match="frame"):
        sim.cut(rectangle(ctx, scratch), frame="world")
    with pytest.raises(fcm.Error, match="not finite"):
        sim.rest_positions([[0.0, float("nan"), 0.0]])
    with pytest.raises(ValueError):
        sim.rest_positions([1.0, 2.0])
    sim.cut(rectangle(ctx, scratch), frame="deformed")
    with pytest.raises(fcm.Error, match="fcm_simulation_cut"):
        sim.write_checkpoint(scratch / "py_cut.ckpt")
    assert not (scratch / "py_cut.ckpt").exists()
