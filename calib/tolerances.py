"""What counts as "the same face", "one plane" and "a plausible number": the one table.

Real meshes are not exact: a face of a float32 PLY is made of triangles whose normals differ
in the 7th digit, a point clicked in the UI lands on the picked triangle with that triangle's
normal, and a scanned or bolted face is flat only to a fraction of a millimetre. The planar-face
detection (:mod:`planner.faces.detection`), the 3-2-1 layout
(:mod:`calib.estimators.three_two_one`), the A-H layout (:mod:`calib.paper.stator_layout`), the
procedure's role picking (:mod:`calib.procedures.three_two_one`) and the gross-error screen of
``wobjcal calibrate`` all read their tolerances here, so a plan the check accepts is a plan the
calibration accepts.

Values, and why:

- :data:`FACE_FLATNESS_RMS_M` 0.1 mm: the stator's tightening bolts bulge its side face by up
  to 0.3 mm (about 0.055 mm RMS) and the paper still measures it as one plane;
- :data:`FACE_MAX_DEVIATION_M` 0.5 mm: the largest distance of a point of one face from its
  plane; points of one role (3-2-1) or of the A-H side face must be coplanar within it;
- :data:`FACE_ANGLE_TOL_RAD` 3 deg: triangles of one detected face may turn this much;
- :data:`ROLE_NORMAL_TOL_RAD` 0.5 deg: two plan normals within this angle belong to one face
  (and an A-H normal within it of its axis is that axis): a fraction of a degree, far above
  float32 round-off (1e-6 rad) and far below any angle between two real faces;
- :data:`COORDINATE_LIMIT_M` 1 km: no cell coordinate (plan position, measured point) is larger;
  ``1e308`` is a typo or an attack, refused with the field named before any arithmetic.
"""

from __future__ import annotations

import math

#: Largest area-weighted RMS distance of a planar face from its fitted plane, m.
FACE_FLATNESS_RMS_M = 1.0e-4
#: Largest distance of any point of one planar face from its plane, m (coplanarity).
FACE_MAX_DEVIATION_M = 5.0e-4
#: Largest angle between triangle normals (and to the fitted plane) within one face, rad.
FACE_ANGLE_TOL_RAD = math.radians(3.0)
#: Largest angle between two plan normals of points on one face, rad.
ROLE_NORMAL_TOL_RAD = math.radians(0.5)
#: Largest magnitude of any coordinate in a plan or measurements file, m.
COORDINATE_LIMIT_M = 1000.0


def same_direction(cos_angle: float, tol_rad: float = ROLE_NORMAL_TOL_RAD) -> bool:
    """True when two unit vectors with dot product ``cos_angle`` are within ``tol_rad``."""
    return cos_angle >= math.cos(tol_rad)


__all__ = [
    "COORDINATE_LIMIT_M",
    "FACE_ANGLE_TOL_RAD",
    "FACE_FLATNESS_RMS_M",
    "FACE_MAX_DEVIATION_M",
    "ROLE_NORMAL_TOL_RAD",
    "same_direction",
]
