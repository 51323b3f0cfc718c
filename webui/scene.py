"""Drawing the cell in viser: work object, frames, probe points, approach arrows, search paths.

Everything is drawn on the server-wide scene so that every browser tab sees the same plan.
Points live under the ``/wobj`` node (posed at ``T_world_wobj``), so their coordinates are the
plan's wobj-frame coordinates. Colours follow the feasibility status.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import trimesh
import viser
from numpy.typing import ArrayLike, NDArray

from calib.frames import quat_wxyz_from_matrix
from calib.probing import SearchCommand
from planner.check.job import PointCheck
from webui.plan_doc import UiPlan, UiPoint

#: RGB colour of each feasibility status (``pending``: being computed; ``role``: the point is
#: on a face, or holds a role, its procedure cannot use); ``unknown`` is the fallback colour
#: of any other status.
STATUS_RGB: dict[str, tuple[int, int, int]] = {
    "feasible": (40, 170, 60),
    "marginal": (240, 165, 0),
    "infeasible": (215, 40, 40),
    "role": (190, 60, 200),
    "pending": (150, 150, 150),
    "unknown": (110, 110, 140),
}
#: What each colour means, for the legend (:func:`legend_html`).
STATUS_MEANING: dict[str, str] = {
    "feasible": "reachable, search path clear",
    "marginal": "little clearance or near a joint limit",
    "infeasible": "out of reach, at a limit, colliding or off a planar face",
    "role": "the procedure cannot use the point there (its role or face); red if infeasible",
    "pending": "being checked",
}
WOBJ_RGB = (170, 185, 200)
#: The colour overlays of the work object (:meth:`Scene.color_work_object`), by layer: the scene
#: node and how far it lies out of the surface, m (the validation's error over the layout's
#: predicted error over the reachability heat map; clicks still hit the part's own mesh).
OVERLAYS: dict[str, tuple[str, float]] = {
    "reach": ("/wobj/heat_mesh", 0.0005),
    "quality": ("/wobj/quality_mesh", 0.00075),
    "error": ("/wobj/error_mesh", 0.001),
}
SELECTED_RGB = (60, 120, 255)
MARKER_RADIUS_M = 0.008


def configure_lighting(scene: viser.SceneApi) -> None:
    """Light the cell cheaply: viser's two directional lights without their cascaded shadow
    maps, no image-based (environment map) lighting, a hemisphere light for the faces the
    directional lights miss.

    The page renders with software WebGL on the machines this runs on (headless Chromium,
    SwiftShader; no GPU): there the shadows (three cascades, each a pass over the scene, and
    filtered lookups per pixel) and the environment map's per-pixel lookups cost most of each
    frame, and every update the page shows waits for a frame (``bench/bench_ui_render.py``).
    """
    scene.configure_default_lights(enabled=True, cast_shadow=False)
    scene.configure_environment_map(None)
    # side lights from four directions: URDF visuals come as glTF meshes, metallic by the
    # glTF default, which only specular light (never an ambient or hemisphere light) shows
    for k, (x, y) in enumerate(((1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0))):
        scene.add_light_directional(
            f"/lights/side_{k}", intensity=1.2, position=(x, y, 0.6), cast_shadow=False
        )
    scene.add_light_hemisphere(
        "/lights/fill", sky_color=(255, 255, 255), ground_color=(110, 110, 120), intensity=1.0
    )


def pose_kwargs(T: ArrayLike) -> dict[str, Any]:
    """viser ``wxyz``/``position`` keyword arguments of a 4x4 transform."""
    T_arr = np.asarray(T, dtype=np.float64)
    return {"wxyz": quat_wxyz_from_matrix(T_arr[:3, :3]), "position": T_arr[:3, 3].copy()}


def search_segment_wobj(point: UiPoint) -> NDArray[np.float64]:
    """``(2, 3)`` start and end of the point's search (sensor TCP), wobj frame, metres."""
    cmd = SearchCommand.from_point(point.probe, np.eye(4))
    return np.stack([cmd.start_m, cmd.start_m + cmd.length_m * cmd.direction])


