"""Exactness of cut-cell rules through the binding: monomials over embedded polyhedra whose
integrals are known in closed form, the divergence theorem on surface rules, and the views
against the gathered copies."""

import itertools

import numpy as np
import pytest

import fcm


def box_moment(lo, hi, a):
    """The integral of x^a0 y^a1 z^a2 over the box [lo, hi]."""
    return np.prod([(hi[d] ** (a[d] + 1) - lo[d] ** (a[d] + 1)) / (a[d] + 1) for d in range(3)])


def authentic(p):
    keep = p["flag"] == 0
    return p["x"][keep], p["physical_weight"][keep]


@pytest.mark.parametrize("element", [fcm.HEX8, fcm.TET4, fcm.HEX20])
def test_box_monomials_exact(ctx, element):
    """A box embedded off the grid lines: every monomial up to the rule's strength integrates
    to its closed form to 1e-12 (relative to the largest monomial's magnitude)."""
    lo, hi = np.array([0.13, 0.21, 0.07]), np.array([0.71, 0.93, 0.66])
    mesh = fcm.Mesh.box(ctx, element, [0, 0, 0], [1, 1, 1], [3, 3, 3])
    body = fcm.Geometry.box(ctx, lo, hi, [2, 3, 2])
    rules = fcm.CellRules(ctx, mesh, body, kinds=fcm.RULES_STIFFNESS)
    strength = rules.info["strength"][fcm.STIFFNESS]
    assert strength >= 2
    assert rules.stats["num_cut"] > 0
    x, w = authentic(rules.points(fcm.STIFFNESS))
    for a in itertools.product(range(strength + 1), repeat=3):
        if sum(a) > strength:
            continue
        got = np.sum(w * x[:, 0] ** a[0] * x[:, 1] ** a[1] * x[:, 2] ** a[2])
        assert got == pytest.approx(box_moment(lo, hi, a), rel=1e-12, abs=1e-14), a


def test_hex8_mass_on_q2(ctx):
    """Hex8's cut-cell mass rules are exact on Q2 (degree <= 2 in each variable, x^2 y^2 z^2
    included) by default, and the whole P6 with axis_degree 6; info reports the caps."""
    lo, hi = np.array([0.13, 0.21, 0.07]), np.array([0.71, 0.93, 0.66])
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [3, 3, 3])
    body = fcm.Geometry.box(ctx, lo, hi, [2, 3, 2])
    q2 = fcm.CellRules(ctx, mesh, body, kinds=fcm.RULES_MASS)
    assert q2.info["strength"][fcm.MASS] == 6 and q2.info["axis_degree"][fcm.MASS] == 2
    p6 = fcm.CellRules(ctx, mesh, body, kinds=fcm.RULES_MASS, axis_degree=[fcm.DEFAULT, 6])
    assert p6.info["axis_degree"][fcm.MASS] == 6
    for rules, cap in ((q2, 2), (p6, 6)):
        x, w = authentic(rules.points(fcm.MASS))
        for a in itertools.product(range(7), repeat=3):
            if sum(a) > 6 or max(a) > cap:
                continue
            got = np.sum(w * x[:, 0] ** a[0] * x[:, 1] ** a[1] * x[:, 2] ** a[2])
            assert got == pytest.approx(box_moment(lo, hi, a), rel=1e-12, abs=1e-14), (cap, a)
    assert len(q2.points(fcm.MASS)["weight"]) < len(p6.points(fcm.MASS)["weight"])


def test_hex8_stiffness_on_mass_space(ctx):
    """With stiffness_on_mass_space the cut cells' stiffness rules are fitted on Q2 (where the
    trilinear gradients' products lie): exact there; by default fewer points, exact on P2 only
    (the control misses Q2's moments)."""
    lo, hi = np.array([0.13, 0.21, 0.07]), np.array([0.71, 0.93, 0.66])
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [3, 3, 3])
    body = fcm.Geometry.box(ctx, lo, hi, [2, 3, 2])
    one = fcm.CellRules(ctx, mesh, body, stiffness_on_mass_space=1)
    two = fcm.CellRules(ctx, mesh, body)
    errors = []
    for rules in (one, two):
        x, w = authentic(rules.points(fcm.STIFFNESS))
        err = 0.0
        for a in ((2, 2, 2), (2, 1, 2), (0, 2, 2), (2, 2, 0)):  # in Q2, not in P2
            exact = box_moment(lo, hi, a)
            got = np.sum(w * x[:, 0] ** a[0] * x[:, 1] ** a[1] * x[:, 2] ** a[2])
            err = max(err, abs(got - exact) / abs(exact))
        errors.append(err)
    assert errors[0] < 1e-12 and errors[1] > 1e-6, errors
    assert len(two.points(fcm.STIFFNESS)["weight"]) < len(one.points(fcm.STIFFNESS)["weight"])


