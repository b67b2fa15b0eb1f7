"""Materials, spaces, integrators and embedded surfaces (``fcm/material.h``, ``fcm/fem.h``,
``fcm/sim.h``)."""

import enum
from collections import namedtuple

from . import _fcm
from .core import FcmObject, DEFAULT


class MaterialModel(enum.IntEnum):
    """Material models (``fcm_material_model``)."""
    LINEAR = 0
    STVK = 1
    COROTATED = 2
    STABLE_NEO_HOOKEAN = 3
    COROTATED_LINEAR = 4


class Material(namedtuple("Material", "model young poisson density")):
    """A material: model (MaterialModel), Young's modulus E > 0, Poisson's ratio in (-1, 0.5),
    density >= 0 (``fcm_material``)."""
    __slots__ = ()


class IntegratorKind(enum.IntEnum):
    """Static equilibrium or dynamics (option ``kind``)."""
    STATIC = 0
    DYNAMIC = 1


class TimeScheme(enum.IntEnum):
    """Time scheme of the dynamic kind (option ``scheme``)."""
    BACKWARD_EULER = 0
    NEWMARK = 1
    HHT = 2
    GENERALIZED_ALPHA = 3


class LinearSolver(enum.IntEnum):
    """Linear solver of the Newton steps (option ``linear_solver``)."""
    DIRECT = 0
    CG = 1
    MINRES = 2
    MULTIGRID = 3


class Preconditioner(enum.IntEnum):
    """Krylov preconditioner (option ``preconditioner``)."""
    NONE = 0
    JACOBI = 1
    BLOCK_JACOBI = 2
    SCHWARZ = 3
    MULTIGRID = 4


class NewtonTolerance(enum.IntEnum):
    """Newton stopping rule (option ``tolerance_mode``)."""
    REPRESENTATIVE = 0
    RELATIVE = 1
    AUTO = 2


class BoundaryMethod(enum.IntEnum):
    """Weak boundary constraints (boundary option ``method``)."""
    NITSCHE = 0
    PENALTY = 1


class Space(FcmObject):
    """The discrete displacement space (DOF map) of a mesh: ``Space(ctx, mesh, rules)`` for an
    embedded problem (active cells, copies of nodes across cuts), ``Space(ctx, mesh)`` for a
    plain finite element mesh. Keeps its mesh and rules alive."""

    __slots__ = ("mesh", "rules")

    def __init__(self, ctx, mesh, rules=None):
        super().__init__(_fcm.space_create(ctx, mesh, None if rules is None else rules))
        self.mesh = mesh
        self.rules = rules

    @property
    def info(self):
        """num_dofs, num_elements, num_bodies, num_colors, num_nodes."""
        return _fcm.space_info(self._h)

    num_dofs = property(lambda self: self.info["num_dofs"], doc="Number of DOFs.")
    num_bodies = property(lambda self: self.info["num_bodies"],
                          doc="Separate bodies (connected components of the elements).")

    def node_dofs(self):
        """(first DOF of each mesh node, -1 where inactive; its number of copies): the x, y, z
        DOFs of copy k of node a are first[a] + 3 k + (0, 1, 2)."""
        return _fcm.space_node_dofs(self._h)

    def node_field(self, dofs):
        """A DOF vector as one 3-vector per mesh node (num_nodes, 3); inactive nodes 0."""
        return _fcm.space_node_field(self._h, dofs)

    def cell_stress(self, material, u):
        """Per cell averages: (stress (num_cells, 6) xx yy zz xy yz xz, von Mises, energy
        density) for the displacement u."""
        return _fcm.space_cell_stress(self._h, tuple(material), u)

    def momentum(self, density, u, v):
        """(mass, linear momentum, angular momentum about the origin) of the body."""
        return _fcm.space_momentum(self._h, float(density), u, v)

    def max_displacement(self, u):
        """The largest |u| over the body's quadrature points."""
        return _fcm.space_max_displacement(self._h, u)

    def write_vtu(self, path, material, u, v=None):
        """Write the background mesh with displacement (velocity) and stresses as VTU."""
        _fcm.space_write_vtu(self._h, tuple(material), u, v, str(path))

    def transfer(self, to, x):
        """Carry a field of this space onto `to`, the space of rules cut from these."""
        return _fcm.space_transfer(self._h, to, x)


