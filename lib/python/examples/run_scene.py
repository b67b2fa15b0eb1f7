"""run_scene.py: run a scene and plot its log.

Runs a scene file (apps/scenes/*.json; without one, the built-in twisting cylinder) for at
most `steps` steps with a monitor that prints each step, writes the log as CSV and draws the
energy, the Newton iterations and the momentum against time into <name>_log.png.

    python3 run_scene.py [scene.json] [steps] [dir]
"""

import sys

import matplotlib

matplotlib.use("Agg")  # a file, no window
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fcm  # noqa: E402


def main(path=None, steps=fcm.DEFAULT, out_dir="."):
    ctx = fcm.Context()
    scene = fcm.Scene.from_file(ctx, path) if path else fcm.Scene.default(ctx)
    sim = fcm.Simulation(ctx, scene, max_steps=int(steps))

    def monitor(step, num_steps, info):
        print(f"step {step}/{num_steps}  t = {info['time']:.4g} s  Newton "
              f"{info['newton_iterations']}  residual {info['residual']:.3g}")

    sim.run(monitor)
    print(sim)
    name = scene.name
    sim.write_log(f"{out_dir}/{name}_log.csv")
    log = sim.log()
    fig, axes = plt.subplots(3, 1, figsize=(7, 8), sharex=True)
    axes[0].plot(log["time"], log["energy"], "o-")
    axes[0].set_ylabel("energy (J)")
    axes[1].step(log["time"], log["newton_iterations"], where="mid")
    axes[1].set_ylabel("Newton iterations")
    for c in "xyz":
        axes[2].plot(log["time"], log[f"momentum_{c}"], label=f"p_{c}")
    axes[2].set_ylabel("momentum (kg m/s)")
    axes[2].set_xlabel("time (s)")
    axes[2].legend()
    axes[0].set_title(f"{name}: {len(log)} steps")
    fig.tight_layout()
    fig.savefig(f"{out_dir}/{name}_log.png", dpi=100)
    print(f"wrote {out_dir}/{name}_log.png")
    return len(log) == sim.step_count and bool(np.all(np.isfinite(log["energy"])))


if __name__ == "__main__":
    sys.exit(0 if main(*sys.argv[1:4]) else 1)
