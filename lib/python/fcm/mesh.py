"""Background meshes (``fcm/mesh.h``)."""

import numpy as np

from . import _fcm
from .core import FcmObject, ElementType


class Mesh(FcmObject):
    """A background mesh of one element type: nodes (n, 3) and cells (m, nodes_per_cell) in
    VTK node order, with face adjacency and boundary faces. Immutable; made by the class
    methods :meth:`box`, :meth:`octree`, :meth:`from_arrays`, :meth:`from_gmsh` and
    :meth:`refined`. Arrays are read-only views that keep the mesh alive.
    """

    __slots__ = ()

    @classmethod
    def from_arrays(cls, ctx, element_type, coords, cells):
        """A mesh from caller arrays (copied): coords (n, 3) float, cells (m, npc) int node
        ids in VTK order. Raises fcm.Error for ids out of range, repeated nodes, a face shared
        by more than two cells."""
        return cls(_fcm.mesh_create(ctx, int(element_type), coords, cells, False))

    @classmethod
    def box(cls, ctx, element_type, lo, hi, n):
        """A structured grid of n[0] x n[1] x n[2] cubes over the box [lo, hi]: one hexahedron
        per cube (HEX8, HEX20) or six tetrahedra (TET4, TET10, Kuhn split). Grid corner (i, j,
        k) is node i + (n0+1)(j + (n1+1)k); cube (i, j, k) is cell i + n0 (j + n1 k)."""
        return cls(_fcm.mesh_box(ctx, int(element_type), lo, hi, n))

    @classmethod
    def octree(cls, ctx, element_type, lo, hi, n, region_level=0, region_lo=None,
               region_hi=None, refine_level=0, geometry=None):
        """An octree background (HEX8 or HEX20): the box grid with cells split into eight
        where they meet the box [region_lo, region_hi] (down to region_level) or the boundary
        of `geometry` (down to refine_level), balanced 2:1; hanging nodes join the levels."""
        return cls(_fcm.mesh_octree(ctx, int(element_type), lo, hi, n, int(region_level),
                                    region_lo, region_hi, int(refine_level),
                                    None if geometry is None else geometry))

    @classmethod
    def from_gmsh(cls, ctx, path):
        """Read a Gmsh MSH file (ASCII 4.1 or 2.x) of tet4, tet10, hex8 or hex20 cells."""
        return cls(_fcm.read_file(ctx, "mesh", str(path)))

    def refined(self, flags):
        """A new octree mesh with the cells flagged nonzero (one flag per cell) split."""
        return Mesh(_fcm.mesh_refined(self._h, np.asarray(flags, dtype=np.uint8)))

    @property
    def info(self):
        """Counts, type, octree level and bounding box as a dict."""
        return _fcm.mesh_info(self._h)

    element_type = property(lambda self: ElementType(self.info["element_type"]),
                            doc="The element type of every cell.")
    num_nodes = property(lambda self: self.info["num_nodes"], doc="Number of nodes.")
    num_cells = property(lambda self: self.info["num_cells"], doc="Number of cells.")
    coords = property(lambda self: _fcm.mesh_array(self._h, "coords"),
                      doc="Node coordinates (num_nodes, 3), a read-only view.")
    cells = property(lambda self: _fcm.mesh_array(self._h, "cells"),
                     doc="Cell node ids (num_cells, nodes_per_cell), a read-only view.")
    neighbors = property(lambda self: _fcm.mesh_array(self._h, "neighbors"),
                         doc="Cell across each face (num_cells, faces): -1 boundary, -2 "
                             "another octree level; a read-only view.")
    boundary_faces = property(lambda self: _fcm.mesh_array(self._h, "boundary_faces"),
                              doc="(cell, local face) pairs of the boundary, a view.")
    levels = property(lambda self: _fcm.mesh_array(self._h, "levels"),
                      doc="Refinement level of each cell (a copy; 0 off octrees).")

    def nodes_in_box(self, lo, hi, tol=0.0):
        """Ids of the nodes in the closed box [lo - tol, hi + tol] (infinities allowed)."""
        return _fcm.mesh_nodes_in_box(self._h, lo, hi, float(tol))

    def __str__(self):
        return _fcm.text(self._h)
