"""Reader of fcm's cell-rules files (``fcm-quadrature export``, ``fcm_cell_rules_write()``).

Pure Python and NumPy: it needs neither the compiled ``fcm`` module nor the library, so a
finite element code can take fcm's cut-cell rules with only this file. The format is
documented in ``lib/docs/rules_format.md``: 8 bytes ``FCMRULES``, the header's length as a
little-endian uint64, the JSON header, then the arrays (raw, little-endian, 8-byte aligned)
at the offsets the header's table gives from the start of the data section.

Example::

    from fcm.rulesfile import read
    rules = read("rules.fcmr")
    for cell in range(rules.num_cells):
        x, w, flags = rules.cell_rule(cell, "stiffness", physical=True)
        # sum(w[j] * f(x[j])) integrates f over the material in the cell

Arrays are read-only views of a memory map of the file (``mmap=True``, the default) or
copies (``mmap=False``); a view keeps the map alive.
"""

import json

import numpy as np

__all__ = ["RulesFile", "RulesFileError", "read", "MAGIC", "VERSION"]

MAGIC = b"FCMRULES"
VERSION = 2  # the newest version this reader knows (2: rules with an axis_degree cap)

_DTYPES = {"float64": "<f8", "int64": "<i8", "int32": "<i4", "uint8": "u1"}
CELL_CLASSES = ("uncut", "cut", "dropped")


class RulesFileError(ValueError):
    """A file that is not a valid fcm rules file; the message names the file and the fault."""


