"""A static and a dynamic solve (with a cut between steps) and a scene run through the
binding equal the same problems run through the C API alone (the program python_reference)
bit for bit."""

import subprocess

import numpy as np
import pytest

import fcm


def c_result(reference, scratch, *args):
    out = scratch / "reference.bin"
    subprocess.run([reference, *map(str, args), str(out)], check=True)
    return np.fromfile(out, dtype=np.float64)


def static_ball(ctx):
    """host_static's problem: an embedded ball under gravity clamped on its lower cap."""
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-0.6] * 3, [0.6] * 3, [6, 6, 6])
    ball = fcm.Geometry.ball(ctx, [0, 0, 0], 0.5, 3)
    rules = fcm.CellRules(ctx, mesh, ball, kinds=fcm.RULES_STIFFNESS, surface_strength=2)
    space = fcm.Space(ctx, mesh, rules)
    mat = fcm.Material(fcm.MaterialModel.STABLE_NEO_HOOKEAN, 2e5, 0.4, 1100.0)
    integ = fcm.Integrator(ctx, space, mat, kind=fcm.IntegratorKind.STATIC,
                           tolerance_mode=fcm.NewtonTolerance.REPRESENTATIVE, dt=1.0,
                           load_steps=2)
    integ.add_gravity([0, 0, -9.81])
    clamp = integ.add_boundary_constraint(lambda X, n: X[2] < -0.35)
    integ.setup()
    info = integ.step()
    return integ, clamp, info, rules


def test_static_bit_for_bit(ctx, reference, scratch):
    integ, clamp, info, rules = static_ball(ctx)
    assert info["reason"] == 1  # converged
    u = integ.displacement
    assert np.array_equal(u, c_result(reference, scratch, "static"))
    # the clamp carries the weight
    force, _ = integ.reaction(clamp, boundary=True)
    weight = 1100.0 * 9.81 * rules.stats["embedded_volume"]
    assert force[2] == pytest.approx(weight, rel=0.02)


def bar_with_cut(ctx, steps, cut_after):
    """host_dynamic's problem: a clamped bar swinging down, cut at x = 1.1 after a step."""
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [2, 0.5, 0.5], [8, 2, 2])
    bar = fcm.Geometry.box(ctx, [0, 0.05, 0.05], [1.8, 0.45, 0.45], [18, 4, 4])
    rules = fcm.CellRules(ctx, mesh, bar)
    space = fcm.Space(ctx, mesh, rules)
    mat = fcm.Material(fcm.MaterialModel.STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000.0)
    integ = fcm.Integrator(ctx, space, mat, dt=0.01)
    integ.add_gravity([0, 0, -9.81])
    integ.add_constraint(mesh.nodes_in_box([-1, -1, -1], [0, 1, 1], 1e-9))
    integ.setup()
    cut = fcm.Surface.from_arrays(ctx, [[1.1, -1, -1], [1.1, 2, -1], [1.1, 2, 2], [1.1, -1, 2]],
                                  [[0, 1, 2], [0, 2, 3]])
    masses = []

    def after_step(current, info):
        u, v, _, step = current.state()
        masses.append(current.space.momentum(mat.density, u, v))
        if step != cut_after:
            return None
        new_rules = current.space.rules.cut(ctx, cut)
        return current.cut(fcm.Space(ctx, mesh, new_rules))

    integ = integ.run(steps, after_step)
    return integ, masses


def test_dynamic_with_cut_bit_for_bit(ctx, reference, scratch):
    integ, masses = bar_with_cut(ctx, 6, 3)
    assert integ.space.num_bodies == 2
    assert np.array_equal(integ.displacement, c_result(reference, scratch, "dynamic", 6, 3))
    assert masses[-1][0] == pytest.approx(masses[0][0], rel=1e-10)  # the cut keeps the mass


def test_scene_bit_for_bit(ctx, reference, scratch, source_dir):
    path = source_dir / "apps" / "scenes" / "cut_slab.json"
    sim = fcm.Simulation(ctx, fcm.Scene.from_file(ctx, path), max_steps=3)
    seen = []
    assert sim.run(lambda step, n, info: seen.append((step, n, info["newton_iterations"])))
    assert [s[0] for s in seen] == [1, 2, 3] and all(s[1] == 3 for s in seen)
    u, v, t, node_u = sim.state()
    assert np.array_equal(u, c_result(reference, scratch, "scene", path, 3))
    log = sim.log()
    assert list(log["step"]) == [1, 2, 3]
    assert np.all(np.diff(log["time"]) > 0) and np.all(np.isfinite(log["mass"]))
