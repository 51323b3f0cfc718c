"""The error of a controller's results file."""

from __future__ import annotations

from calib.plan.measurements import MeasurementsError


class ResultsError(MeasurementsError):
    """A results file is malformed, partial or from another program; the message names the
    file and the point, slot or register."""
