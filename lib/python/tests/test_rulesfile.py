"""The rules-file reader (fcm.rulesfile) on files written by ``fcm-quadrature export``:
exactness facts through the reader (piece volumes, monomials over a box body, a closed surface
rule), the CSR structure after a cut, malformed files refused with RulesFileError naming the
fault, and the app's refusal of bad arguments (exit 2, no file).

The program is taken from $FCM_QUADRATURE, else from the PATH, else from a build directory
beside the sources (build/); without it the tests are skipped."""

import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fcm.rulesfile import RulesFileError, read

ROOT = Path(__file__).resolve().parents[3]
B0 = np.array([0.4, 0.2, 0.5])
B1 = np.array([2.3, 2.6, 2.45])
STRENGTH = 4


def _program():
    env = os.environ.get("FCM_QUADRATURE")
    if env:
        return env
    found = shutil.which("fcm-quadrature")
    if found:
        return found
    for cand in sorted(ROOT.glob("build*/fcm-quadrature")):
        if os.access(cand, os.X_OK):
            return str(cand)
    return None


PROGRAM = _program()
needs_program = pytest.mark.skipif(PROGRAM is None, reason="fcm-quadrature not found")


def export(tmp_path, name, *extra):
    out = tmp_path / name
    box = "box:%g,%g,%g,%g,%g,%g,2" % (*B0, *B1)
    cmd = [PROGRAM, "export", "--element", "hex8", "--box", "0", "0", "0", "3", "3", "3",
           "--cells", "3", "3", "3", "--geometry", box, "--strength", str(STRENGTH),
           "--min-fraction", "0", "--output", str(out), *extra]
    run = subprocess.run(cmd, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    return read(out)


@pytest.fixture(scope="module")
def box_rules(tmp_path_factory):
    return export(tmp_path_factory.mktemp("rules"), "box.fcmr")


@needs_program
def test_header(box_rules):
    r = box_rules
    assert r.element == "hex8" and r.num_cells == 27 and r.num_pieces <= 27
    assert r.kinds == ["stiffness", "mass"] and r.has_surface
    assert r.header["rules"]["stiffness"]["strength"] == STRENGTH
    # Hex8's mass rules are exact on Q_2 only (degree <= 2 per variable): version 2
    mass = r.header["rules"]["mass"]
    assert mass["axis_degree"] == 2 < mass["strength"] and r.header["version"] == 2


@needs_program
def test_uncapped_rules_are_version_1(tmp_path):
    r = export(tmp_path, "p6.fcmr", "--mass-strength", "6")
    mass = r.header["rules"]["mass"]
    assert mass["axis_degree"] == mass["strength"] == 6 and r.header["version"] == 1
    assert "export" in r.header["description"]
    assert r["mesh/cells"].shape == (27, 8) and r["mesh/nodes"].shape == (64, 3)


@needs_program
def test_volumes_and_monomials(box_rules):
    r = box_rules
    vol = np.prod(B1 - B0)
    total = 0.0
    for cell in range(r.num_cells):
        for piece in r.cell_pieces(cell):
            x, w, flags = r.piece_rule(piece, physical=True)
            assert np.isclose(w[flags == 0].sum(), r["piece_volume"][piece], rtol=1e-12,
                              atol=1e-14)
            total += w[flags == 0].sum()
        # the cell's volume fraction: its material over |K| = 1
        _, w, flags = r.cell_rule(cell, physical=True)
        assert np.isclose(w[flags == 0].sum(), r["cell_volume_fraction"][cell], rtol=1e-12,
                          atol=1e-14)
    assert np.isclose(total, vol, rtol=1e-12)
    x, w, flags = r.cell_rule(0, physical=True)
    allx = r["stiffness/points_phys"][r["stiffness/flags"] == 0]
    allw = r["stiffness/weights_phys"][r["stiffness/flags"] == 0]
    for a in range(STRENGTH + 1):
        for b in range(STRENGTH + 1 - a):
            for c in range(STRENGTH + 1 - a - b):
                e = np.array([a, b, c])
                exact = np.prod((B1 ** (e + 1) - B0 ** (e + 1)) / (e + 1))
                q = np.sum(allw * allx[:, 0] ** a * allx[:, 1] ** b * allx[:, 2] ** c)
                assert abs(q - exact) <= 1e-12 * abs(exact), (a, b, c, q, exact)


@needs_program
def test_reference_and_physical_agree(box_rules):
    """Hex8 cells of the grid are cubes of side 1: X = centre + xi / 2, det J = 1/8."""
    r = box_rules
    nodes, cells = r["mesh/nodes"], r["mesh/cells"]
    for cell in range(r.num_cells):
        xi, wr, _ = r.cell_rule(cell)
        x, wp, _ = r.cell_rule(cell, physical=True)
        centre = nodes[cells[cell]].mean(axis=0)
        assert np.allclose(x, centre + 0.5 * xi, rtol=0, atol=1e-14)
        assert np.allclose(wp, wr / 8, rtol=1e-14, atol=0)


@needs_program
def test_surface_closes(box_rules):
    r = box_rules
    x, w, n = r["surface/points_phys"], r["surface/weights"], r["surface/normals"]
    lengths = B1 - B0
    area = 2 * (lengths[0] * lengths[1] + lengths[1] * lengths[2] + lengths[0] * lengths[2])
    assert np.isclose(w.sum(), area, rtol=1e-12)
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-14)
    assert np.allclose((w[:, None] * n).sum(axis=0), 0.0, atol=1e-12 * area)
    assert np.isclose(np.sum(w * np.einsum("ij,ij->i", x, n)), 3 * np.prod(lengths), rtol=1e-12)
    xs, ws, ns, tri = r.cell_surface(13, physical=True)  # the middle cell: inside the body
    assert len(ws) == 0 and r.cell_class(13) == "uncut"


