"""The context, the base of every fcm object, and the enumerations shared by the package."""

import enum

from . import _fcm

#: The "use the default" value of numeric options (``FCM_DEFAULT``).
DEFAULT = _fcm.DEFAULT


class Status(enum.IntEnum):
    """fcm_status codes (``fcm.Error.status``)."""
    OK = _fcm.OK
    ERR_ARG = _fcm.ERR_ARG
    ERR_ALLOC = _fcm.ERR_ALLOC
    ERR_IO = _fcm.ERR_IO
    ERR_FORMAT = _fcm.ERR_FORMAT
    ERR_LAPACK = _fcm.ERR_LAPACK
    ERR_SINGULAR = _fcm.ERR_SINGULAR
    ERR_NOT_CONVERGED = _fcm.ERR_NOT_CONVERGED
    ERR_NUMERIC = _fcm.ERR_NUMERIC
    ERR_LP = _fcm.ERR_LP
    ERR_GEOMETRY = _fcm.ERR_GEOMETRY
    ERR_UNSUPPORTED = _fcm.ERR_UNSUPPORTED
    ERR_INTERNAL = _fcm.ERR_INTERNAL


class ElementType(enum.IntEnum):
    """Element types of background meshes (VTK node order, ``fcm/element.h``)."""
    TET4 = 0
    TET10 = 1
    HEX8 = 2
    HEX20 = 3


TET4, TET10, HEX8, HEX20 = ElementType.TET4, ElementType.TET10, ElementType.HEX8, ElementType.HEX20


class RuleKind(enum.IntEnum):
    """The two volume rules of a cell: stiffness (and forces) and consistent mass."""
    STIFFNESS = 0
    MASS = 1


STIFFNESS, MASS = RuleKind.STIFFNESS, RuleKind.MASS
#: Bits of the ``kinds`` option of :class:`CellRules`.
RULES_STIFFNESS, RULES_MASS, RULES_ALL = 1, 2, 3


class CellClass(enum.IntEnum):
    """Class of a background cell by its volume fraction."""
    UNCUT = 0
    CUT = 1
    DROPPED = 2


class Simplify(enum.IntEnum):
    """Whether cut-cell rules are simplified (option ``simplify``)."""
    OFF = 0
    ON = 1
    AUTO = 2


class Moments(enum.IntEnum):
    """Where a cut cell's rule comes from (option ``moments``)."""
    AUTO = 0
    VOLUME = 1
    SURFACE = 2


class SimplifyMethod(enum.IntEnum):
    """Simplification algorithm (option ``simplify_method``)."""
    AUTO = 0
    LP = 1
    RECOMBINE = 2
    ELIMINATE = 3


class StabilizationMode(enum.IntEnum):
    """Stabilization points of cut cells (option ``stabilization_mode``)."""
    MASS_STIFFNESS = 0
    MASS = 1
    OFF = 2


class FcmObject:
    """Base of the classes that own an fcm object: ``close()`` (also ``with`` blocks) ends it
    for Python; the C object itself lives on while a NumPy view into it or an object made from
    it is alive. A closed object raises ``ValueError`` on use."""

    __slots__ = ("_h", "__weakref__")

    def __init__(self, handle):
        self._h = handle

    def close(self):
        """Close the object (idempotent)."""
        self._h.close()

    @property
    def closed(self):
        """True after :meth:`close`."""
        return self._h.closed

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __repr__(self):
        h = getattr(self, "_h", None)
        state = " closed" if h is None or h.closed else ""
        return f"<fcm.{type(self).__name__}{state}>"


class Context(FcmObject):
    """The root of every fcm object: threads, errors, the allocation count.

    ``Context(num_threads=DEFAULT)``: OpenMP threads of the library's parallel loops (>= 1, or
    DEFAULT for OpenMP's default); results do not depend on it. Objects keep their context
    alive, so closing a context with live objects defers its end until they are gone.
    """

    __slots__ = ()

    def __init__(self, num_threads=DEFAULT):
        super().__init__(_fcm.ctx_create(int(num_threads)))

    @property
    def num_threads(self):
        """Threads of the library's parallel loops (settable; DEFAULT: OpenMP's)."""
        return _fcm.ctx_num_threads(self._h)

    @num_threads.setter
    def num_threads(self, n):
        _fcm.ctx_num_threads(self._h, int(n))

    @property
    def live_allocations(self):
        """Allocations made through the context and not yet released."""
        return _fcm.ctx_live_allocations(self._h)
