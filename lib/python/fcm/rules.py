"""Cut-cell quadrature rules of an embedded geometry in a background mesh (``fcm/embed.h``)."""

from . import _fcm
from .core import FcmObject, ElementType, CellClass, STIFFNESS


class CellRules(FcmObject):
    """Per-cell quadrature of an embedded geometry in a background mesh (lib/METHOD.md §5).

    ``CellRules(ctx, mesh, geometry, cell_mask=None, **options)`` builds the rules of every
    background cell: uncut cells share the catalogue rule, cut cells get an exact, positive
    rule of at most M points (simplified) plus stabilization points (flag 1), cells below
    min_fraction are dropped. The mesh and geometry are only read during the call.

    Rules live in the reference coordinates xi of each cell; a volume weight includes
    l_j |J_Q| / |det J_K(xi)|, so the physical integral over the cell's material is
    sum_j w_j det J_K(xi_j) f(X(xi_j)) (:meth:`points` computes X and w det J). Surface
    weights are physical areas.

    Options (``fcm_cell_rules_options``; :meth:`defaults` lists their defaults):

    - kinds: volume rules to build, bits RULES_STIFFNESS | RULES_MASS (default both)
    - strength: per kind (stiffness, mass), DEFAULT the element's; a number sets both
    - axis_degree: per kind, the cut-cell rules' moment space is capped at this degree in
      each variable (DEFAULT: the element's, Hex8's mass 2, i.e. the tensor space Q2 of
      trilinear products; an explicit strength without it means the whole total degree)
    - stiffness_on_mass_space: 1 fits the cut cells' stiffness rules on the mass rules' space
      (Hex8: Q2, where an affine cell's stiffness integrand lies: exact, one fit for both
      kinds, up to 27 stiffness points a piece; for a stiffness integrated once, as the
      corotated linear model's); 0 (default) each kind on its own space
    - surface_strength: triangle rule strength of surface rules (DEFAULT: none)
    - min_fraction (1e-4), uncut_fraction (1 - 1e-12): the class thresholds
    - clip_rtol, sliver_rtol, convex_rtol: clipping, sliver and convexity tolerances
    - simplify: Simplify.ON (default), OFF or AUTO; moments: Moments.AUTO, VOLUME or SURFACE
    - expected_assemblies, point_cost: the AUTO cost model's inputs, per kind
    - simplify_method, simplify_rank_tol, simplify_residual_tol, simplify_lp_iteration_limit,
      simplify_lp_time_limit, simplify_elimination_block: ``fcm_simplify_options``
    - max_rule_memory: bytes one cut cell may take to build (0: no limit)
    - stabilization_mode (StabilizationMode), stabilization_alpha (1e-6)

    cell_mask: one flag per cell; cells flagged 0 are classified but get no points.
    Errors raise :class:`fcm.Error` (e.g. a strength out of range names it and the range).
    """

    __slots__ = ("mesh", "geometry")

    def __init__(self, ctx, mesh, geometry, cell_mask=None, _handle=None, **options):
        super().__init__(_handle if _handle is not None else
                         _fcm.rules_create(ctx, mesh, geometry, options, cell_mask))
        #: The background mesh the rules were built on.
        self.mesh = mesh
        #: The embedded geometry.
        self.geometry = geometry

    @staticmethod
    def defaults():
        """The default options as a dict."""
        return _fcm.rules_defaults()

    def cut(self, ctx, surface):
        """The rules extended by a cut (XFEM): the surface splits the cells it crosses into
        material pieces, each with its own rules; the other cells' rules are copied. These
        rules are unchanged."""
        h = _fcm.rules_cut(ctx, self.mesh, self.geometry, self._h, surface)
        return CellRules(None, self.mesh, self.geometry, _handle=h)

    @property
    def info(self):
        """num_cells, element_type, strength per kind, axis_degree per kind (the degree cap in
        each variable of the cut cells' moment space), surface_strength, has_kind, num_cuts,
        num_pieces, num_links."""
        return _fcm.rules_info(self._h)

    num_cells = property(lambda self: self.info["num_cells"], doc="Background cells.")
    element_type = property(lambda self: ElementType(self.info["element_type"]))
    stats = property(lambda self: _fcm.rules_stats(self._h),
                     doc="The build's statistics (``fcm_cell_rules_stats``) as a dict.")

    def cells(self):
        """Per cell: cell_class (CellClass values), volume_fraction, cell_first_piece,
        cell_num_pieces; per piece: piece_cell, piece_volume, piece_parent; links (pairs of
        linked pieces, a view). Copies, except links."""
        return _fcm.rules_cells(self._h)

    def cell_class(self, cell):
        """The CellClass of one cell."""
        return CellClass(int(self.cells()["cell_class"][cell]))

    def get(self, cell, kind=STIFFNESS):
        """(points (n, 3) reference coordinates, weights (n,), flags (n,): 1 stabilization)
        of one cell's rule of `kind`: read-only views that keep the rules alive."""
        return _fcm.rules_get(self._h, int(cell), int(kind), False)

    def get_piece(self, piece, kind=STIFFNESS):
        """As :meth:`get` for one material piece (cells that cuts split have several)."""
        return _fcm.rules_get(self._h, int(piece), int(kind), True)

    def get_surface(self, cell):
        """(points (n, 3), area weights (n,), outward normals (n, 3), boundary triangle of each
        point (n,)) of one cell's surface rule: read-only views."""
        return _fcm.rules_get_surface(self._h, int(cell), False)

    def get_piece_surface(self, piece):
        """As :meth:`get_surface` for one piece."""
        return _fcm.rules_get_surface(self._h, int(piece), True)

    def points(self, kind=STIFFNESS):
        """Every point of `kind` over all cells (copies): a dict of cell, xi (reference),
        x (physical), weight, physical_weight (w det J) and flag."""
        return _fcm.rules_gather(self._h, self.mesh, int(kind))

    def surface_points(self):
        """Every surface point (copies): cell, xi, x, weight (= physical_weight), normal."""
        return _fcm.rules_gather(self._h, self.mesh, -1)

    def __str__(self):
        return _fcm.text(self._h)
