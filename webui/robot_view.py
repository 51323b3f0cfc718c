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

from webui.scene import pose_kwargs

logger = logging.getLogger(__name__)


class RobotView:
    """The robot model drawn under ``/robot`` (posed at ``T_world_base``).

    Args:
        server: the viser server.
        urdf_path: the robot URDF; its visual geometry is drawn.
        T_world_base: ``(4, 4)`` robot base in the world frame.
    """

    def __init__(self, server: viser.ViserServer, urdf_path: Path, T_world_base: ArrayLike) -> None:
        self._server = server
        server.scene.add_frame("/robot", show_axes=False, **pose_kwargs(T_world_base))
        self._urdf = ViserUrdf(server, Path(urdf_path), root_node_name="/robot/urdf")
        self.joint_names: tuple[str, ...] = tuple(self._urdf.get_actuated_joint_names())
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
        """Pose the robot at joint values ``q`` (radians, URDF actuated-joint order)."""
        q_arr = np.asarray(q, dtype=np.float64).reshape(-1)
        if q_arr.shape[0] != len(self.joint_names):
            logger.warning(
                "ignoring q of length %d for %d joints", len(q_arr), len(self.joint_names)
            )
            return
        self.q = q_arr
        self._urdf.update_cfg(q_arr)

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

    def stop(self) -> None:
        """Stop a running animation."""
        self._play_stop.set()
        if self._play_thread is not None and self._play_thread is not threading.current_thread():
            self._play_thread.join(1.0)
        self._play_thread = None

    def remove(self) -> None:
        """Remove the robot from the scene."""
        self.stop()
        self._urdf.remove()
        self._server.scene.remove_by_name("/robot")
