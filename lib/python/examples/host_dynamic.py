"""host_dynamic.py: the Python twin of apps/examples/host_dynamic.cpp — a host that owns the
time loop and cuts mid-run.

An embedded bar, clamped at x = 0, swings down under gravity (backward Euler); after step
`cut_step` the host cuts it at x = 1.1 (CellRules.cut -> Space -> Integrator.cut) and the
cut-off end falls. Mass and momentum are checked across the cut; the embedded surface (both
sides of the cut) is written as VTU.

    python3 host_dynamic.py [dir] [steps (20)] [cut_step (10)]

Exit status 0 when every call succeeded and the checks hold.
"""

import sys

import fcm


def run(ctx, steps, cut_step, report=print):
    """The run; returns (integrator at the end, embedded surface, material, checks held)."""
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [2, 0.5, 0.5], [8, 2, 2])
    bar = fcm.Geometry.box(ctx, [0, 0.05, 0.05], [1.8, 0.45, 0.45], [18, 4, 4])
    mat = fcm.Material(fcm.MaterialModel.STABLE_NEO_HOOKEAN, 1e6, 0.3, 1000.0)
    # A dynamic run assembles the mass matrix: both rule kinds (the default).
    rules = fcm.CellRules(ctx, mesh, bar, kinds=fcm.RULES_STIFFNESS | fcm.RULES_MASS)
    integ = fcm.Integrator(ctx, fcm.Space(ctx, mesh, rules), mat, dt=0.01)
    integ.add_gravity([0, 0, -9.81])
    integ.add_constraint(mesh.nodes_in_box([-1, -1, -1], [0, 1, 1], 1e-9))  # the x = 0 nodes
    integ.setup()
    surf = fcm.EmbeddedSurface(integ.space, bar)
    # The cut: two triangles spanning the plane x = 1.1 across the bar.
    cut = fcm.Surface.from_arrays(ctx, [[1.1, -1, -1], [1.1, 2, -1], [1.1, 2, 2], [1.1, -1, 2]],
                                  [[0, 1, 2], [0, 2, 3]])

    def momentum(integ):
        u, v, _, _ = integ.state()
        m, p, _ = integ.space.momentum(mat.density, u, v)
        return m, p

    good = True
    for step in range(1, steps + 1):
        info = integ.step()
        m, p = momentum(integ)
        report(f"t = {integ.time:.2f} s  Newton {info['newton_iterations']}  bodies "
              f"{integ.space.num_bodies}  mass {m:.6g} kg  p_z {p[2]:.4g} kg m/s")
        if step != cut_step:
            continue
        # Cut between steps: new rules, a new space, an integrator continuing the old state.
        space = fcm.Space(ctx, mesh, integ.space.rules.cut(ctx, cut))
        integ = integ.cut(space)
        surf.set_space(space)
        m1, p1 = momentum(integ)
        report(f"cut at t = {integ.time:.2f} s: {space.num_bodies} bodies, mass {m:.6g} -> "
              f"{m1:.6g} kg, p_z {p[2]:.6g} -> {p1[2]:.6g}")
        if (space.num_bodies != 2 or abs(m1 - m) > 1e-10 * m
                or abs(p1[2] - p[2]) > 1e-9 * (abs(p[2]) + m)):
            print("host_dynamic: the cut changed the bodies, mass or momentum", file=sys.stderr)
            good = False
    return integ, surf, mat, good


def main(out_dir=".", steps=20, cut_step=10):
    integ, surf, mat, good = run(fcm.Context(), int(steps), int(cut_step))
    # The surface at reference positions with displacement and stresses (Warp By Vector).
    surf.write_vtu(f"{out_dir}/host_dynamic_surface.vtu", mat, integ.displacement)
    return good


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:4]) else 1)
