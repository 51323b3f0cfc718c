"""The moves of the plan in the 3D view: the via points and the checked joint moves.

Each via (``points[i].vias``, joint values) is drawn where the probing TCP is at its joint
values: a small near-black sphere (distinct from the probe markers' status colours
and from their size), and a thin near-black polyline from the via(s) to the point they lead to
(the TCP at the point's checked pose, else the point itself); redrawn only when the vias or
their points change (a click that edits no via sends nothing).

:func:`draw_moves` (the Teach tab's "Show moves between points") draws the joint moves from each
point's safe start through the next point's vias to its safe start (the program's moves), green when
clear and red when they collide, checked by :func:`planner.cell.moves.check_via_path` as ``wobjcal
check`` does.
"""

from __future__ import annotations

import itertools
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from calib.frames import transform_points

if TYPE_CHECKING:
    from webui.context import AppContext

#: Colour of via markers and paths (near black: no status colour, not the selection's blue).
VIA_RGB = (35, 35, 40)
#: Radius of a via marker, m.
VIA_RADIUS_M = 0.008
ROOT = "/vias"


class ViaView:
    """Draws the vias of the edited plan (see the module docstring).

    Args:
        app: the app whose plan and scene to use.
    """

    def __init__(self, app: AppContext) -> None:
        self._app = app
        self._drawn: Any = None
        #: ``{point id: (k, 3) via TCP positions, world, m}`` of the last drawing.
        self.positions: dict[str, NDArray[np.float64]] = {}

    def _key(self) -> Any:
        doc = self._app.state.doc
        vias = tuple(
            (p.id, p.probe.position_m, tuple(tuple(v.q_rad) for v in p.vias))
            for p in doc.points
            if p.vias
        )
        view = self._app.view
        return vias, None if view is None else view.T_world_wobj.tobytes()

    def draw(self, force: bool = False) -> None:
        """Draw the vias (nothing is sent when they did not change, unless ``force``)."""
        key = self._key()
        if key == self._drawn and not force:
            return
        scene = self._app.server.scene
        if self._drawn is not None and self._drawn[0]:
            scene.remove_by_name(ROOT)
        self._drawn = key
        self.positions = {}
        view = self._app.view
        if not key[0] or view is None or view.chain is None:
            return
        source = self._app.state.doc.source
        tcp = "sensor" if source is None else source.cell.tool.tcp
        for p in self._app.state.doc.points:
            if not p.vias:
                continue
            qs = [np.asarray(v.q_rad, dtype=np.float64) for v in p.vias]
            if any(len(q) != view.chain.n_joints for q in qs):
                continue  # the check names the wrong count
            pts = np.array(
                [self._app.worker.call(lambda s, q=q: s.T_world_tcp(q, tcp))[:3, 3] for q in qs]
            )
            self.positions[p.id] = pts
            for k, x in enumerate(pts, start=1):
                scene.add_icosphere(
                    f"{ROOT}/{p.id}/v{k}",
                    radius=VIA_RADIUS_M,
                    color=VIA_RGB,
                    subdivisions=1,
                    position=x,
                )
            check = self._app.check_of(p.id)
            end = (
                transform_points(view.T_world_wobj, p.probe.position_m)
                if check is None or check.T_base_tcp is None
                else (view.T_world_base @ check.T_base_tcp)[:3, 3]
            )
            line = np.vstack([pts, end[None]])
            scene.add_line_segments(
                f"{ROOT}/{p.id}/path",
                points=np.stack([line[:-1], line[1:]], axis=1),
                colors=VIA_RGB,
                thickness=2.0,
                thickness_units="screen",
            )


def draw_moves(app: AppContext, tcp: str) -> tuple[dict[str, str], str]:
    """Draw and check the joint moves between the safe starts of consecutive points with a
    feasible pose (through the vias of the later point), under ``/moves``.

    Returns:
        ``({"A->B": problem}, markdown)``: ``""`` for a clear move; the lines for the panel.
    """
    scene = app.server.scene
    doc, checks = app.state.doc, app.checks()
    posed = [  # where the program arrives at and leaves each point: its safe start
        (p.id, c.q_safe)
        for p in doc.points
        if (c := checks.get(p.id)) is not None and c.q_safe is not None and c.status != "infeasible"
    ]
    moves: dict[str, str] = {}
    lines = []
    for (a, qa), (b, qb) in itertools.pairwise(posed):
        vias = [np.asarray(v.q_rad) for v in doc.get(b).vias]
        path = app.worker.call(
            lambda s, qa=qa, qb=qb, vias=vias: s.check_via_path(qa, vias, qb, tcp)
        )
        moves[f"{a}->{b}"] = path.problem
        for k, (_na, _nb, move) in enumerate(path.legs):
            tcp_path = move.tcp_path_world
            scene.add_line_segments(
                f"/moves/{a}_{b}_{k}",
                points=np.stack([tcp_path[:-1], tcp_path[1:]], axis=1),
                colors=(215, 40, 40) if move.problem else (40, 170, 60),
                thickness=2.0,
                thickness_units="screen",
            )
        via = f" (through {len(vias)} via{'s' if len(vias) > 1 else ''})" if vias else ""
        lines.append(f"- {a} → {b}{via}: {path.problem or 'clear'}")
    skipped = [p.id for p in doc.points if p.id not in dict(posed)]
    if skipped:
        lines.append(f"- left out (no feasible pose): {', '.join(skipped)}")
    return moves, "\n".join(lines) or "no two points with a pose"
