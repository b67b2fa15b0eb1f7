"""Embedded geometries, triangle surfaces and voxel images (``fcm/geom.h``, ``fcm/levelset.h``,
``fcm/surface.h``, ``fcm/voxels.h``)."""

import numpy as np

from . import _fcm
from .core import FcmObject, ElementType


class Geometry(FcmObject):
    """An embedded body: a mesh of convex cells (Tet4, or convex Hex8) the background mesh
    integrates over, with its boundary triangles. Immutable. Made by the class methods:
    procedural shapes (:meth:`box`, :meth:`ball`, :meth:`hemisphere`, :meth:`hollow_ball`,
    :meth:`tube`), files (:meth:`from_gmsh`, :meth:`from_tetgen`), a level-set function
    (:meth:`from_level_set`, any Python callable; :meth:`from_implicit`, the library's
    implicit functions and their unions, intersections, differences), voxel images (:meth:`from_voxels`),
    triangle surfaces (:meth:`from_surface`), caller arrays (:meth:`from_arrays`) and
    :meth:`transformed`.
    """

    __slots__ = ("info",)

    def __init__(self, handle, info=None):
        super().__init__(handle)
        #: What the build reported (level sets, voxels), else None.
        self.info = info

    @classmethod
    def from_arrays(cls, ctx, element_type, coords, cells):
        """A geometry of TET4 or HEX8 cells from caller arrays (copied)."""
        return cls(_fcm.mesh_create(ctx, int(element_type), coords, cells, True))

    @classmethod
    def box(cls, ctx, lo, hi, n):
        """The box [lo, hi] as n[0] x n[1] x n[2] cubes of 6 tets each."""
        return cls(_fcm.geometry_shape(ctx, "box", lo, hi, n))

    @classmethod
    def ball(cls, ctx, center, radius, n):
        """A ball (48 n^3 tets; n cubes per radius), volume converging like O(n^-2)."""
        return cls(_fcm.geometry_shape(ctx, "ball", center, float(radius), int(n)))

    @classmethod
    def hemisphere(cls, ctx, center, radius, n):
        """The half y >= center[1] of :meth:`ball`, its flat face exactly on that plane."""
        return cls(_fcm.geometry_shape(ctx, "hemisphere", center, float(radius), int(n)))

    @classmethod
    def hollow_ball(cls, ctx, center, r_in, r_out, hole_radius, n, layers):
        """A hollow ball r_in <= r <= r_out with three axis holes (0: none)."""
        return cls(_fcm.geometry_shape(ctx, "hollow_ball", center, float(r_in),
                                       float(r_out), float(hole_radius), int(n), int(layers)))

    @classmethod
    def tube(cls, ctx, center, axis, r_in, r_out, length, n_r, n_theta, n_axial):
        """A tube r_in <= r <= r_out around axis (0, 1, 2) through center."""
        return cls(_fcm.geometry_shape(ctx, "tube", center, int(axis), float(r_in),
                                       float(r_out), float(length), int(n_r), int(n_theta),
                                       int(n_axial)))

    @classmethod
    def from_gmsh(cls, ctx, path):
        """Read a Gmsh MSH file of tet4 or hex8 cells."""
        return cls(_fcm.read_file(ctx, "geometry", str(path)))

    @classmethod
    def from_tetgen(cls, ctx, node_path, ele_path):
        """Read a TetGen mesh (.node and .ele files)."""
        return cls(_fcm.read_file(ctx, "tetgen", str(node_path), str(ele_path)))

    @classmethod
    def from_level_set(cls, ctx, phi, lo, hi, n, **options):
        """The body {phi < 0} in the box [lo, hi] sampled on n cells, by marching tetrahedra.

        phi: a callable taking a point (float64 array of shape (3,)) and returning a float;
        an exception it raises stops the build and is raised here. Options (``fcm_level_set_
        options``): refinement (sub-cells per cut-cell edge, 1..64, default 4),
        estimate_error (1), refine_inside (0), max_subcells. The build's report (volume,
        error estimate, counts) is in ``.info``.
        """
        handle, info = _fcm.geometry_from_level_set(ctx, phi, lo, hi, n, options)
        return cls(handle, info)

    #: Kinds of :meth:`from_implicit` nodes (``fcm_implicit_kind``).
    IMPLICIT_KINDS = ("sphere", "torus", "box", "gyroid", "union", "intersection", "difference")

    @classmethod
    def from_implicit(cls, ctx, nodes, lo, hi, n, **options):
        """As :meth:`from_level_set` with phi a tree of the library's implicit functions,
        evaluated in C: nodes is a list of dicts, the root last, each with "kind" (one of
        IMPLICIT_KINDS) and its members (``fcm_implicit``): sphere center, radius; torus
        center, radius, minor_radius, axis; box min, max; gyroid min, max, period,
        thickness, sheet; union / intersection / difference the operand indices a, b (earlier
        nodes). Invalid trees raise fcm.Error naming the node and member."""
        tree = []
        for node in nodes:
            node = dict(node)
            kind = node.pop("kind")
            if kind not in cls.IMPLICIT_KINDS:
                raise ValueError(f"implicit kind {kind!r}: expected one of {cls.IMPLICIT_KINDS}")
            tree.append(dict(node, kind=cls.IMPLICIT_KINDS.index(kind)))
        handle, info = _fcm.geometry_from_implicit(ctx, tree, lo, hi, n, options)
        return cls(handle, info)

    @classmethod
    def from_voxels(cls, image, threshold=0.5, labels=None, merge=True):
        """The selected voxels of a :class:`VoxelImage` (value >= threshold, or equal to one
        of `labels`) as Hex8 boxes (merged greedily unless merge=False)."""
        handle, info = _fcm.geometry_from_voxels(image, float(threshold), labels, int(merge))
        return cls(handle, info)

    @classmethod
    def from_surface(cls, surface, **options):
        """A geometry from a closed triangle surface: tetrahedralized by Gmsh, or with
        volume_mesh=0 the checked, oriented surface alone (cut-cell rules from its moments).
        Options (``fcm_surface_mesh_options``): max_volume, size, quality,
        check_intersections, orient, volume_mesh."""
        return cls(_fcm.geometry_from_surface(surface, options))

    def transformed(self, A, b):
        """A copy with every node mapped by x -> A x + b (A a 3 x 3 matrix)."""
        return Geometry(_fcm.geometry_transformed(self._h, A, b))

    @property
    def summary(self):
        """Counts, type, volume and bounding box as a dict."""
        return _fcm.geometry_info(self._h)

    element_type = property(lambda self: ElementType(self.summary["element_type"]),
                            doc="TET4 or HEX8.")
    volume = property(lambda self: self.summary["volume"], doc="Sum of the cell volumes.")
    coords = property(lambda self: _fcm.geometry_array(self._h, "coords"),
                      doc="Node coordinates (n, 3), a read-only view.")
    cells = property(lambda self: _fcm.geometry_array(self._h, "cells"),
                     doc="Cell node ids (m, 4 or 8), a read-only view.")
    boundary_triangles = property(lambda self: _fcm.geometry_array(self._h, "boundary_triangles"),
                                  doc="Boundary triangles (k, 3), outward, a read-only view.")
    boundary_cells = property(lambda self: _fcm.geometry_array(self._h, "boundary_cells"),
                              doc="The cell owning each boundary triangle, a read-only view.")

    def __str__(self):
        return _fcm.text(self._h)


