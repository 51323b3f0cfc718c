"""wobjcal calibration core: pure numpy/scipy, no simulator, no UI.

Frames and conventions are documented once, in :mod:`calib.frames`. Importing ``calib`` never
imports PyBullet, viser, trimesh or ``planner``.

Owns:
    - foundations: :mod:`calib.frames` (transforms, Tait-Bryan z-y'-x'' angles of eq. 7-9,
      quaternions), :mod:`calib.errors`, :mod:`calib.arguments` and :mod:`calib.structs`
      (argument and field checks), :mod:`calib.probing` (probe points, search commands, the
      :data:`Probe` callback contract), :mod:`calib.plane_probe` (the one ideal probe: searches
      answered on the nominal faces' planes), :mod:`calib.procedure_run` (``ProcedureRun``:
      what every procedure run returns), :mod:`calib.units`, :mod:`calib.atomic_io`;
    - :mod:`calib.paper`: the paper's equations and its A-H procedure;
    - :mod:`calib.estimators`: 3-2-1, best fit with covariance, observability, step runners;
    - :mod:`calib.procedures`: the registry of procedures a plan can name;
    - :mod:`calib.models`: the physical models (sensor, robot error, misplacement);
    - :mod:`calib.plan`: the versioned plan and measurement files;
    - :mod:`calib.stats`: Table-1 confidence intervals.
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
