"""The README's Python example runs as written (the first python block of its "## Python"
section) and computes what it says."""

import contextlib
import io
import re

import pytest

import fcm


def test_readme_example(source_dir):
    text = (source_dir / "README.md").read_text()
    section = text.split("\n## Python\n", 1)[1].split("\n## ", 1)[0]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    assert len(block.strip().splitlines()) == 5
    out = io.StringIO()
    scope = {}
    with contextlib.redirect_stdout(out):
        exec(compile(block, "README.md", "exec"), scope)
    m = re.fullmatch(r"(\d+) cut cells; volume (\S+)\n", out.getvalue())
    assert m, out.getvalue()
    rules = scope["rules"]
    assert int(m.group(1)) == rules.stats["num_cut"] > 0
    # the embedded volume is the faceted ball's, which is within 3 % of the sphere's
    assert float(m.group(2)) == pytest.approx(rules.stats["geometry_volume"], rel=1e-12)
    assert float(m.group(2)) == pytest.approx(4 / 3 * 3.141592653589793 * 0.8 ** 3, rel=0.03)
    assert isinstance(rules, fcm.CellRules)
