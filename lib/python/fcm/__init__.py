"""fcm — the finite cell method library from Python.

Cut-cell quadrature of embedded geometries in background meshes, spaces, static and dynamic
solvers, cuts between steps, and JSON scenes, over fcm's C API (the extension module
``fcm._fcm``). Arrays come back as NumPy arrays: read-only views into the C objects where
their memory lives as long as the object (mesh and geometry arrays, rules), copies otherwise
(solver state, fields); a view keeps its object alive. Every failing call raises
:class:`fcm.Error` with the library's status and message; wrong argument types, dtypes and
shapes raise ``TypeError`` / ``ValueError`` before the library is called.

A minimal session::

    import fcm
    ctx = fcm.Context()
    mesh = fcm.Mesh.box(ctx, fcm.HEX8, [0, 0, 0], [1, 1, 1], [4, 4, 4])
    ball = fcm.Geometry.ball(ctx, [0.5, 0.5, 0.5], 0.3, 4)
    rules = fcm.CellRules(ctx, mesh, ball)
    print(rules.stats["embedded_volume"], ball.volume)
"""

from . import _fcm
from ._fcm import Error
from .core import (Context, ElementType, TET4, TET10, HEX8, HEX20, RuleKind, STIFFNESS, MASS,
                   RULES_STIFFNESS, RULES_MASS, RULES_ALL, CellClass, Simplify, Moments,
                   SimplifyMethod, StabilizationMode, Status, DEFAULT)
from .mesh import Mesh
from .geometry import Geometry, Surface, VoxelImage
from .rules import CellRules
from .solid import (MaterialModel, Material, IntegratorKind, TimeScheme, LinearSolver,
                    Preconditioner, NewtonTolerance, BoundaryMethod, Space, Integrator,
                    EmbeddedSurface)
from .scene import Scene, Simulation
from . import rulesfile

__version__ = _fcm.version

__all__ = [
    "Error", "Context", "ElementType", "TET4", "TET10", "HEX8", "HEX20", "RuleKind",
    "STIFFNESS", "MASS", "RULES_STIFFNESS", "RULES_MASS", "RULES_ALL", "CellClass", "Simplify",
    "Moments", "SimplifyMethod", "StabilizationMode", "Status", "DEFAULT", "Mesh", "Geometry",
    "Surface", "VoxelImage", "CellRules", "MaterialModel", "Material", "IntegratorKind",
    "TimeScheme", "LinearSolver", "Preconditioner", "NewtonTolerance", "BoundaryMethod",
    "Space", "Integrator", "EmbeddedSurface", "Scene", "Simulation", "rulesfile", "__version__",
]
