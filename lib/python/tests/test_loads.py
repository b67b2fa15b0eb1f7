"""Loads given by Python callables (body forces, tractions, time scales) and contact planes
through the binding, checked by equilibrium and linearity."""

import numpy as np
import pytest

import fcm

RHO, G = 1100.0, 9.81


def clamped_ball(ctx, model=fcm.MaterialModel.LINEAR):
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-0.6] * 3, [0.6] * 3, [4, 4, 4])
    ball = fcm.Geometry.ball(ctx, [0, 0, 0], 0.5, 2)
    rules = fcm.CellRules(ctx, mesh, ball, kinds=fcm.RULES_STIFFNESS, surface_strength=2)
    mat = fcm.Material(model, 2e6, 0.3, RHO)
    integ = fcm.Integrator(ctx, fcm.Space(ctx, mesh, rules), mat, kind=fcm.IntegratorKind.STATIC,
                           tolerance_mode=fcm.NewtonTolerance.RELATIVE, newton_tolerance=1e-10)
    clamp = integ.add_boundary_constraint(lambda X, n: X[2] < -0.35)
    return integ, clamp, rules


def solve(integ):
    integ.setup()
    info = integ.step()
    assert info["reason"] == 1
    return integ.displacement


def test_body_force_equals_gravity(ctx):
    a, _, _ = clamped_ball(ctx)
    a.add_gravity([0, 0, -G])
    b, _, _ = clamped_ball(ctx)
    calls = []

    def field(x, normal):
        calls.append(normal)
        return (0.0, 0.0, -RHO * G)

    b.add_body_force(field)
    ua, ub = solve(a), solve(b)
    assert calls and all(n is None for n in calls)
    assert np.allclose(ub, ua, rtol=0, atol=1e-12 * np.abs(ua).max())


def test_scale_is_linear(ctx):
    full, _, _ = clamped_ball(ctx)
    full.add_gravity([0, 0, -G])
    half, _, _ = clamped_ball(ctx)
    half.add_gravity([0, 0, -G], scale=lambda t: 0.5)
    uf, uh = solve(full), solve(half)
    assert np.allclose(2 * uh, uf, rtol=0, atol=1e-9 * np.abs(uf).max())


def test_traction_in_equilibrium(ctx):
    """A traction on the upper cap is carried by the clamp: reaction + applied force = 0."""
    integ, clamp, rules = clamped_ball(ctx)
    t = np.array([0.0, 300.0, -1000.0])
    integ.add_traction(lambda x, n: t if x[2] > 0.3 else (0.0, 0.0, 0.0))
    solve(integ)
    s = rules.surface_points()
    applied = t * np.sum(s["weight"][s["x"][:, 2] > 0.3])
    force, _ = integ.reaction(clamp, boundary=True)
    assert np.allclose(np.array(force) + applied, 0, atol=1e-6 * np.abs(applied).max())


def test_field_exception_propagates(ctx):
    integ, _, _ = clamped_ball(ctx)

    def field(x, normal):
        raise LookupError("no field here")

    integ.add_body_force(field)
    with pytest.raises(LookupError, match="no field here"):
        integ.setup()
    integ, _, _ = clamped_ball(ctx)
    integ.add_traction(lambda x, n: (1.0, 2.0))
    with pytest.raises(ValueError, match="expected 3 numbers, got 2"):
        integ.setup()


def test_contact_plane(ctx):
    """A ball above a floor: after setup the smallest distance is the gap (up to the surface
    points' spacing) and the barrier exerts no force beyond its threshold."""
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-0.6, -0.6, -0.2], [0.6, 0.6, 1.0], [4, 4, 4])
    ball = fcm.Geometry.ball(ctx, [0, 0, 0.4], 0.3, 2)
    rules = fcm.CellRules(ctx, mesh, ball, surface_strength=2)
    integ = fcm.Integrator(ctx, fcm.Space(ctx, mesh, rules),
                           fcm.Material(fcm.MaterialModel.STABLE_NEO_HOOKEAN, 1e5, 0.3, 1000.0),
                           dt=0.01)
    floor = integ.add_contact_plane([0, 0, 0], [0, 0, 1], distance=0.02)
    integ.setup()
    info = integ.contact_info(floor)
    assert info["distance"] == 0.02 and info["stiffness"] > 0
    assert 0.1 <= info["min_distance"] < 0.1 + 0.05
    assert info["force"] == (0.0, 0.0, 0.0)
    with pytest.raises(fcm.Error):
        integ.contact_info(5)