class Surface(FcmObject):
    """A triangle surface: an embedded body's boundary (OBJ, OFF, STL, PLY) or a cut."""

    __slots__ = ()

    @classmethod
    def from_arrays(cls, ctx, coords, triangles):
        """A surface from vertices (n, 3) and triangles (m, 3), copied."""
        return cls(_fcm.surface_create(ctx, coords, triangles))

    @classmethod
    def from_file(cls, ctx, path):
        """Read an OBJ, OFF, STL or PLY file."""
        return cls(_fcm.read_file(ctx, "surface", str(path)))

    @classmethod
    def plane(cls, ctx, point, normal, lo, hi):
        """The plane through point with normal, clipped to the box [lo, hi] (a cut)."""
        return cls(_fcm.surface_plane(ctx, point, normal, lo, hi))

    coords = property(lambda self: _fcm.surface_array(self._h, "coords"),
                      doc="Vertices (n, 3), a read-only view.")
    triangles = property(lambda self: _fcm.surface_array(self._h, "triangles"),
                         doc="Triangles (m, 3), a read-only view.")


class VoxelImage(FcmObject):
    """A voxel image: values[k, j, i] (i fastest), axis vectors (rows of a 3 x 3 matrix) and
    the centre of voxel (0, 0, 0)."""

    __slots__ = ()

    @classmethod
    def from_array(cls, ctx, values, axes=np.eye(3), origin=(0.0, 0.0, 0.0)):
        """An image from a 3-D array values[k, j, i] (copied)."""
        return cls(_fcm.voxels_create(ctx, values, np.asarray(axes, float).ravel(), origin))

    @classmethod
    def from_file(cls, ctx, path):
        """Read a NRRD (.nrrd, .nhdr) or MetaImage (.mha, .mhd) file."""
        return cls(_fcm.read_file(ctx, "voxels", str(path)))

    values = property(lambda self: _fcm.voxels_values(self._h),
                      doc="The values [k, j, i], a read-only view.")
