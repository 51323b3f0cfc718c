"""The robot in the scene: its URDF visual meshes, posed by joint values, and path playback."""

from __future__ import annotations

import logging
import threading
import time
from pathlib import Path

import numpy as np
import viser
from numpy.typing import ArrayLike
from viser.extras import ViserUrdf

from webui.backend import CellView
from webui.scene import pose_kwargs

logger = logging.getLogger(__name__)


def robot_view_or_reason(server: viser.ViserServer, view: CellView) -> tuple[RobotView | None, str]:
    """The robot drawn in the scene, or ``None`` and why it could not be drawn.

    The robot's visual meshes are only for the eye: a URDF whose visuals cannot be read (e.g.
    COLLADA ``.dae`` files without ``pycollada``) still checks, validates and exports; the
    reason names the file and the fix instead of an "internal error: ImportError".
    """
    try:
        return RobotView(server, view), ""
    except ImportError as exc:
        text = str(exc).lower()
        hint = " (pip install pycollada)" if "collada" in text and "pip" not in text else ""
        why = f"{exc}{hint}"
    except Exception as exc:  # a visual mesh trimesh cannot read: draw no robot, say why
        why = f"{type(exc).__name__}: {exc}"
    server.scene.remove_by_name("/robot")
    server.scene.remove_by_name("/tool")
    return None, (
        f"robot not drawn: the visual meshes of {view.robot_urdf} cannot be read: {why}; the "
        "checks, validation and exports are not affected"
    )


class RobotView:
    """The robot model drawn under ``/robot`` (posed at ``T_world_base``).

    Args:
        server: the viser server.
        view: the cell geometry: robot URDF and base pose, tool, kinematic chain.
    """

    def __init__(self, server: viser.ViserServer, view: CellView) -> None:
        self._server = server
        self._view = view
        server.scene.add_frame("/robot", show_axes=False, **pose_kwargs(view.T_world_base))
        if view.robot_urdf is None:
            raise ValueError("the cell has no robot URDF to draw")
        self._urdf = ViserUrdf(server, Path(view.robot_urdf), root_node_name="/robot/urdf")
        self._tool: ViserUrdf | None = None
        self._tool_frame: viser.FrameHandle | None = None
        if view.chain is not None and (view.tool_urdf is not None or view.tool_mesh is not None):
            self._tool_frame = server.scene.add_frame("/tool", show_axes=False)
            if view.tool_urdf is not None:
                self._tool = ViserUrdf(server, Path(view.tool_urdf), root_node_name="/tool/urdf")
            elif (mesh := view.tool_mesh) is not None:
                server.scene.add_mesh_simple(
                    "/tool/mesh",
                    np.asarray(mesh.vertices, np.float32),
                    np.asarray(mesh.faces, np.uint32),
                    color=(90, 90, 100),
                )
        urdf_names = tuple(self._urdf.get_actuated_joint_names())
        #: joint names in the order of ``q`` (the chain's order when there is a chain)
        chain_names = () if view.chain is None else tuple(view.chain.joint_names)
        self.joint_names: tuple[str, ...] = (
            chain_names if set(chain_names) == set(urdf_names) else urdf_names
        )
        self._to_urdf = np.array([self.joint_names.index(n) for n in urdf_names], dtype=int)
        self._play_stop = threading.Event()
        self._play_thread: threading.Thread | None = None
        self.q = np.zeros(len(self.joint_names))
        self.set_q(self._home())

    def _home(self) -> np.ndarray:
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
        with self._server.atomic():
            self._urdf.update_cfg(q_arr[self._to_urdf])
            T = self._view.T_world_flange(q_arr)
            if T is not None and self._tool_frame is not None:
                pose = pose_kwargs(T @ self._view.T_flange_tool)
                self._tool_frame.wxyz = pose["wxyz"]
                self._tool_frame.position = pose["position"]

    def play(self, q_path: ArrayLike, duration_s: float = 2.0, loops: int = 1) -> None:
        """Animate ``q_path (M, n)`` in a background thread (stops a running animation)."""
        path = np.asarray(q_path, dtype=np.float64)
        self.stop()
        self._play_stop = stop = threading.Event()

        def run() -> None:
            dt = duration_s / max(len(path) - 1, 1)
            for _ in range(loops):
                for q in path:
                    if stop.is_set():
                        return
                    self.set_q(q)
                    time.sleep(dt)

        self._play_thread = threading.Thread(target=run, name="wobjcal-play", daemon=True)
        self._play_thread.start()

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for a running animation to end; True when none is running any more."""
        thread = self._play_thread
        if thread is not None:
            thread.join(timeout)
            return not thread.is_alive()
        return True

    def stop(self) -> None:
        """Stop a running animation."""
        self._play_stop.set()
        if self._play_thread is not None and self._play_thread is not threading.current_thread():
            self._play_thread.join(1.0)
        self._play_thread = None

    def remove(self) -> None:
        """Remove the robot from the scene."""
        self.stop()
        # removing the root nodes removes every link under them
        self._server.scene.remove_by_name("/robot")
        self._server.scene.remove_by_name("/tool")
