"""wobjcal calibration core: pure numpy/scipy, no simulator, no UI.

Frames and conventions are documented once, in :mod:`calib.frames`. Importing ``calib`` never
imports PyBullet, viser, trimesh or ``planner``.

The public API, by module:

* :mod:`calib.frames` - transforms, Tait-Bryan z-y'-x'' angles (paper eq. 7-9), quaternions.
* :mod:`calib.probing` - :class:`ProbePoint`, :class:`SearchCommand`, :class:`ProbeResult`,
  the :data:`Probe` callback contract.
* :mod:`calib.paper.hultman` - the paper's equations 1-12.
* :mod:`calib.paper.xoffset` - the x-offset matrix (eq. 13-14) and the slot-hole target function.
* :mod:`calib.paper.stator_procedure` - the paper's A-H procedure driven by a probe callback.
* :mod:`calib.estimators.three_two_one` - general 3-2-1 alignment (any non-parallel faces).
* :mod:`calib.estimators.best_fit` - least-squares point-to-plane fit with the 6x6 covariance.
* :mod:`calib.estimators.observability` - does a point layout constrain all 6 DOF, and if not, what
moves.
* :mod:`calib.estimators.runners` - step-by-step 3-2-1 and best-fit runners driven by a probe.
* :mod:`calib.stats` - Table-1 confidence intervals.
* :mod:`calib.plan.file`, :mod:`calib.plan.measurements` - the versioned JSON files.
"""

from calib._version import __version__
from calib.errors import (
    DegenerateGeometryError,
    InputError,
    NonFiniteError,
    ProbeFailedError,
    ShapeError,
    UnobservableError,
    WobjcalError,
)
from calib.estimators.best_fit import BestFitResult, best_fit, best_fit_many
from calib.estimators.observability import ObservabilityReport, analyze_layout, require_observable
from calib.estimators.runners import run_best_fit, run_three_two_one
from calib.estimators.three_two_one import ThreeTwoOneLayout, ThreeTwoOneResult, three_two_one
from calib.paper.hultman import adjust_origin, orientation_from_three_points, p3_estimate
from calib.paper.settings import Hultman2013
from calib.paper.stator_procedure import run_stator_procedure
from calib.paper.xoffset import SlotGrid, slot_target, xoffset_matrix
from calib.probing import Probe, ProbePoint, ProbeResult, SearchCommand, SearchSpec
from calib.stats import ConfidenceTable, confidence_intervals, to_markdown

__all__ = [
    "BestFitResult",
    "ConfidenceTable",
    "DegenerateGeometryError",
    "Hultman2013",
    "InputError",
    "NonFiniteError",
    "ObservabilityReport",
    "Probe",
    "ProbeFailedError",
    "ProbePoint",
    "ProbeResult",
    "SearchCommand",
    "SearchSpec",
    "ShapeError",
    "SlotGrid",
    "ThreeTwoOneLayout",
    "ThreeTwoOneResult",
    "UnobservableError",
    "WobjcalError",
    "__version__",
    "adjust_origin",
    "analyze_layout",
    "best_fit",
    "best_fit_many",
    "confidence_intervals",
    "orientation_from_three_points",
    "p3_estimate",
    "require_observable",
    "run_best_fit",
    "run_stator_procedure",
    "run_three_two_one",
    "slot_target",
    "three_two_one",
    "to_markdown",
    "xoffset_matrix",
]
