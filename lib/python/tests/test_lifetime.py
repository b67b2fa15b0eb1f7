"""Reference counting under gc: views keep the fcm objects they read alive (also after
close()), objects keep what they were made from alive, cycles through callbacks are
collected, and once everything is gone the context has no allocation left."""

import gc
import weakref

import numpy as np

import fcm


def coords_only(ctx):
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 2, 3], [2, 2, 2])
    return mesh.coords, weakref.ref(mesh)


def test_view_outlives_its_object(ctx):
    x, ref = coords_only(ctx)
    gc.collect()
    assert ref() is None  # the Python object is gone, the view reads the C mesh
    assert ctx.live_allocations > 0
    expected = np.array([[i / 2, j, k * 1.5] for k in range(3) for j in range(3)
                         for i in range(3)])
    assert np.array_equal(x, expected)
    assert x.base is not None and not x.flags.writeable
    del x
    gc.collect()
    assert ctx.live_allocations == 0  # released with its last view


def test_view_survives_close(ctx):
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [3, 3, 3])
    ball = fcm.Geometry.ball(ctx, [0.5] * 3, 0.3, 2)
    rules = fcm.CellRules(ctx, mesh, ball)
    cells = mesh.cells.copy()
    xi, w, flags = rules.get(13)
    w_copy = w.copy()
    view = mesh.cells
    mesh.close()
    rules.close()
    del mesh, rules
    gc.collect()
    assert np.array_equal(view, cells) and np.array_equal(w, w_copy) and xi.shape == (len(w), 3)
    del view, xi, w, flags, ball
    gc.collect()
    assert ctx.live_allocations == 0


def test_objects_keep_their_inputs_alive(ctx):
    def build():
        mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [2, 2, 2])
        ball = fcm.Geometry.ball(ctx, [0.5] * 3, 0.3, 2)
        rules = fcm.CellRules(ctx, mesh, ball, kinds=fcm.RULES_STIFFNESS)
        return fcm.Space(ctx, mesh, rules)

    space = build()
    gc.collect()
    u = np.zeros(space.num_dofs)
    assert space.node_field(u).shape == (27, 3)
    space.mesh.close()  # closed for Python, but the space still uses it
    assert space.max_displacement(u) == 0.0
    del space
    gc.collect()
    assert ctx.live_allocations == 0


def test_context_closed_first():
    c = fcm.Context()
    mesh = fcm.Mesh.box(c, fcm.HEX8, [0, 0, 0], [1, 1, 1], [1, 1, 1])
    c.close()  # deferred: the mesh still lives in it
    assert mesh.num_cells == 1
    del mesh
    gc.collect()


def test_cycle_through_callback_is_collected(ctx):
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-0.6] * 3, [0.6] * 3, [2, 2, 2])
    ball = fcm.Geometry.ball(ctx, [0, 0, 0], 0.5, 2)
    rules = fcm.CellRules(ctx, mesh, ball, kinds=fcm.RULES_STIFFNESS, surface_strength=2)
    integ = fcm.Integrator(ctx, fcm.Space(ctx, mesh, rules),
                           fcm.Material(fcm.MaterialModel.LINEAR, 1e5, 0.3, 1e3),
                           kind=fcm.IntegratorKind.STATIC)
    integ.add_boundary_constraint(lambda X, n: integ is not None and X[2] < 0)
    ref = weakref.ref(integ)
    del integ, rules, mesh, ball
    gc.collect()
    assert ref() is None
    assert ctx.live_allocations == 0


def test_closed_inside_callbacks():
    """A callback that closes the objects the running call uses: the call completes on them
    (they end afterwards) and nothing reads freed memory."""
    c = fcm.Context()

    def phi(x):
        c.close()
        return float(np.linalg.norm(x)) - 0.3

    g = fcm.Geometry.from_level_set(c, phi, [-0.5] * 3, [0.5] * 3, [2, 2, 2])
    assert c.closed and g.volume > 0
    del g
    gc.collect()

    ctx = fcm.Context()
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [2, 0.5, 0.5], [4, 1, 1])
    bar = fcm.Geometry.box(ctx, [0, 0.05, 0.05], [1.8, 0.45, 0.45], [4, 1, 1])
    rules = fcm.CellRules(ctx, mesh, bar)
    integ = fcm.Integrator(ctx, fcm.Space(ctx, mesh, rules),
                           fcm.Material(fcm.MaterialModel.LINEAR, 1e6, 0.3, 1e3), dt=0.01)

    def field(x, normal):
        integ.close()
        return (0.0, 0.0, -9810.0)

    integ.add_body_force(field)
    integ.add_constraint(mesh.nodes_in_box([-1, -1, -1], [0, 1, 1], 1e-9))
    integ.setup()  # completes; the integrator ends after it
    assert integ.closed and integ._h.released
    del integ, rules, mesh, bar
    gc.collect()
    assert ctx.live_allocations == 0
