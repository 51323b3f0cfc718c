"""What the controllers write back after a measuring run, read into measurements.

Owns the readers of each controller's results (:func:`read_results`): the RAPID program's JSON
(``wobjcal.measurements/1``), the KRL data list as the controller saves it (``.dat``), the
URScript program's log lines and the FANUC register backups (``POSREG.VA`` and
``NUMREG.VA``), with the register, unit and frame conversions each needs, and the detection of
which one a file is. Each reader knows its controller's program from the plan (its slots, its
registers) through :mod:`planner.export`, the writer of that program; a malformed or partial
file is one :class:`ResultsError` naming the file and the point or register.
"""

from planner.results.errors import ResultsError
from planner.results.read import KINDS, ControllerResults, detect_kind, read_results

__all__ = ["KINDS", "ControllerResults", "ResultsError", "detect_kind", "read_results"]
