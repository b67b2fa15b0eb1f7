"""DOF vectors, node fields, stresses and momentum through the binding on an embedded ball,
checked against fields known exactly: an affine displacement (constant strain) and a rigid
velocity."""

import numpy as np
import pytest

import fcm

E, NU, RHO = 1e5, 0.3, 800.0


@pytest.fixture
def ball_space(ctx):
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-0.6] * 3, [0.6] * 3, [4, 4, 4])
    ball = fcm.Geometry.ball(ctx, [0.05, 0, 0], 0.5, 3)
    rules = fcm.CellRules(ctx, mesh, ball, min_fraction=0.0)
    return fcm.Space(ctx, mesh, rules), mesh, ball, rules


def affine(space, mesh, G):
    """The DOF vector of u(X) = G X at every active node."""
    first, copies = space.node_dofs()
    u = np.zeros(space.num_dofs)
    for a in np.flatnonzero(first >= 0):
        for k in range(copies[a]):
            u[first[a] + 3 * k:first[a] + 3 * k + 3] = G @ mesh.coords[a]
    return u


def test_affine_displacement_fields_and_stress(ball_space):
    space, mesh, _, rules = ball_space
    eps = 1e-4
    G = np.diag([eps, 0.0, 0.0])
    u = affine(space, mesh, G)
    first, _ = space.node_dofs()
    active = first >= 0
    assert 3 * np.count_nonzero(active) == space.num_dofs
    field = space.node_field(u)
    assert np.allclose(field[active], mesh.coords[active] @ G.T, rtol=0, atol=1e-15)
    assert np.all(field[~active] == 0)
    # a linear material: stress xx = (lambda + 2 mu) eps, yy = zz = lambda eps, no shear
    lam, mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    mat = fcm.Material(fcm.MaterialModel.LINEAR, E, NU, RHO)
    stress, von_mises, energy = space.cell_stress(mat, u)
    cls = rules.cells()["cell_class"]
    body = cls != fcm.CellClass.DROPPED
    expected = np.array([(lam + 2 * mu) * eps, lam * eps, lam * eps, 0, 0, 0])
    assert np.allclose(stress[body], expected, rtol=0, atol=1e-9 * expected[0])
    assert np.all(stress[~body] == 0)
    assert np.allclose(energy[body], 0.5 * (lam + 2 * mu) * eps ** 2, rtol=1e-9)
    assert np.allclose(von_mises[body], 2 * mu * eps, rtol=1e-9)  # sqrt(3 J2) of this state
    p = rules.points()  # the authentic stiffness points
    assert space.max_displacement(u) == pytest.approx(
        eps * np.max(np.abs(p["x"][p["flag"] == 0, 0])), rel=1e-12)


def test_rigid_velocity_momentum(ball_space):
    space, mesh, ball, _ = ball_space
    v = affine(space, mesh, np.zeros((3, 3)))
    first, copies = space.node_dofs()
    for a in np.flatnonzero(first >= 0):
        for k in range(copies[a]):
            v[first[a] + 3 * k:first[a] + 3 * k + 3] = (1.0, -2.0, 0.5)
    mass, p, L = space.momentum(RHO, np.zeros_like(v), v)
    assert mass == pytest.approx(RHO * ball.volume, rel=1e-12)
    assert p == pytest.approx(mass * np.array([1.0, -2.0, 0.5]), rel=1e-12)
    # about the origin: L = m c x v with the centroid c = (0.05, 0, 0)
    assert L == pytest.approx(np.cross([0.05 * mass, 0, 0], [1.0, -2.0, 0.5]), rel=1e-9, abs=1e-9)
    with pytest.raises(ValueError, match="expected .* values"):
        space.momentum(RHO, v[:-1], v)