StepInfo = dict


class Integrator(FcmObject):
    """A static or dynamic solver on a space: ``Integrator(ctx, space, material, **options)``.

    Add loads, constraints and obstacles (:meth:`add_gravity`, :meth:`add_body_force`,
    :meth:`add_traction`, :meth:`add_constraint`, :meth:`add_boundary_constraint`,
    :meth:`add_contact_plane`), then :meth:`setup` and :meth:`step` as often as wanted:
    the host owns the time loop. Between steps :meth:`cut` continues the state on the space
    of cut rules (like apps/examples/host_dynamic.cpp).

    Options (``fcm_integrator_options``; :meth:`defaults`): kind (IntegratorKind), scheme
    (TimeScheme), hht_alpha, rho_inf, dt, load_steps, max_halvings, newton_max_iterations,
    tolerance_mode (NewtonTolerance), newton_tolerance, newton_atol, rep_acceleration,
    line_search, armijo, backtrack, max_backtracks, project_psd, reuse_factorization,
    reuse_contraction, newton_fixed_iterations, cut_reuse, linear_solver (LinearSolver),
    direct_method, preconditioner (Preconditioner), preconditioner_tangent, krylov_rtol,
    krylov_atol, krylov_max_iterations, multigrid_fixed_cycles, krylov_stagnation_window,
    schwarz_theta, rayleigh_mass, rayleigh_stiffness.
    """

    __slots__ = ("space", "material")

    def __init__(self, ctx, space, material, _handle=None, **options):
        super().__init__(_handle if _handle is not None else
                         _fcm.integrator_create(ctx, space, tuple(material), options))
        self.space = space
        self.material = Material(*material)

    @staticmethod
    def defaults():
        """The default options as a dict."""
        return _fcm.integrator_defaults()

    def add_gravity(self, acceleration=(0.0, 0.0, -9.81), scale=None):
        """A uniform body acceleration (m/s^2), times scale(t) when given (a callable)."""
        _fcm.integrator_add_load(self._h, "gravity", acceleration, scale)

    def add_body_force(self, field, scale=None):
        """A body force density b = field(x, None) (N/m^3, three numbers at the physical point
        x), times scale(t). Called from the assembly's threads during setup and steps; an
        exception it raises fails that call and is raised there."""
        _fcm.integrator_add_load(self._h, "body_force", field, scale)

    def add_traction(self, field, scale=None):
        """A traction t = field(x, normal) (N/m^2) on the embedded boundary (the rules need
        surface_strength), times scale(t); called as :meth:`add_body_force`'s field."""
        _fcm.integrator_add_load(self._h, "traction", field, scale)

    def add_contact_plane(self, point, normal, velocity=(0.0, 0.0, 0.0), distance=0.0,
                          stiffness=0.0):
        """A rigid half-space obstacle (the plane through point, normal pointing to the body's
        side, moving at velocity) by the log barrier on the embedded surface's points
        (distance: the barrier's threshold, 0: 0.1 h; stiffness: 0: E / h). Needs surface
        rules. Returns its id for :meth:`contact_info`."""
        return _fcm.integrator_add_contact_plane(self._h, point, normal, velocity,
                                                 float(distance), float(stiffness))

    def contact_info(self, obstacle_id):
        """force, min_distance, distance (threshold) and stiffness of a contact obstacle."""
        return _fcm.integrator_contact_info(self._h, int(obstacle_id))

    def add_constraint(self, nodes, **motion):
        """Hold mesh nodes (ids) fixed, or move them by a motion: velocity, center, axis,
        angular_speed, start, end, release, components (``fcm_motion``). Returns its id."""
        return _fcm.integrator_add_constraint(self._h, nodes, motion)

    def add_boundary_constraint(self, select, motion=None, **options):
        """Constrain the embedded-boundary points that select(X, normal) accepts (a Python
        callable, called during :meth:`setup`; an exception it raises is raised there) weakly
        (options: method BoundaryMethod.NITSCHE or PENALTY, nitsche_safety, penalty); motion:
        a dict as :meth:`add_constraint` takes. Returns its id."""
        return _fcm.integrator_add_boundary_constraint(self._h, select, motion or {}, options)

    def setup(self):
        """Assemble what the steps share (mass matrix, loads, constraints)."""
        _fcm.integrator_setup(self._h)

    def step(self):
        """One step (a static solve, or one time step): the step's report as a dict
        (``fcm_step_info``: reason, newton_iterations, residual, time, energies, ...)."""
        return _fcm.step(self._h)

    def run(self, steps, callback=None):
        """Take `steps` steps; after each, callback(integrator, step_info) may return a new
        integrator to continue with (e.g. :meth:`cut` of this one) or None. Returns the
        integrator the loop ended with."""
        integ = self
        for _ in range(int(steps)):
            info = integ.step()
            if callback is not None:
                nxt = callback(integ, info)
                if nxt is not None:
                    integ = nxt
        return integ

    def cut(self, space):
        """A new integrator on `space` (of rules cut from this one's) continuing this one's
        state, loads and constraints."""
        return Integrator(None, space, self.material,
                          _handle=_fcm.integrator_create_cut(self._h, space))

    def state(self):
        """(u, v, t, steps): copies of the displacement, velocity, time and step count."""
        return _fcm.integrator_state(self._h)

    def set_state(self, u, v, t, steps):
        """Restore a state (e.g. one of :meth:`state`)."""
        _fcm.integrator_set_state(self._h, u, v, float(t), int(steps))

    displacement = property(lambda self: self.state()[0], doc="u (a copy).")
    velocity = property(lambda self: self.state()[1], doc="v (a copy).")
    time = property(lambda self: self.state()[2], doc="The time reached.")

    def reaction(self, constraint_id, boundary=False):
        """(force, moment) a constraint exerts on the body (boundary=True for the ids of
        :meth:`add_boundary_constraint`)."""
        return _fcm.integrator_reaction(self._h, int(constraint_id), bool(boundary))

    def energy(self):
        """kinetic, elastic, external_work, linear/angular momentum, time, step_count."""
        return _fcm.integrator_energy(self._h)


