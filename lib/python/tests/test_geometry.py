"""Geometries from every source through the binding, checked by volumes known exactly:
voxel images, surface files, transformed and procedural shapes, octree backgrounds."""

import numpy as np
import pytest

import fcm


def rules_volume(ctx, mesh, geometry):
    rules = fcm.CellRules(ctx, mesh, geometry, kinds=fcm.RULES_STIFFNESS, min_fraction=0.0)
    p = rules.points()
    return np.sum(p["physical_weight"][p["flag"] == 0])


def test_voxels(ctx):
    """A 6 x 5 x 4 image with an L-shaped set of ones: the geometry's volume is the count
    times the voxel volume, and so is the volume its rules integrate."""
    values = np.zeros((4, 5, 6))  # [k, j, i]
    values[1:3, 1:4, 1:5] = 1.0
    values[1, 1, 5] = 1.0
    axes = np.diag([0.1, 0.2, 0.25])
    image = fcm.VoxelImage.from_array(ctx, values, axes, [0.05, 0.1, 0.125])
    assert np.array_equal(image.values, values)
    g = fcm.Geometry.from_voxels(image)
    count = int(values.sum())
    assert g.info["num_selected"] == count
    assert g.volume == pytest.approx(count * 0.1 * 0.2 * 0.25, rel=1e-13)
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [0.6, 1.0, 1.0], [3, 3, 3])
    assert rules_volume(ctx, mesh, g) == pytest.approx(g.volume, rel=1e-12)
    labelled = fcm.Geometry.from_voxels(image, labels=[1.0], merge=False)
    assert labelled.info["num_boxes"] == count


def test_surface_file(ctx, scratch):
    """A cube [0.2, 0.7]^3 as an OBJ file, embedded as a surface alone: volume 0.125."""
    v = [(x, y, z) for z in (0.2, 0.7) for y in (0.2, 0.7) for x in (0.2, 0.7)]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    lines = [f"v {x} {y} {z}" for x, y, z in v]
    lines += [f"f {a + 1} {b + 1} {c + 1}\nf {a + 1} {c + 1} {d + 1}" for a, b, c, d in quads]
    path = scratch / "cube.obj"
    path.write_text("\n".join(lines) + "\n")
    surface = fcm.Surface.from_file(ctx, path)
    assert surface.coords.shape == (8, 3) and surface.triangles.shape == (12, 3)
    g = fcm.Geometry.from_surface(surface, volume_mesh=0)
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [3, 3, 3])
    assert rules_volume(ctx, mesh, g) == pytest.approx(0.125, rel=1e-12)


def test_shapes_and_transform(ctx):
    ball = fcm.Geometry.ball(ctx, [0, 0, 0], 0.5, 2)
    half = fcm.Geometry.hemisphere(ctx, [0, 0, 0], 0.5, 2)
    assert half.volume == pytest.approx(ball.volume / 2, rel=1e-13)
    assert np.min(half.coords[:, 1]) == pytest.approx(0.0, abs=1e-15)
    A = np.array([[2.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.5]])  # det 1
    moved = ball.transformed(A * 1.5, [1, 2, 3])  # det 3.375
    assert moved.volume == pytest.approx(3.375 * ball.volume, rel=1e-13)
    tube = fcm.Geometry.tube(ctx, [0, 0, 0], 2, 0.3, 0.5, 1.0, 1, 24, 2)
    assert 0.9 < tube.volume / (np.pi * (0.25 - 0.09)) < 1.0  # inscribed polygons
    hollow = fcm.Geometry.hollow_ball(ctx, [0, 0, 0], 0.3, 0.5, 0.0, 4, 2)
    assert 0.9 < hollow.volume / (4 / 3 * np.pi * (0.125 - 0.027)) < 1.0
    assert len(hollow.boundary_triangles) == len(hollow.boundary_cells) > 0
    with pytest.raises(fcm.Error, match="radius"):
        fcm.Geometry.ball(ctx, [0, 0, 0], -1.0, 2)


def test_octree_background(ctx):
    """An octree refined along a ball's boundary: levels up to the asked one, and the rules on
    it integrate the ball's volume."""
    ball = fcm.Geometry.ball(ctx, [0.5] * 3, 0.3, 3)
    mesh = fcm.Mesh.octree(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [2, 2, 2], refine_level=2,
                           geometry=ball)
    assert mesh.info["is_octree"] and mesh.info["max_level"] == 2
    levels = mesh.levels
    assert levels.max() == 2 and levels.min() >= 0 and len(levels) == mesh.num_cells
    assert rules_volume(ctx, mesh, ball) == pytest.approx(ball.volume, rel=1e-12)
    coarsest = levels == levels.min()
    finer = mesh.refined(coarsest)
    assert finer.num_cells >= mesh.num_cells + 7 * np.count_nonzero(coarsest)
    assert finer.levels.min() == levels.min() + 1
    region = fcm.Mesh.octree(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [1, 1, 1], region_level=1,
                             region_lo=[0, 0, 0], region_hi=[0.1, 0.1, 0.1])
    assert region.num_cells == 8


def test_implicit_tree(ctx):
    """A sphere minus a box through its centre by the library's implicit functions: the
    volume converges to the exact one as O(h^2), and an invalid tree names the member."""
    nodes = [{"kind": "sphere", "center": [0, 0, 0], "radius": 0.4},
             {"kind": "box", "min": [0, -1, -1], "max": [1, 1, 1]},
             {"kind": "difference", "a": 0, "b": 1}]
    exact = 2 / 3 * np.pi * 0.4 ** 3  # the half x < 0
    errors = []
    for refinement in (2, 4):
        g = fcm.Geometry.from_implicit(ctx, nodes, [-0.5] * 3, [0.5] * 3, [5, 5, 5],
                                       refinement=refinement)
        assert g.info["volume"] == pytest.approx(g.volume, rel=1e-13)
        assert g.coords[:, 0].max() <= 1e-15
        errors.append(abs(g.volume - exact))
    assert errors[1] < errors[0] / 3
    with pytest.raises(fcm.Error, match="radius"):
        fcm.Geometry.from_implicit(ctx, [{"kind": "sphere", "radius": -1.0}], [-1] * 3, [1] * 3,
                                   [2, 2, 2])
    with pytest.raises(ValueError, match="implicit kind 'cone'"):
        fcm.Geometry.from_implicit(ctx, [{"kind": "cone"}], [-1] * 3, [1] * 3, [2, 2, 2])
    with pytest.raises(TypeError, match="unknown option 'radiuss'"):
        fcm.Geometry.from_implicit(ctx, [{"kind": "sphere", "radiuss": 1}], [-1] * 3, [1] * 3,
                                   [2, 2, 2])
