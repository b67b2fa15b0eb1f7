"""embed_surface.py: embed a triangle surface in a background grid, plot the cut-cell
quadrature points and the convergence of the embedded volume and second moment.

The surfaces are faceted spheres of increasing resolution (the boundary of
fcm.Geometry.ball with n cubes per radius). Each is embedded as a surface alone
(Geometry.from_surface with volume_mesh=0: the cut-cell rules are fitted on the exact
moments of the material from the boundary triangles). The rules integrate the polyhedron
exactly (the volume matches the polyhedron's to round-off), so what converges is the
geometry: the faceted sphere approaches the sphere like O(h^2) in the facet size h. The
script prints the errors and the observed rates and draws two panels into
embed_surface.png: the points of a slice of cut cells, and the errors against h.

    python3 embed_surface.py [dir] [resolutions (1,2,4,8)]
"""

import math
import sys

import matplotlib

matplotlib.use("Agg")  # a file, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fcm  # noqa: E402


def embed(ctx, mesh, n, radius):
    """(rules, polyhedron volume) of the faceted sphere of resolution n."""
    ball = fcm.Geometry.ball(ctx, [0, 0, 0], radius, n)
    surface = fcm.Surface.from_arrays(ctx, ball.coords, ball.boundary_triangles)
    body = fcm.Geometry.from_surface(surface, volume_mesh=0)
    return fcm.CellRules(ctx, mesh, body, kinds=fcm.RULES_MASS, min_fraction=0.0), ball.volume


def main(out_dir=".", resolutions="1,2,4,8"):
    ns = [int(s) for s in str(resolutions).split(",")]
    ctx = fcm.Context()
    radius = 0.8
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-1, -1, -1], [1, 1, 1], [5, 5, 5])
    exact_v = 4 / 3 * math.pi * radius ** 3
    exact_m2 = 4 / 5 * math.pi * radius ** 5  # the integral of |x|^2
    hs, ev, em, last = [], [], [], None
    for n in ns:
        rules, poly_volume = embed(ctx, mesh, n, radius)
        p = rules.points(fcm.MASS)
        real = p["flag"] == 0
        w, x = p["physical_weight"][real], p["x"][real]
        volume, m2 = np.sum(w), np.sum(w * np.sum(x * x, axis=1))
        if abs(volume - poly_volume) > 1e-12 * poly_volume:
            print(f"resolution {n}: rules volume {volume!r} != polyhedron {poly_volume!r}")
            return False
        hs.append(radius / n)
        ev.append(abs(volume - exact_v) / exact_v)
        em.append(abs(m2 - exact_m2) / exact_m2)
        print(f"n = {n:2d}  h = {hs[-1]:.4f}  cut cells {rules.stats['num_cut']:3d}  "
              f"points {len(w):6d}  volume error {ev[-1]:.3e}  moment error {em[-1]:.3e}")
        last = (rules, p)
    rates = [math.log(ev[i] / ev[i + 1]) / math.log(hs[i] / hs[i + 1]) for i in range(len(hs) - 1)]
    print("observed rates of the volume error:", " ".join(f"{r:.2f}" for r in rates))

    rules, p = last
    cls = rules.cells()["cell_class"][p["cell"]]
    fig, (ax0, ax1) = plt.subplots(1, 2, figsize=(10, 4.5))
    sl = np.abs(p["x"][:, 1]) < 0.2  # the cells of the middle slab
    for c, colour, label in ((fcm.CellClass.UNCUT, "0.7", "uncut cells"),
                             (fcm.CellClass.CUT, "C3", "cut cells")):
        k = sl & (cls == c) & (p["flag"] == 0)
        ax0.scatter(p["x"][k, 0], p["x"][k, 2], s=6, c=colour, label=label)
    t = np.linspace(0, 2 * math.pi, 200)
    ax0.plot(radius * np.cos(t), radius * np.sin(t), "k-", lw=0.8, label="sphere")
    ax0.set_aspect("equal")
    ax0.set_title("quadrature points, |y| < 0.2")
    ax0.legend(loc="upper right", fontsize=8)
    ax1.loglog(hs, ev, "o-", label="volume")
    ax1.loglog(hs, em, "s-", label=r"$\int |x|^2$")
    ax1.loglog(hs, [ev[0] * (h / hs[0]) ** 2 for h in hs], "k--", lw=0.8, label="O(h^2)")
    ax1.set_xlabel("facet size h")
    ax1.set_ylabel("relative error")
    ax1.legend()
    ax1.set_title("faceted sphere against the sphere")
    fig.tight_layout()
    fig.savefig(f"{out_dir}/embed_surface.png", dpi=100)
    print(f"wrote {out_dir}/embed_surface.png")
    return all(r > 1.5 for r in rates) and 1.8 < rates[-1] < 2.2


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:3]) else 1)
