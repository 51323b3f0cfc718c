"""The 3-point frame's preview triad (issue 22, item 7): the frame the origin and +x define with
the origin's face normal, as :func:`calib.user_frame.three_point_frame` gives it for a third
point on that face's +y side."""

from __future__ import annotations

import numpy as np

from calib.user_frame import three_point_frame
from webui.frame_panel import preview_frame


def test_the_preview_is_the_frame_a_third_point_on_the_face_gives() -> None:
    o, px = np.array([0.1, -0.2, 0.05]), np.array([0.4, 0.1, 0.05])
    T = preview_frame(o, px, [0.0, 0.0, 1.0])
    assert T is not None
    np.testing.assert_allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-12)
    assert np.linalg.det(T[:3, :3]) > 0.999
    third = o + 0.2 * T[:3, 1] + 0.05 * T[:3, 0]  # on the face, +y side
    np.testing.assert_allclose(T, three_point_frame(o, px, third), atol=1e-12)


def test_a_tilted_normal_is_made_perpendicular_and_a_normal_along_x_gives_none() -> None:
    T = preview_frame([0, 0, 0], [1, 0, 0], [0.3, 0.0, 1.0])
    assert T is not None
    np.testing.assert_allclose(T[:3, 2], [0.0, 0.0, 1.0], atol=1e-12)
    assert preview_frame([0, 0, 0], [1, 0, 0], [2.0, 0.0, 0.0]) is None
    assert preview_frame([0, 0, 0], [0, 0, 0], [0.0, 0.0, 1.0]) is None
