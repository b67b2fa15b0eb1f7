"""Every example of lib/python/examples runs (small sizes) and writes what it says, so the
examples cannot rot: each exits 0 only when its own checks hold."""

import os
import re
import subprocess
import sys

import pytest

PNG = b"\x89PNG\r\n\x1a\n"


def run(source_dir, name, *args):
    script = source_dir / "lib" / "python" / "examples" / name
    r = subprocess.run([sys.executable, str(script), *map(str, args)], capture_output=True,
                       text=True, env=dict(os.environ, MPLBACKEND="Agg"))
    assert r.returncode == 0, r.stdout + r.stderr
    return r.stdout


def is_png(path):
    return path.read_bytes()[:8] == PNG and path.stat().st_size > 1000


def test_host_static(source_dir, scratch):
    out = run(source_dir, "host_static.py", scratch)
    assert "static solve" in out and "reaction of the clamp" in out
    for f in ("host_static_background.vtu", "host_static_surface.vtu"):
        assert (scratch / f).read_bytes().startswith(b"<?xml")


def test_host_dynamic(source_dir, scratch):
    out = run(source_dir, "host_dynamic.py", scratch, 6, 3)
    assert re.search(r"cut at t = 0\.03 s: 2 bodies", out)
    assert len(re.findall(r"^t = ", out, re.M)) == 6
    assert (scratch / "host_dynamic_surface.vtu").stat().st_size > 0


def test_embed_surface(source_dir, scratch):
    out = run(source_dir, "embed_surface.py", scratch, "2,4,8")
    line = re.search(r"observed rates of the volume error:(.*)", out).group(1)
    rates = [float(r) for r in line.split()]
    assert len(rates) == 2 and all(1.8 < r < 2.2 for r in rates)
    assert is_png(scratch / "embed_surface.png")


def test_run_scene(source_dir, scratch):
    scene = source_dir / "apps" / "scenes" / "cut_slab.json"
    out = run(source_dir, "run_scene.py", scene, 3, scratch)
    assert "step 3/3" in out
    rows = (scratch / "cut_slab_log.csv").read_text().splitlines()
    assert rows[0].startswith("step,time,") and len(rows) == 4
    assert is_png(scratch / "cut_slab_log.png")


@pytest.mark.parametrize("name", ["host_static.py", "host_dynamic.py", "embed_surface.py",
                                  "run_scene.py"])
def test_examples_have_docstrings(source_dir, name):
    text = (source_dir / "lib" / "python" / "examples" / name).read_text()
    assert text.startswith('"""') and "python3 " + name in text