class PlanScene:
    """The server-wide 3D scene of one session.

    Args:
        server: the viser server (its scene is shared by all clients).
    """

    def __init__(self, server: viser.ViserServer) -> None:
        self._server = server
        self._scene = server.scene
        self.wobj_mesh_handle: viser.MeshHandle | None = None
        self._point_nodes: dict[str, list[Any]] = {}
        self._heat: Any = None
        self._wobj_mesh: trimesh.Trimesh | None = None

    def color_work_object(
        self,
        vertex_rgb: ArrayLike | None,
        mesh: trimesh.Trimesh | None = None,
        layer: str = "reach",
    ) -> None:
        """Overlay the work object with per-vertex colours (``(V, 3)`` uint8), or remove it.

        ``mesh``: a refined copy of the work object (wobj frame) the colours belong to;
        default the work object itself. ``layer``: whose colours (:data:`OVERLAYS`: the
        reachability heat map, the layout's predicted error, the validation's simulated
        error); each is an overlay of its own, a hair further out than the one before, so one
        panel's colours never remove another's and the later layer shows while both are on.
        """
        name, lift_m = OVERLAYS[layer]
        if vertex_rgb is None or self._wobj_mesh is None:
            self._scene.remove_by_name(name)
            return
        colored = (self._wobj_mesh if mesh is None else mesh).copy()
        rgb = np.asarray(vertex_rgb, dtype=np.uint8)
        colored.visual = trimesh.visual.ColorVisuals(
            colored, vertex_colors=np.hstack([rgb, np.full((len(rgb), 1), 255, np.uint8)])
        )
        # a hair above the surface so the colours win the depth test; clicks still hit the mesh
        colored.vertices = colored.vertices + lift_m * colored.vertex_normals
        self._scene.add_mesh_trimesh(name, colored)

    def draw_work_object(self, mesh: trimesh.Trimesh, T_world_wobj: ArrayLike) -> viser.MeshHandle:
        """Draw the work object (wobj frame mesh) and the nominal WOCS axes at ``T_world_wobj``."""
        self._wobj_mesh = mesh
        self._scene.add_frame(
            "/wobj", axes_length=0.12, axes_radius=0.004, **pose_kwargs(T_world_wobj)
        )
        self.wobj_mesh_handle = self._scene.add_mesh_simple(
            "/wobj/mesh",
            np.asarray(mesh.vertices, dtype=np.float32),
            np.asarray(mesh.faces, dtype=np.uint32),
            color=WOBJ_RGB,
            flat_shading=True,
        )
        self._scene.add_label(
            "/wobj/name",
            "WOCS",
            position=(0.0, 0.0, 0.0),
            anchor="top-right",
            font_screen_scale=0.8,
        )
        return self.wobj_mesh_handle

    def draw_fixtures(self, fixtures: Mapping[str, tuple[trimesh.Trimesh, ArrayLike]]) -> None:
        """Draw fixed obstacles ``{name: (mesh, T_world_fixture)}`` (the earlier cell's, even
        ones of the same name, are removed first)."""
        self._scene.remove_by_name("/fixtures")
        for name, (mesh, T) in fixtures.items():
            self._scene.add_mesh_simple(
                f"/fixtures/{name}",
                np.asarray(mesh.vertices, dtype=np.float32),
                np.asarray(mesh.faces, dtype=np.uint32),
                color=(120, 110, 100),
                **pose_kwargs(T),
            )

    def draw_calibrated_frame(self, T_world_wobj: ArrayLike | None) -> None:
        """Show (or with ``None`` hide) the calibrated WOCS frame."""
        if T_world_wobj is None:
            self._scene.remove_by_name("/wobj_calibrated")
            return
        self._scene.add_frame(
            "/wobj_calibrated", axes_length=0.15, axes_radius=0.003, **pose_kwargs(T_world_wobj)
        )
        self._scene.add_label(
            "/wobj_calibrated/name", "WOCS cal.", anchor="bottom-right", font_screen_scale=0.8
        )

    def draw_points(
        self,
        plan: UiPlan,
        checks: Mapping[str, PointCheck],
        selected: str | None = None,
        only: list[str] | None = None,
        flags: Mapping[str, str] | None = None,
    ) -> None:
        """Draw the points of ``plan`` (or just those in ``only``), coloured by their check;
        the marker of a point ``flags`` names (its procedure cannot use it) is in the ``role``
        colour unless the point is infeasible (red wins: the role must not hide it), and its
        arrow and search line keep the check's colour.

        Points no longer in the plan are removed.
        """
        flags = flags or {}
        for pid in set(self._point_nodes) - set(plan.ids):
            self._remove_point(pid)
        wanted = None if only is None else set(only)
        with self._server.atomic():
            for point in plan.points:
                if wanted is None or point.id in wanted:
                    self.draw_point(
                        point, checks.get(point.id), selected == point.id, point.id in flags
                    )

    def draw_point(
        self,
        point: UiPoint,
        check: PointCheck | None,
        selected: bool = False,
        flagged: bool = False,
    ) -> None:
        """Draw (or redraw) one point: marker, its id as label, approach arrow and search path.

        The label is the id only (the status is the colour, the reason is in the points table):
        short labels next to their marker, hidden behind the part (depth-tested).
        """
        status: str = "pending" if check is None else check.status
        rgb = STATUS_RGB.get(status, STATUS_RGB["unknown"])  # the arrow and the search line
        marker_rgb = rgb
        if flagged and status not in ("pending", "infeasible"):  # infeasible stays red
            marker_rgb = STATUS_RGB["role"]
        p = np.asarray(point.probe.position_m, dtype=np.float64)
        n = np.asarray(point.probe.normal, dtype=np.float64)
        base = f"/wobj/points/{point.id}"
        seg = search_segment_wobj(point)
        approach_len = max(point.probe.search.start_offset_m, 0.02)
        tail = p + n * (approach_len + 0.01)
        nodes = [
            self._scene.add_icosphere(
                f"{base}/marker",
                radius=MARKER_RADIUS_M * (1.5 if selected else 1.0),
                color=SELECTED_RGB if selected else marker_rgb,
                subdivisions=2,
                position=p,
            ),
            self._scene.add_label(
                f"{base}/label",
                point.id,
                position=p + 0.012 * n,
                anchor="bottom-left",
                depth_test=True,
                font_screen_scale=0.9,
            ),
            self._scene.add_arrows(
                f"{base}/approach",
                points=np.stack([tail, p + n * 0.004])[None, :, :],
                colors=rgb,
                shaft_radius=0.002,
                head_radius=0.005,
                head_length=0.01,
            ),
            self._scene.add_line_segments(
                f"{base}/search",
                points=seg[None, :, :],
                colors=rgb,
                thickness=3.0,
                thickness_units="screen",
            ),
        ]
        self._point_nodes[point.id] = nodes

    def _remove_point(self, point_id: str) -> None:
        self._scene.remove_by_name(f"/wobj/points/{point_id}")
        self._point_nodes.pop(point_id, None)

    def show_heat_map(self, points_wobj: ArrayLike | None, rgb: ArrayLike | None = None) -> None:
        """Show reachability samples on the work object as coloured dots, or hide them (None)."""
        if points_wobj is None or rgb is None:
            self._scene.remove_by_name("/wobj/heat")
            self._heat = None
            return
        self._heat = self._scene.add_point_cloud(
            "/wobj/heat",
            points=np.asarray(points_wobj, dtype=np.float32),
            colors=np.asarray(rgb, dtype=np.uint8),
            point_size=0.006,
            point_shape="circle",
        )


