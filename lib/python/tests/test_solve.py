"""A static and a dynamic solve (with a cut between steps) and a scene run through the
binding equal the same problems run through the C API alone (the program python_reference)
bit for bit."""

import importlib.util
import subprocess

import numpy as np
import pytest

import fcm


def c_result(reference, scratch, *args):
    out = scratch / "reference.bin"
    subprocess.run([reference, *map(str, args), str(out)], check=True)
    return np.fromfile(out, dtype=np.float64)


def example(source_dir, name):
    """A module of lib/python/examples (their set-ups are the problems compared here)."""
    path = source_dir / "lib" / "python" / "examples" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_static_bit_for_bit(ctx, reference, scratch, source_dir):
    """host_static.py's problem: an embedded ball under gravity clamped on its lower cap."""
    integ, clamp, info, rules, _, _ = example(source_dir, "host_static").solve(ctx)
    assert info["reason"] == 1  # converged
    u = integ.displacement
    assert np.array_equal(u, c_result(reference, scratch, "static"))
    # the clamp carries the weight
    force, _ = integ.reaction(clamp, boundary=True)
    weight = 1100.0 * 9.81 * rules.stats["embedded_volume"]
    assert force[2] == pytest.approx(weight, rel=0.02)


def test_dynamic_with_cut_bit_for_bit(ctx, reference, scratch, source_dir):
    """host_dynamic.py's problem: a clamped bar swinging down, cut at x = 1.1 after step 3
    (the example checks that the cut keeps the mass and momentum)."""
    lines = []
    integ, _, _, good = example(source_dir, "host_dynamic").run(ctx, 6, 3, lines.append)
    assert good and len(lines) == 7 and integ.space.num_bodies == 2
    assert np.array_equal(integ.displacement, c_result(reference, scratch, "dynamic", 6, 3))


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


def test_scene_host_loop(ctx, reference, scratch, source_dir):
    """The same steps taken one by one by the host equal the run and the C API's."""
    path = source_dir / "apps" / "scenes" / "cut_slab.json"
    sim = fcm.Simulation(ctx, fcm.Scene.from_file(ctx, path), max_steps=3)
    times = []
    while not sim.done:
        times.append(sim.step()["time"])
    assert len(times) == 3 and times == sorted(times)
    assert np.array_equal(sim.state()[0], c_result(reference, scratch, "scene", path, 3))
    with pytest.raises(fcm.Error):
        sim.step()  # the run is done