class RulesFile:
    """The contents of a rules file.

    Attributes:
        path: the file read.
        header: the JSON header as a dict (format, version, element, counts, rules, surface,
            mesh, description, arrays).
        arrays: name -> NumPy array, for every array of the header's table ("cell_class",
            "cell_volume_fraction", "cell_piece_offsets", "piece_cell", "piece_volume",
            "<kind>/piece_offsets", "<kind>/points_ref", "<kind>/weights_ref",
            "<kind>/flags", "<kind>/points_phys", "<kind>/weights_phys" for kind "stiffness"
            and "mass", "surface/...", "mesh/nodes", "mesh/cells").
    """

    def __init__(self, path, mmap=True):
        self.path = str(path)
        raw = np.memmap(self.path, dtype=np.uint8, mode="r") if mmap else np.fromfile(
            self.path, dtype=np.uint8)
        if raw.size < 16 or bytes(raw[:8]) != MAGIC:
            self._fail("not an fcm rules file (the first 8 bytes are not %r)" % MAGIC)
        hlen = int(raw[8:16].view("<u8")[0])
        data_at = 16 + hlen
        if data_at > raw.size or data_at % 8:
            self._fail("header length %d does not fit the file (%d bytes) or leaves the data "
                       "unaligned" % (hlen, raw.size))
        try:
            self.header = json.loads(bytes(raw[16:data_at]).decode("utf-8"))
        except (UnicodeDecodeError, ValueError) as e:
            self._fail("header is not valid JSON: %s" % e)
        h = self.header
        if not isinstance(h, dict) or h.get("format") != "fcm-cell-rules":
            self._fail('header "format" is not "fcm-cell-rules"')
        if not isinstance(h.get("version"), int) or not 1 <= h["version"] <= VERSION:
            self._fail("version %r not supported (this reader knows 1..%d)"
                       % (h.get("version"), VERSION))
        if h.get("byte_order") != "little":
            self._fail('byte order %r (only "little" is defined)' % h.get("byte_order"))
        if data_at + h.get("data_bytes", -1) != raw.size:
            self._fail("file has %d bytes, the header announces %d (truncated or extended)"
                       % (raw.size, data_at + h.get("data_bytes", -1)))
        self.arrays = {}
        for a in h.get("arrays", []):
            self.arrays[a["name"]] = self._array(raw, data_at, a)
        self._check_structure()

    def _fail(self, what):
        raise RulesFileError("%s: %s" % (self.path, what))

    def _array(self, raw, data_at, a):
        name = a.get("name")
        if a.get("dtype") not in _DTYPES or a.get("byte_order") != "little":
            self._fail("array %r: dtype %r / byte order %r not supported"
                       % (name, a.get("dtype"), a.get("byte_order")))
        shape = tuple(a.get("shape", ()))
        if not 1 <= len(shape) <= 2 or any(not isinstance(s, int) or s < 0 for s in shape):
            self._fail("array %r: bad shape %r" % (name, shape))
        dt = np.dtype(_DTYPES[a["dtype"]])
        count = int(np.prod(shape))
        begin = data_at + a.get("offset", -1)
        if a.get("offset", -1) < 0 or begin % 8 or begin + count * dt.itemsize > raw.size:
            self._fail("array %r: offset %r and %d values leave the file"
                       % (name, a.get("offset"), count))
        view = raw[begin:begin + count * dt.itemsize].view(dt).reshape(shape)
        if isinstance(view, np.memmap):
            view = np.asarray(view)
        view.flags.writeable = False
        return view

    def _offsets(self, name, n, rows):
        off = self.arrays.get(name)
        if off is None or off.shape != (n + 1,) or off[0] != 0 or off[-1] != rows or np.any(
                np.diff(off) < 0):
            self._fail("array %r: not n + 1 = %d non-decreasing offsets from 0 to %d"
                       % (name, n + 1, rows))
        return off

    def _check_structure(self):
        nc, npc = self.num_cells, self.num_pieces
        for name in ("cell_class", "cell_volume_fraction", "cell_piece_offsets", "piece_cell",
                     "piece_volume"):
            if name not in self.arrays:
                self._fail("array %r missing" % name)
        self._offsets("cell_piece_offsets", nc, npc)
        for kind in self.kinds:
            n = self.header["rules"][kind]["num_points"]
            self._offsets(kind + "/piece_offsets", npc, n)
        if self.has_surface:
            self._offsets("surface/piece_offsets", npc, self.header["surface"]["num_points"])

    # ------------------------------------------------------------------ properties

    @property
    def element(self):
        """The background element: "tet4", "tet10", "hex8" or "hex20"."""
        return self.header["element"]

    @property
    def num_cells(self):
        return int(self.header["num_cells"])

    @property
    def num_pieces(self):
        return int(self.header["num_pieces"])

    @property
    def kinds(self):
        """The volume rules in the file ("stiffness", "mass")."""
        return list(self.header["rules"].keys())

    @property
    def has_surface(self):
        return self.header.get("surface") is not None

    def __getitem__(self, name):
        return self.arrays[name]

    def __contains__(self, name):
        return name in self.arrays

    def cell_class(self, cell):
        """"uncut", "cut" or "dropped"."""
        return CELL_CLASSES[int(self.arrays["cell_class"][cell])]

    def cell_pieces(self, cell):
        """The pieces of `cell` as a range (empty for a dropped cell)."""
        off = self.arrays["cell_piece_offsets"]
        return range(int(off[cell]), int(off[cell + 1]))

    # ------------------------------------------------------------------ rules

    def _range(self, prefix, first_piece, end_piece):
        off = self.arrays[prefix + "/piece_offsets"]
        return slice(int(off[first_piece]), int(off[end_piece]))

    def _volume(self, kind, s, physical):
        if kind not in self.header["rules"]:
            raise KeyError("no %r rules in %s (it has %s)" % (kind, self.path, self.kinds))
        if physical and kind + "/points_phys" not in self.arrays:
            raise KeyError("%s was written without physical points (--reference-only)"
                           % self.path)
        suffix = "phys" if physical else "ref"
        a = self.arrays
        return (a["%s/points_%s" % (kind, suffix)][s], a["%s/weights_%s" % (kind, suffix)][s],
                a[kind + "/flags"][s])

    def piece_rule(self, piece, kind="stiffness", physical=False):
        """(points n x 3, weights n, flags n) of one piece. Reference: points in the cell's
        reference element, weights to be multiplied by det J(xi); physical: mapped points and
        weights with det J included. Flag 1 marks a stabilization point."""
        return self._volume(kind, self._range(kind, piece, piece + 1), physical)

    def cell_rule(self, cell, kind="stiffness", physical=False):
        """The rule of a whole cell: its pieces' rules concatenated, as piece_rule()."""
        pieces = self.cell_pieces(cell)
        return self._volume(kind, self._range(kind, pieces.start, pieces.stop), physical)

    def _surface(self, s, physical):
        if not self.has_surface:
            raise KeyError("%s has no surface rules" % self.path)
        a = self.arrays
        pts = a["surface/points_phys" if physical else "surface/points_ref"]
        return pts[s], a["surface/weights"][s], a["surface/normals"][s], a["surface/triangles"][s]

    def piece_surface(self, piece, physical=False):
        """(points n x 3, area weights n, unit outward normals n x 3, boundary triangle ids n)
        of the embedded boundary in one piece; weights are physical areas in both cases."""
        return self._surface(self._range("surface", piece, piece + 1), physical)

    def cell_surface(self, cell, physical=False):
        """The surface rule of a whole cell, as piece_surface()."""
        pieces = self.cell_pieces(cell)
        return self._surface(self._range("surface", pieces.start, pieces.stop), physical)

    def __repr__(self):
        return "<fcm rules file %r: %s, %d cells, %d pieces, rules %s, surface %s>" % (
            self.path, self.element, self.num_cells, self.num_pieces, self.kinds,
            "yes" if self.has_surface else "no")


def read(path, mmap=True):
    """Read a rules file; raises RulesFileError (a ValueError) for anything malformed."""
    return RulesFile(path, mmap=mmap)
