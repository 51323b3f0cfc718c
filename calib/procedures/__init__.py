"""Calibration procedures: the registry of what a plan's ``procedure.method`` can name.

Owns:
    - :mod:`calib.procedures.base`: the :class:`~calib.procedures.base.ProcedureKind` protocol
      (roles, role checks, :meth:`run` with a probe, :meth:`estimate` from measurements, the
      layout an adaptive robot program needs), :class:`RolePoint`; what a run returns,
      :class:`~calib.procedure_run.ProcedureRun`, lives below, in :mod:`calib.procedure_run`;
    - one module per procedure, with its settings struct (the plan's ``procedure`` object) and
      its implementation: ``hultman2013`` (the paper's A-H), ``three_two_one``, ``best_fit``,
      ``iterative`` (the iterative best fit: measure all, fit, re-command all, until it
      settles);
    - the registry :data:`PROCEDURES`, the settings union :data:`ProcedureSettings` and
      :func:`procedure_kind`.

Also: :mod:`calib.procedures.comparison` (the best fit of a procedure's own measurements, fed
as the procedure is fed) and :mod:`calib.procedures.linearize` (the predicted covariance of any
procedure, from its own run against the ideal part).

Every caller (the plan file, ``wobjcal calibrate``, the validation, the exporters, suggest,
the UI) looks a procedure up here; none tests the method's name. What differs between
procedures outside their own module is a field of the entry: ``design``
(:class:`~calib.procedures.base.LayoutDesign`: how ``wobjcal suggest`` designs its layouts;
:data:`DESIGNED` lists those that have one), ``steering``
(:class:`~calib.procedures.base.Steering`: after which points an adaptive program updates its
frame) and ``published`` (the half-widths the validation shows beside a built-in part: the
paper's Table 1 for A-H). Adding a procedure is one module
(a settings struct tagged ``method="<name>"`` and a class following the protocol) plus its entry
in :data:`PROCEDURES` and in the :data:`ProcedureSettings` union, as the iterative best fit went
in::

    # calib/procedures/iterative.py: class Iterative(msgspec.Struct, tag="iterative", ...)
    #                                ITERATIVE = IterativeProcedure()
    PROCEDURES = {k.method: k for k in (HULTMAN2013, THREE_TWO_ONE, BEST_FIT, ITERATIVE)}
    ProcedureSettings = Hultman2013 | ThreeTwoOne | BestFit | Iterative
"""

from __future__ import annotations

from calib.errors import PlanError
from calib.paper.settings import Hultman2013
from calib.procedures.base import LayoutDesign, ProcedureKind, ProcedureRun, RolePoint, Steering
from calib.procedures.best_fit import BEST_FIT, BestFit
from calib.procedures.hultman2013 import HULTMAN2013
from calib.procedures.iterative import ITERATIVE, Iterative
from calib.procedures.three_two_one import THREE_TWO_ONE, ThreeTwoOne
from calib.registry import lookup

#: The procedures by method name, in the order the UI offers them.
PROCEDURES: dict[str, ProcedureKind] = {
    k.method: k for k in (HULTMAN2013, THREE_TWO_ONE, BEST_FIT, ITERATIVE)
}
#: The plan's ``procedure`` object: one settings struct per procedure, tagged by ``method``.
ProcedureSettings = Hultman2013 | ThreeTwoOne | BestFit | Iterative
#: The method names.
METHODS = tuple(PROCEDURES)
#: The procedures whose layouts ``wobjcal suggest`` designs (a
#: :class:`~calib.procedures.base.LayoutDesign` in their entry), in the registry's order.
DESIGNED = tuple(m for m, kind in PROCEDURES.items() if kind.design is not None)
#: Of those, the ones whose layout grows point by point (``--add``, ``--objective time``); the
#: first (the best fit) is what suggest designs for unless told.
GROWN = tuple(m for m in DESIGNED if (d := PROCEDURES[m].design) is not None and d.grows)

__all__ = [
    "DESIGNED",
    "GROWN",
    "METHODS",
    "PROCEDURES",
    "BestFit",
    "Hultman2013",
    "Iterative",
    "LayoutDesign",
    "ProcedureKind",
    "ProcedureRun",
    "ProcedureSettings",
    "RolePoint",
    "Steering",
    "ThreeTwoOne",
    "method_of",
    "procedure_kind",
]


def method_of(settings: ProcedureSettings) -> str:
    """The ``method`` tag of a procedure's settings struct."""
    return str(type(settings).__struct_config__.tag)


def procedure_kind(method: str | ProcedureSettings) -> ProcedureKind:
    """The procedure named ``method`` (or of a settings struct).

    Raises:
        PlanError: no such procedure (the message lists the known ones).
    """
    name = method if isinstance(method, str) else method_of(method)
    return lookup(PROCEDURES, name, "procedure (procedure.method)", PlanError)
