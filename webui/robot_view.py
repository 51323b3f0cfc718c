"""The robot drawn in one scene (the server's or one browser tab's): its URDF visual meshes and
tool, posed by joint values. :mod:`webui.tab_robots` keeps one per browser tab."""

from __future__ import annotations

import logging
import threading

import numpy as np
import viser
import yourdfpy
from numpy.typing import ArrayLike
from viser.extras import ViserUrdf

from webui.backend import CellView
from webui.scene import pose_kwargs

logger = logging.getLogger(__name__)

#: How the robot and its tool are drawn.
DISPLAYS = ("shown", "ghost", "hidden")
#: The ghost's colour and opacity (0-1).
GHOST_RGBA = (0.72, 0.74, 0.80, 0.22)


class RobotView:
    """The robot model drawn under ``/robot`` (posed at ``T_world_base``) and its tool under
    ``/tool``, in the scene of ``target``.

    Args:
        target: the server (every tab) or one tab's client handle.
        view: the cell geometry: robot URDF and base pose, tool, kinematic chain.
        urdf: the robot's model with its visual meshes loaded (shared by the tabs' views;
            posing it is serialized by ``lock``).
        lock: held while the shared model is posed.
        display: ``"shown"``, ``"ghost"`` (translucent grey: the part and points behind it
            show) or ``"hidden"``.
    """

    def __init__(
        self,
        target: viser.ViserServer | viser.ClientHandle,
        view: CellView,
        urdf: yourdfpy.URDF,
        lock: threading.Lock,
        display: str = "shown",
    ) -> None:
        if display not in DISPLAYS:
            raise ValueError(f"robot display: one of {', '.join(DISPLAYS)}, got {display!r}")
        self._target = target
        self._view = view
        self._lock = lock
        self.display = display
        ghost = GHOST_RGBA if display == "ghost" else None
        root = target.scene.add_frame("/robot", show_axes=False, **pose_kwargs(view.T_world_base))
        with lock:  # the shared model is read while the meshes are added
            self._urdf = ViserUrdf(
                target, urdf, root_node_name="/robot/urdf", mesh_color_override=ghost
            )
        self._tool: ViserUrdf | None = None
        self._tool_frame: viser.FrameHandle | None = None
        if view.chain is not None and (view.tool_urdf is not None or view.tool_mesh is not None):
            self._tool_frame = target.scene.add_frame("/tool", show_axes=False)
            if view.tool_urdf is not None:
                self._tool = ViserUrdf(
                    target, view.tool_urdf, root_node_name="/tool/urdf", mesh_color_override=ghost
                )
            elif (mesh := view.tool_mesh) is not None:
                target.scene.add_mesh_simple(
                    "/tool/mesh",
                    np.asarray(mesh.vertices, np.float32),
                    np.asarray(mesh.faces, np.uint32),
                    color=(90, 90, 100),
                    opacity=GHOST_RGBA[3] if ghost else None,
                )
        if display == "hidden":
            root.visible = False
            if self._tool_frame is not None:
                self._tool_frame.visible = False
        urdf_names = tuple(self._urdf.get_actuated_joint_names())
        #: joint names in the order of ``q`` (the chain's order when there is a chain)
        chain_names = () if view.chain is None else tuple(view.chain.joint_names)
        self.joint_names: tuple[str, ...] = (
            chain_names if set(chain_names) == set(urdf_names) else urdf_names
        )
        self._to_urdf = np.array([self.joint_names.index(n) for n in urdf_names], dtype=int)
        self.q = np.zeros(len(self.joint_names))

    def home(self) -> np.ndarray:
        """``(n,)`` zero joint values clipped into the URDF's limits, rad."""
        limits = self._urdf.get_actuated_joint_limits()
        q = []
        for name in self.joint_names:
            lo, hi = limits[name]
            lo = -np.pi if lo is None else lo
            hi = np.pi if hi is None else hi
            q.append(float(np.clip(0.0, lo, hi)))
        return np.asarray(q)

    def set_q(self, q: ArrayLike) -> None:
        """Pose the robot and its tool at ``q`` (radians, in :attr:`joint_names` order)."""
        q_arr = np.asarray(q, dtype=np.float64).reshape(-1)
        if q_arr.shape[0] != len(self.joint_names):
            logger.warning(
                "ignoring q of length %d for %d joints", len(q_arr), len(self.joint_names)
            )
            return
        self.q = q_arr
        with self._lock, self._target.atomic():
            self._urdf.update_cfg(q_arr[self._to_urdf])
            T = self._view.T_world_flange(q_arr)
            if T is not None and self._tool_frame is not None:
                pose = pose_kwargs(T @ self._view.T_flange_tool)
                self._tool_frame.wxyz = pose["wxyz"]
                self._tool_frame.position = pose["position"]

    def remove(self) -> None:
        """Remove the robot and its tool from the scene (removing the root nodes removes every
        link under them)."""
        self._target.scene.remove_by_name("/robot")
        self._target.scene.remove_by_name("/tool")
