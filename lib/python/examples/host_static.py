"""host_static.py: the Python twin of apps/examples/host_static.c.

An embedded ball under gravity, clamped on its curved lower cap by Nitsche's method on the
embedded boundary itself (not on background nodes), solved statically. Writes the background
grid and the embedded surface as VTU (ParaView: Warp By Vector) and checks the clamp's
reaction against the weight.

    python3 host_static.py [dir]

Exit status 0 when the run succeeded and the ball sags under its weight.
"""

import sys

import numpy as np

import fcm


def solve(ctx):
    """Set up and solve; returns (integrator, clamp id, step info, rules, ball, material)."""
    # Background: 6 x 6 x 6 Hex8 cells over [-0.6, 0.6]^3; body: a ball of radius 0.5.
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [-0.6] * 3, [0.6] * 3, [6, 6, 6])
    ball = fcm.Geometry.ball(ctx, [0, 0, 0], 0.5, 3)
    # A static problem needs stiffness rules only; the clamp needs surface rules.
    rules = fcm.CellRules(ctx, mesh, ball, kinds=fcm.RULES_STIFFNESS, surface_strength=2)
    space = fcm.Space(ctx, mesh, rules)
    # Soft rubber, static equilibrium under gravity in 2 load steps.
    mat = fcm.Material(fcm.MaterialModel.STABLE_NEO_HOOKEAN, 2e5, 0.4, 1100.0)
    integ = fcm.Integrator(ctx, space, mat, kind=fcm.IntegratorKind.STATIC,
                           tolerance_mode=fcm.NewtonTolerance.REPRESENTATIVE, dt=1.0,
                           load_steps=2)
    integ.add_gravity([0.0, 0.0, -9.81])
    # Clamp the lower cap (u = 0 there) weakly by Nitsche's method (the default method).
    clamp = integ.add_boundary_constraint(lambda X, normal: X[2] < -0.35)
    integ.setup()
    return integ, clamp, integ.step(), rules, ball, mat


def main(out_dir="."):
    ctx = fcm.Context()
    integ, clamp, info, rules, ball, mat = solve(ctx)
    space = integ.space
    print(rules)
    print(f"static solve: {info['newton_iterations']} Newton iterations, "
          f"residual {info['residual']:.3g}")
    u = integ.displacement
    force, _ = integ.reaction(clamp, boundary=True)
    umax = space.max_displacement(u)
    print(f"reaction of the clamp ({force[0]:.4g}, {force[1]:.4g}, {force[2]:.4g}) N; "
          f"largest |u| in the body {umax:.4g} m")

    space.write_vtu(f"{out_dir}/host_static_background.vtu", mat, u)
    surf = fcm.EmbeddedSurface(space, ball)
    surf.write_vtu(f"{out_dir}/host_static_surface.vtu", mat, u)
    print(f"wrote {out_dir}/host_static_{{background,surface}}.vtu")

    # The ball sags (its top moves down), the bottom stays put, the clamp carries the weight.
    X = surf.points
    disp, _ = surf.eval(u)
    top = disp[X[:, 2] > 0.499, 2].min()
    cap = np.abs(disp[X[:, 2] < -0.499, 2]).max()
    weight = 1100.0 * 9.81 * rules.stats["embedded_volume"]
    print(f"top of the ball moves {top:.4g} m, bottom {cap:.3g} m; weight {weight:.4g} N")
    return (top < 0 and umax < 0.5 and cap * cap < 1e-4 * top * top
            and 0.98 * weight < force[2] < 1.02 * weight)


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:2]) else 1)
