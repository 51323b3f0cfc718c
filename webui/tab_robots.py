"""The robot in every browser tab: one drawing per tab, each with its own pose, and playback.

Each tab shows the robot at its own pose: selecting a point in one tab poses that tab's robot
only (:meth:`TabRobots.set_q` with the tab's client id), while the Teach tab's jog (shared by
the tabs) and a script pose every tab's robot (``client_id=None``). The robot's model (URDF
with its visual meshes) is read once, when the cell loads; a URDF whose visuals cannot be read
is refused then, with the reason (:func:`tab_robots_or_reason`).
"""

from __future__ import annotations

import functools
import logging
import threading
import time

import numpy as np
import viser
import yourdfpy
from numpy.typing import ArrayLike

from webui.backend import CellView
from webui.robot_view import RobotView

logger = logging.getLogger(__name__)


def _read_model(path: str) -> yourdfpy.URDF:
    """The URDF at ``path`` with its visual meshes (as :class:`viser.extras.ViserUrdf` reads it)."""
    from pathlib import Path

    p = Path(path)
    return yourdfpy.URDF.load(
        p,
        build_scene_graph=True,
        build_collision_scene_graph=False,
        load_meshes=True,
        load_collision_meshes=False,
        filename_handler=functools.partial(yourdfpy.filename_handler_magic, dir=p.parent),
    )


def tab_robots_or_reason(
    server: viser.ViserServer, view: CellView, display: str = "shown"
) -> tuple[TabRobots | None, str]:
    """The robot of every tab, or ``None`` and why it cannot be drawn.

    The robot's visual meshes are only for the eye: a URDF whose visuals cannot be read (e.g.
    COLLADA ``.dae`` files without ``pycollada``) still checks, validates and exports; the
    reason names the file and the fix instead of an "internal error: ImportError".
    """
    try:
        return TabRobots(server, view, display), ""
    except ImportError as exc:
        text = str(exc).lower()
        hint = " (pip install pycollada)" if "collada" in text and "pip" not in text else ""
        why = f"{exc}{hint}"
    except Exception as exc:  # a visual mesh trimesh cannot read: draw no robot, say why
        why = f"{type(exc).__name__}: {exc}"
    return None, (
        f"robot not drawn: the visual meshes of {view.robot_urdf} cannot be read: {why}; the "
        "checks, validation and exports are not affected"
    )