@needs_program
def test_cut_pieces(tmp_path):
    """A plane cut given as an OBJ splits the cells it crosses: two pieces each, whose volumes
    add up to the cell's material; the uncut file has one piece per non-dropped cell."""
    obj = tmp_path / "cut.obj"
    obj.write_text("v 1.3 -1 -1\nv 1.3 4 -1\nv 1.3 4 4\nv 1.3 -1 4\nf 1 2 3\nf 1 3 4\n")
    r = export(tmp_path, "cut.fcmr", "--cut", str(obj))
    assert r.header["num_cuts"] == 1
    split = 0
    for cell in range(r.num_cells):
        pieces = r.cell_pieces(cell)
        vol = sum(r["piece_volume"][p] for p in pieces)
        assert np.isclose(vol, r["cell_volume_fraction"][cell], rtol=1e-12, atol=1e-14)
        for p in pieces:
            assert r["piece_cell"][p] == cell
            x, w, f = r.piece_rule(p, physical=True)
            side = np.sign(x[f == 0, 0] - 1.3)
            assert np.all(side == side[0])  # every authentic point on one side of the cut
        split += len(pieces) == 2
    assert split == 9  # the cells of the column 1 <= x <= 2 that hold material


@needs_program
def test_reference_only_and_no_mesh(tmp_path):
    r = export(tmp_path, "ref.fcmr", "--reference-only", "--no-mesh")
    assert "stiffness/points_phys" not in r and "mesh/nodes" not in r
    assert r.header["mesh"]["included"] is False
    with pytest.raises(KeyError, match="without physical points"):
        r.cell_rule(0, physical=True)


@needs_program
@pytest.mark.parametrize("args, message", [
    ([], "--element is required"),
    (["--element", "hex8", "--box", "0", "0", "0", "1", "1", "1", "--cells", "2", "2", "2",
      "--geometry", "box:0,0,0,1,1,1,1", "--strength", "2"], "--output is required"),
    (["--element", "hex8", "--box", "0", "0", "0", "1", "1", "1", "--cells", "2", "2", "2",
      "--geometry", "nosuchshape:1", "--strength", "2", "--output", "OUT"], "--geometry"),
    (["--element", "hex8", "--box", "0", "0", "0", "1", "1", "1", "--cells", "2", "2", "2",
      "--geometry", "box:0,0,0,1,1,1,1", "--strength", "2", "--output", "NODIR/x.fcmr"],
     "not a file in an existing directory"),
    (["--element", "hex8", "--box", "0", "0", "0", "1", "1", "1", "--cells", "2", "2", "2",
      "--geometry", "box:0,0,0,1,1,1,1", "--strength", "99", "--output", "OUT"], "--strength"),
])
def test_bad_arguments(tmp_path, args, message):
    args = [a.replace("OUT", str(tmp_path / "x.fcmr")).replace("NODIR", str(tmp_path / "no"))
            for a in args]
    run = subprocess.run([PROGRAM, "export", *args], capture_output=True, text=True)
    assert run.returncode == 2 and message in run.stderr, run.stderr
    assert not list(tmp_path.iterdir())  # nothing written, no temporary


@needs_program
def test_malformed_files(tmp_path, box_rules):
    good = Path(box_rules.path).read_bytes()

    def refused(data, message):
        p = tmp_path / "bad.fcmr"
        p.write_bytes(data)
        with pytest.raises(RulesFileError, match=message):
            read(p)

    refused(b"NOTRULES" + good[8:], "not an fcm rules file")
    refused(good[:-8], "truncated")
    refused(good[:12], "not an fcm rules file")
    refused(re.sub(rb'"version": [0-9]+,', b'"version": 7,', good, count=1),
            "version 7 not supported")
    refused(good.replace(b'"format": "fcm-cell-rules"', b'"format": "fcm-cell-rulez"', 1),
            "format")
    hlen = int.from_bytes(good[8:16], "little")
    refused(good[:8] + (hlen + 8).to_bytes(8, "little") + good[16:], "header")
    # a CSR offset array that decreases
    r = read(Path(box_rules.path), mmap=False)
    off_at = 16 + hlen + next(a["offset"] for a in r.header["arrays"]
                              if a["name"] == "stiffness/piece_offsets")
    bad = bytearray(good)
    bad[off_at + 8:off_at + 16] = (10 ** 9).to_bytes(8, "little")
    refused(bytes(bad), "non-decreasing offsets")
