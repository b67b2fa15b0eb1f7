"""Misuse raises clear Python errors and never crashes: wrong types, dtypes and shapes
(TypeError / ValueError before the library is called), closed objects, the library's own
errors as fcm.Error with status and message, and exceptions of Python callbacks."""

import numpy as np
import pytest

import fcm


def test_wrong_dtype_and_shape(ctx):
    with pytest.raises(TypeError, match="coords: dtype complex128"):
        fcm.Mesh.from_arrays(ctx, fcm.TET4, np.zeros((4, 3), complex), [[0, 1, 2, 3]])
    with pytest.raises(TypeError, match="cells: dtype float64"):
        fcm.Mesh.from_arrays(ctx, fcm.TET4, np.eye(4, 3), [[0.0, 1.0, 2.0, 3.0]])
    with pytest.raises(ValueError, match=r"coords: expected shape \(n, 3\), got \(4, 2\)"):
        fcm.Mesh.from_arrays(ctx, fcm.TET4, np.zeros((4, 2)), [[0, 1, 2, 3]])
    with pytest.raises(ValueError, match="cells: expected shape"):
        fcm.Mesh.from_arrays(ctx, fcm.HEX8, np.zeros((4, 3)), [[0, 1, 2, 3]])
    with pytest.raises(ValueError, match="lo: expected 3 numbers, got 2"):
        fcm.Mesh.box(ctx, fcm.HEX8, [0, 0], [1, 1, 1], [1, 1, 1])
    with pytest.raises(ValueError, match="element type 7 out of range"):
        fcm.Mesh.box(ctx, 7, [0, 0, 0], [1, 1, 1], [1, 1, 1])
    with pytest.raises(TypeError, match="n: dtype float64"):
        fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [1.5, 1, 1])
    # int32 converts without loss
    mesh = fcm.Mesh.from_arrays(ctx, fcm.TET4, np.eye(4, 3), np.array([[0, 1, 2, 3]], np.int32))
    assert mesh.num_cells == 1


def test_wrong_objects_and_options(ctx):
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [2, 2, 2])
    ball = fcm.Geometry.ball(ctx, [0.5] * 3, 0.3, 2)
    with pytest.raises(TypeError, match="expected an fcm Geometry, got an fcm Mesh"):
        fcm.CellRules(ctx, mesh, mesh)
    with pytest.raises(TypeError, match="expected an fcm Mesh, got str"):
        fcm.CellRules(ctx, "mesh", ball)
    with pytest.raises(TypeError, match="unknown option 'strenght'"):
        fcm.CellRules(ctx, mesh, ball, strenght=3)
    with pytest.raises(TypeError, match="option surface_strength: expected an integer"):
        fcm.CellRules(ctx, mesh, ball, surface_strength=2.5)
    with pytest.raises(ValueError, match="option strength takes 2 values"):
        fcm.CellRules(ctx, mesh, ball, strength=[1, 2, 3])
    with pytest.raises(ValueError, match="num_threads = 0"):
        fcm.Context(num_threads=0)


def test_library_errors_carry_status_and_message(ctx):
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [2, 2, 2])
    ball = fcm.Geometry.ball(ctx, [0.5] * 3, 0.3, 2)
    with pytest.raises(fcm.Error) as e:
        fcm.CellRules(ctx, mesh, ball, strength=50)
    assert e.value.status == fcm.Status.ERR_ARG and e.value.status_name == "invalid argument"
    assert "strength = 50" in str(e.value) and isinstance(e.value, RuntimeError)
    with pytest.raises(fcm.Error) as e:
        fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [0, 1, 1], [1, 1, 1])
    assert e.value.status == fcm.Status.ERR_ARG
    with pytest.raises(fcm.Error) as e:
        fcm.Surface.from_file(ctx, "/nonexistent/file.obj")
    assert e.value.status == fcm.Status.ERR_IO and "/nonexistent/file.obj" in str(e.value)
    with pytest.raises(fcm.Error) as e:
        fcm.Scene.from_string(ctx, '{"time": {"dt": -1}}', "bad.json")
    assert e.value.status in (fcm.Status.ERR_ARG, fcm.Status.ERR_FORMAT)
    assert "bad.json" in str(e.value)
    rules = fcm.CellRules(ctx, mesh, ball, kinds=fcm.RULES_STIFFNESS)
    with pytest.raises(fcm.Error, match="mass"):
        rules.get(0, fcm.MASS)  # a kind that was not built
    with pytest.raises(fcm.Error):
        rules.get(rules.num_cells, fcm.STIFFNESS)  # out of range
    with pytest.raises(ValueError, match="rule kind 5"):
        rules.get(0, 5)
    # the context is usable after errors, and nothing leaked
    assert fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [1, 1, 1]).num_cells == 1


