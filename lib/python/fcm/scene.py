"""JSON scenes and their simulations (``fcm/scene.h``, ``fcm/simulation.h``)."""

import csv
import io
import os
import tempfile

import numpy as np

from . import _fcm
from .core import FcmObject, DEFAULT


class Scene(FcmObject):
    """A parsed, validated scene (apps/scenes/README.md has the schema): :meth:`from_file`,
    :meth:`from_string`, :meth:`default` (the built-in twisting cylinder)."""

    __slots__ = ()

    @classmethod
    def from_file(cls, ctx, path):
        """Parse a scene file; relative file names in it are relative to the file."""
        return cls(_fcm.scene_create(ctx, "file", str(path)))

    @classmethod
    def from_string(cls, ctx, text, name=None):
        """Parse a scene from JSON text (name: used in messages)."""
        return cls(_fcm.scene_create(ctx, "string", text, name))

    @classmethod
    def default(cls, ctx):
        """The built-in default scene."""
        return cls(_fcm.scene_create(ctx, "default"))

    @property
    def info(self):
        """name, description, source, json (normalized), num_effects, material."""
        return _fcm.scene_info(self._h)

    name = property(lambda self: self.info["name"])
    json = property(lambda self: self.info["json"],
                    doc="The scene as normalized JSON, every default filled in.")


class Simulation(FcmObject):
    """A scene's pipeline: geometry, cell rules, space, integrator, effects.
    ``Simulation(ctx, scene, max_steps=DEFAULT, host_cuts=False)``; then :meth:`step` in a host
    loop, or :meth:`run` with a monitor called after every step. host_cuts: the host will
    :meth:`cut` the body (each cut then integrates only the elements it changes)."""

    __slots__ = ("scene",)

    def __init__(self, ctx, scene, max_steps=DEFAULT, host_cuts=False):
        super().__init__(_fcm.simulation_create(ctx, scene, int(max_steps), bool(host_cuts)))
        self.scene = scene

    def step(self):
        """One step: its report as a dict (``fcm_step_info``)."""
        return _fcm.step(self._h)

    def run(self, monitor=None):
        """Take the steps left. monitor(step, num_steps, step_info), called after each step,
        returns False to stop (run() then returns False); an exception it raises stops the
        run and is raised. Returns True when the run is done."""
        return _fcm.simulation_run(self._h, monitor)

    def cut(self, blade, frame="reference"):
        """Cut the body now along `blade` (a :class:`~fcm.geometry.Surface`), as a scene's cut
        effect does (``fcm_simulation_cut``): frame "reference" (the blade at rest) or
        "deformed" (where the tool is now; its vertices carried back to rest). Returns the
        cut's report (missed, dofs_before, dofs_after, cells_integrated, seconds and its
        phases) as a dict."""
        frames = {"reference": 0, "deformed": 1}
        if frame not in frames:
            raise ValueError(f"cut: frame must be 'reference' or 'deformed', got {frame!r}")
        return _fcm.simulation_cut(self._h, blade._h, frames[frame])

    def rest_positions(self, x):
        """Points of the body as it is now, (n, 3), carried back to the rest positions of the
        material points they lie on (``fcm_simulation_rest_positions``): a new (n, 3) array."""
        return _fcm.simulation_rest_positions(self._h, np.asarray(x, dtype=float))

    @property
    def info(self):
        """done, step_count, num_steps, frame_due, state_finite."""
        return _fcm.simulation_info(self._h)

    done = property(lambda self: bool(self.info["done"]))
    step_count = property(lambda self: self.info["step_count"])

    def state(self):
        """(u, v, t, node displacement (num_nodes, 3)): copies of the current state."""
        return _fcm.simulation_state(self._h)

    def write_frame(self, directory, index):
        """Write frame `index` (VTU files and PVD indexes) into an existing directory."""
        _fcm.simulation_write(self._h, "frame", str(directory), int(index))

    def write_log(self, path):
        """Write the per-step log as CSV."""
        _fcm.simulation_write(self._h, "log", str(path))

    def write_checkpoint(self, path):
        """Save the run's state."""
        _fcm.simulation_write(self._h, "checkpoint", str(path))

    def read_checkpoint(self, path):
        """Continue from a checkpoint of the same scene."""
        _fcm.simulation_write(self._h, "restore", str(path))

    def log(self):
        """The per-step log (one row per step: step, time, newton_iterations, residual,
        energy, mass, momentum, reactions, ...) as a NumPy structured array (a copy)."""
        fd, path = tempfile.mkstemp(suffix=".csv")
        os.close(fd)
        try:
            self.write_log(path)
            with open(path, newline="") as f:
                text = f.read()
        finally:
            os.unlink(path)
        rows = list(csv.reader(io.StringIO(text)))
        names = rows[0]
        data = np.array([[float(x) for x in r] for r in rows[1:]], dtype=float).reshape(-1, len(names))
        out = np.empty(len(data), dtype=[(n, float) for n in names])
        for i, n in enumerate(names):
            out[n] = data[:, i]
        return out

    def __str__(self):
        return _fcm.text(self._h)