def legend_html(
    entries: Mapping[str, str] = STATUS_MEANING,
    colours: Mapping[str, tuple[int, int, int]] = STATUS_RGB,
) -> str:
    """HTML of a colour legend: a swatch of ``colours`` and the meaning, per entry."""
    rows = []
    for status, meaning in entries.items():
        r, g, b = colours.get(status, STATUS_RGB["unknown"])
        rows.append(
            f'<div style="display:flex;gap:6px;align-items:center;font-size:0.8em">'
            f'<span style="width:12px;height:12px;border-radius:6px;flex:none;'
            f'background:rgb({r},{g},{b})"></span><b>{status}</b> {meaning}</div>'
        )
    return "".join(rows)


def heat_rgb(score: ArrayLike) -> NDArray[np.uint8]:
    """Colours of scores in [0, 1]: red (0, unreachable) through amber to green (1)."""
    s = np.clip(np.asarray(score, dtype=np.float64), 0.0, 1.0)[:, None]
    red = np.array(STATUS_RGB["infeasible"], float)
    amber = np.array(STATUS_RGB["marginal"], float)
    green = np.array(STATUS_RGB["feasible"], float)
    low = red + (amber - red) * np.clip(2 * s, 0, 1)
    out = np.where(s < 0.5, low, amber + (green - amber) * np.clip(2 * s - 1, 0, 1))
    return out.round().astype(np.uint8)