class EmbeddedSurface(FcmObject):
    """The boundary of an embedded body located in a space, for output:
    ``EmbeddedSurface(space, geometry)``. :meth:`set_space` follows a cut."""

    __slots__ = ()

    def __init__(self, space, geometry):
        super().__init__(_fcm.esurf_create(space, geometry))

    def set_space(self, space):
        """Move to another space on the same mesh (after a cut)."""
        _fcm.esurf_set_space(self._h, space)

    points = property(lambda self: _fcm.esurf_arrays(self._h)[0],
                      doc="Reference positions of the points (n, 3), a read-only view.")
    triangles = property(lambda self: _fcm.esurf_arrays(self._h)[1],
                         doc="Triangles (m, 3), a read-only view.")

    def eval(self, u):
        """(displacement (n, 3), deformed positions (n, 3)) of the points for u."""
        return _fcm.esurf_eval(self._h, u)

    def write_vtu(self, path, material, u):
        """Write the surface with displacement and stresses as VTU."""
        _fcm.esurf_write_vtu(self._h, tuple(material), u, str(path))


__all__ = ["MaterialModel", "Material", "IntegratorKind", "TimeScheme", "LinearSolver",
           "Preconditioner", "NewtonTolerance", "BoundaryMethod", "Space", "Integrator",
           "EmbeddedSurface", "DEFAULT"]