class TabRobots:
    """The robot drawn in each connected tab, each at its own pose.

    Args:
        server: the viser server (its connected tabs get a robot at once).
        view: the cell geometry (robot URDF and base pose, tool, chain).
        display: how the tabs draw it (:data:`webui.robot_view.DISPLAYS`).

    Raises:
        ValueError: the cell has no robot URDF; ImportError or a mesh error: its visual
            meshes cannot be read.
    """

    def __init__(self, server: viser.ViserServer, view: CellView, display: str = "shown") -> None:
        if view.robot_urdf is None:
            raise ValueError("the cell has no robot URDF to draw")
        self._server = server
        self._view = view
        self._model = _read_model(str(view.robot_urdf))
        self._model_lock = threading.Lock()  # the model is posed for one tab at a time
        self._lock = threading.RLock()
        self._views: dict[int, RobotView] = {}
        self._players: dict[int | None, tuple[threading.Event, threading.Thread]] = {}
        chain = view.chain
        names = tuple(self._model.actuated_joint_names)
        self.joint_names: tuple[str, ...] = (
            tuple(chain.joint_names)
            if chain is not None and set(chain.joint_names) == set(names)
            else names
        )
        limits = [self._model.joint_map[n].limit for n in self.joint_names]
        lo = [-np.pi if lim is None or lim.lower is None else lim.lower for lim in limits]
        hi = [np.pi if lim is None or lim.upper is None else lim.upper for lim in limits]
        #: ``(n,)`` the pose the tabs share (the jog's, a script's), rad; a new tab starts there.
        self.q = np.clip(np.zeros(len(self.joint_names)), lo, hi)
        self._q_by_client: dict[int, np.ndarray] = {}
        #: how every tab draws the robot (:data:`webui.robot_view.DISPLAYS`)
        self.display = display
        for client in server.get_clients().values():
            self.add_client(client)

    # ---- tabs ------------------------------------------------------------------------------
    def add_client(self, client: viser.ClientHandle) -> None:
        """Draw the robot in a newly connected tab, at the shared pose (once per tab)."""
        with self._lock:
            if client.client_id in self._views:
                return
            robot = RobotView(client, self._view, self._model, self._model_lock, self.display)
            robot.set_q(self.q)
            self._views[client.client_id] = robot
            self._q_by_client[client.client_id] = self.q.copy()

    def set_display(self, display: str) -> None:
        """Draw the robot in every tab ``"shown"``, ``"ghost"`` or ``"hidden"``
        (:data:`webui.robot_view.DISPLAYS`); each tab keeps its pose."""
        from webui.robot_view import DISPLAYS

        if display not in DISPLAYS:
            raise ValueError(f"robot display: one of {', '.join(DISPLAYS)}, got {display!r}")
        with self._lock:
            if display == self.display:
                return
            self.display = display
            clients = self._server.get_clients()
            for cid, old in list(self._views.items()):
                client = clients.get(cid)
                old.remove()
                if client is None:
                    del self._views[cid]
                    continue
                robot = RobotView(client, self._view, self._model, self._model_lock, display)
                robot.set_q(self._q_by_client.get(cid, self.q))
                self._views[cid] = robot

    def remove_client(self, client_id: int) -> None:
        """Forget a tab that disconnected (its scene went with it)."""
        self._stop(client_id)
        with self._lock:
            self._views.pop(client_id, None)
            self._q_by_client.pop(client_id, None)

    def q_of(self, client_id: int | None) -> np.ndarray:
        """``(n,)`` the pose a tab shows (the shared pose for ``None`` or an unknown tab), rad."""
        with self._lock:
            q = None if client_id is None else self._q_by_client.get(client_id)
            return (self.q if q is None else q).copy()

    # ---- posing ----------------------------------------------------------------------------
    def set_q(self, q: ArrayLike, client_id: int | None = None) -> None:
        """Pose one tab's robot (``client_id``) or every tab's and the shared pose (``None``),
        ``q`` in radians in :attr:`joint_names` order."""
        qa = np.asarray(q, dtype=np.float64).reshape(-1)
        if qa.shape[0] != len(self.joint_names):
            logger.warning("ignoring q of length %d for %d joints", len(qa), len(self.joint_names))
            return
        with self._lock:
            if client_id is None:
                self.q = qa.copy()
                targets = dict(self._views)
            else:
                view = self._views.get(client_id)
                targets = {} if view is None else {client_id: view}
            for cid in targets:
                self._q_by_client[cid] = qa.copy()
        for view in targets.values():
            view.set_q(qa)

    def play(
        self,
        q_path: ArrayLike,
        duration_s: float = 2.0,
        loops: int = 1,
        client_id: int | None = None,
    ) -> None:
        """Animate ``q_path (M, n)`` in one tab (or every tab) on a background thread; a
        running animation of the same tab (for every tab: of any tab) stops first."""
        path = np.asarray(q_path, dtype=np.float64)
        stop = threading.Event()

        def run() -> None:
            dt = duration_s / max(len(path) - 1, 1)
            for _ in range(loops):
                for q in path:
                    if stop.is_set():
                        return
                    self.set_q(q, client_id)
                    time.sleep(dt)

        thread = threading.Thread(target=run, name="wobjcal-play", daemon=True)
        with self._lock:  # one step: two plays at once never leave one running unstoppable
            keys = list(self._players) if client_id is None else [client_id]
            old = [self._players.pop(k) for k in keys if k in self._players]
            self._players[client_id] = (stop, thread)
            thread.start()  # registered threads are started ones (join needs that)
        for old_stop, old_thread in old:  # every tab's, for an animation in every tab
            old_stop.set()
            if old_thread is not threading.current_thread():
                old_thread.join(1.0)

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for running animations to end; True when none is running any more."""
        with self._lock:
            threads = [t for _, t in self._players.values()]
        for thread in threads:
            thread.join(timeout)
        return not any(t.is_alive() for t in threads)

    def _stop(self, client_id: int | None) -> None:
        with self._lock:
            player = self._players.pop(client_id, None)
        if player is not None:
            player[0].set()
            if player[1] is not threading.current_thread():
                player[1].join(1.0)

    def stop(self) -> None:
        """Stop every running animation."""
        with self._lock:
            keys = list(self._players)
        for key in keys:
            self._stop(key)

    def remove(self) -> None:
        """Remove the robot from every tab."""
        self.stop()
        with self._lock:
            views, self._views = dict(self._views), {}
            self._q_by_client.clear()
        for view in views.values():
            view.remove()
