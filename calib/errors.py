"""The exception hierarchy of wobjcal.

Every error wobjcal raises on purpose derives from :class:`WobjcalError`. Errors about bad
input also derive from :class:`ValueError`, so callers that only know the standard library can
still catch them. Messages name the offending argument, field or file and say what was expected.

``planner`` adds its own subclasses (URDF, mesh, unknown frame, unreachable target) on top of
these; ``calib`` never raises anything from numpy or scipy at its public boundary.
"""

from __future__ import annotations


class WobjcalError(Exception):
    """Base class of every error wobjcal raises on purpose."""


class InputError(WobjcalError, ValueError):
    """An argument, field or file has the wrong shape, type, unit or value."""


class PlanError(InputError):
    """A plan file, a model in it or a plan object is malformed.

    The message names the file and the JSON path (``points[3].normal: must have length 3``).
    """


class ShapeError(InputError):
    """An array has the wrong shape, e.g. ``points must be (N, 3), got (4, 2)``."""


class NonFiniteError(InputError):
    """An array holds NaN or infinity where finite numbers are required."""


class DegenerateGeometryError(InputError):
    """A point layout or face set cannot define a frame.

    Examples: collinear or coincident points, parallel faces, a zero-length search direction.
    """


class UnobservableError(DegenerateGeometryError):
    """A point layout leaves one or more of the 6 degrees of freedom unconstrained.

    Attributes:
        unconstrained: human-readable descriptions of each unconstrained motion, e.g.
            ``"translation along wobj z"``.
    """

    def __init__(self, message: str, unconstrained: tuple[str, ...] = ()) -> None:
        super().__init__(message)
        self.unconstrained = unconstrained


class ProbeFailedError(WobjcalError):
    """A measurement in a calibration procedure returned no point.

    Attributes:
        point_id: id of the probe point that failed, e.g. ``"C"``.
        reason: why the probe failed, as reported by the probe callback.
    """

    def __init__(self, point_id: str, reason: str) -> None:
        super().__init__(f"probe {point_id!r} failed: {reason}")
        self.point_id = point_id
        self.reason = reason