def test_ball_volume_centroid_and_surface(ctx):
    """The faceted ball: the rules' volume is the polyhedron's, its centroid the centre; the
    surface rules satisfy the divergence theorem: sum w n = 0 and sum w (x . n) = 3 V."""
    c = np.array([0.02, -0.03, 0.05])
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-1, -1, -1], [1, 1, 1], [5, 5, 5])
    ball = fcm.Geometry.ball(ctx, c, 0.7, 3)
    V = ball.volume
    dropping = fcm.CellRules(ctx, mesh, ball)  # cells under min_fraction 1e-4 are dropped
    _, w = authentic(dropping.points(fcm.MASS))
    dropped = dropping.stats["dropped_volume"]
    assert dropped > 0 and np.sum(w) == pytest.approx(V - dropped, rel=1e-12)
    rules = fcm.CellRules(ctx, mesh, ball, surface_strength=2, min_fraction=0.0)
    x, w = authentic(rules.points(fcm.MASS))
    assert np.sum(w) == pytest.approx(V, rel=1e-12)
    assert np.sum(w[:, None] * x, axis=0) / V == pytest.approx(c, abs=1e-12)
    s = rules.surface_points()
    n = s["normal"]
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    assert np.abs(np.sum(s["weight"][:, None] * n, axis=0)).max() < 1e-12
    assert np.sum(s["weight"] * np.sum(s["x"] * n, axis=1)) == pytest.approx(3 * V, rel=1e-12)


def test_level_set_callable_matches_geometry(ctx):
    """A Python phi: the rules integrate the marched body's volume exactly, and the volume
    converges to the sphere's as the marching refines (O(h^2): the error falls by > 3 per
    halving)."""
    r = 0.4
    phi = lambda x: float(np.linalg.norm(x)) - r
    errors = []
    for refinement in (2, 4):
        g = fcm.Geometry.from_level_set(ctx, phi, [-0.5] * 3, [0.5] * 3, [4, 4, 4],
                                        refinement=refinement, estimate_error=0)
        assert g.info["volume"] == pytest.approx(g.volume, rel=1e-13)
        errors.append(abs(g.volume - 4 / 3 * np.pi * r ** 3))
        if refinement == 4:
            mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-0.5] * 3, [0.5] * 3, [4, 4, 4])
            rules = fcm.CellRules(ctx, mesh, g, kinds=fcm.RULES_STIFFNESS)
            _, w = authentic(rules.points())
            assert np.sum(w) == pytest.approx(g.volume, rel=1e-12)
    assert errors[1] < errors[0] / 3


def test_views_match_gather_and_options(ctx):
    """get() of each cell (views) gives the gathered points; the options round-trip."""
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [2, 2, 2])
    ball = fcm.Geometry.ball(ctx, [0.5, 0.5, 0.5], 0.35, 2)
    rules = fcm.CellRules(ctx, mesh, ball, strength=[3, 4], simplify=fcm.Simplify.OFF,
                          stabilization_mode=fcm.StabilizationMode.OFF)
    assert rules.info["strength"] == (3, 4)
    g = rules.points(fcm.MASS)
    k = 0
    for cell in range(rules.num_cells):
        xi, w, flag = rules.get(cell, fcm.MASS)
        assert not xi.flags.writeable
        n = len(w)
        assert np.array_equal(xi, g["xi"][k:k + n]) and np.array_equal(w, g["weight"][k:k + n])
        assert not flag.any()  # stabilization off
        k += n
    assert k == len(g["weight"])
    d = fcm.CellRules.defaults()
    assert d["simplify"] == fcm.Simplify.ON and d["kinds"] == fcm.RULES_ALL
    cells = rules.cells()
    assert set(np.unique(cells["cell_class"])) <= {0, 1, 2}
    assert np.all((cells["volume_fraction"] >= 0) & (cells["volume_fraction"] <= 1))
    assert "cut" in str(rules)


def test_cut_splits_pieces(ctx):
    """A plane cut through a bar: more pieces than cells, the piece volumes sum to the body's,
    each piece's rule integrates its own volume."""
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [2, 0.5, 0.5], [8, 2, 2])
    bar = fcm.Geometry.box(ctx, [0, 0.05, 0.05], [1.8, 0.45, 0.45], [18, 4, 4])
    rules = fcm.CellRules(ctx, mesh, bar)
    cut = fcm.Surface.from_arrays(ctx, [[1.1, -1, -1], [1.1, 2, -1], [1.1, 2, 2], [1.1, -1, 2]],
                                  [[0, 1, 2], [0, 2, 3]])
    cut_rules = rules.cut(ctx, cut)
    assert cut_rules.info["num_cuts"] == 1
    assert cut_rules.info["num_pieces"] > rules.info["num_pieces"]
    cells = cut_rules.cells()
    assert np.sum(cells["piece_volume"]) == pytest.approx(bar.volume, rel=1e-12)
    mesh_x = mesh.coords
    for p in range(cut_rules.info["num_pieces"]):
        xi, w, flag = cut_rules.get_piece(p)
        cell = cells["piece_cell"][p]
        if len(w) == 0:
            continue
        # Hex8 cells of the box grid are affine: det J = |K| / 8
        X = mesh_x[mesh.cells[cell]]
        detJ = np.prod(X.max(axis=0) - X.min(axis=0)) / 8
        assert np.sum(w[flag == 0]) * detJ == pytest.approx(cells["piece_volume"][p], rel=1e-11)