def test_closed_objects_refuse_calls(ctx):
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [2, 2, 2])
    mesh.close()
    mesh.close()  # idempotent
    assert mesh.closed
    with pytest.raises(ValueError, match="the Mesh is closed"):
        mesh.num_cells
    with pytest.raises(ValueError, match="the Mesh is closed"):
        fcm.CellRules(ctx, mesh, fcm.Geometry.ball(ctx, [0.5] * 3, 0.3, 2))
    with fcm.Geometry.ball(ctx, [0.5] * 3, 0.3, 2) as ball:
        pass
    with pytest.raises(ValueError, match="closed"):
        ball.volume


def test_level_set_exception_propagates(ctx):
    calls = []

    def phi(x):
        calls.append(1)
        if len(calls) == 5:
            raise KeyError("phi failed")
        return float(np.linalg.norm(x)) - 0.3

    with pytest.raises(KeyError, match="phi failed"):
        fcm.Geometry.from_level_set(ctx, phi, [-0.5] * 3, [0.5] * 3, [2, 2, 2])
    assert len(calls) == 5  # not called again after the exception
    with pytest.raises(TypeError, match="must be real number|float"):
        fcm.Geometry.from_level_set(ctx, lambda x: "no", [-0.5] * 3, [0.5] * 3, [2, 2, 2])
    with pytest.raises(TypeError, match="expected a callable"):
        fcm.Geometry.from_level_set(ctx, 3.0, [-0.5] * 3, [0.5] * 3, [2, 2, 2])
    with pytest.raises(fcm.Error) as e:  # not finite: the library's own error
        fcm.Geometry.from_level_set(ctx, lambda x: float("nan"), [-0.5] * 3, [0.5] * 3, [2] * 3)
    assert e.value.status == fcm.Status.ERR_GEOMETRY


def test_callback_exceptions_propagate(ctx, source_dir):
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-0.6] * 3, [0.6] * 3, [3, 3, 3])
    ball = fcm.Geometry.ball(ctx, [0, 0, 0], 0.5, 2)
    rules = fcm.CellRules(ctx, mesh, ball, kinds=fcm.RULES_STIFFNESS, surface_strength=2)
    mat = fcm.Material(fcm.MaterialModel.LINEAR, 1e5, 0.3, 1000.0)
    integ = fcm.Integrator(ctx, fcm.Space(ctx, mesh, rules), mat, kind=fcm.IntegratorKind.STATIC)

    def select(X, normal):
        raise ZeroDivisionError("selector failed")

    integ.add_boundary_constraint(select)
    with pytest.raises(ZeroDivisionError, match="selector failed"):
        integ.setup()
    # a monitor's exception stops the run after that step and is raised
    scene = fcm.Scene.from_file(ctx, source_dir / "apps" / "scenes" / "cut_slab.json")
    sim = fcm.Simulation(ctx, scene, max_steps=3)

    def monitor(step, n, info):
        if step == 2:
            raise OverflowError("monitor failed")

    with pytest.raises(OverflowError, match="monitor failed"):
        sim.run(monitor)
    assert sim.step_count == 2
    assert sim.run(lambda step, n, info: False) is False  # False stops
    assert sim.step_count == 3
