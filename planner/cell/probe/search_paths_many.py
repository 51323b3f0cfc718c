"""Many search paths at once, each run with its program's pose: the vetting of simulated searches.

A vetted simulated trial runs about 54 searches (the A-H program's and the x-offset run's 42),
each vetted in the cell with the sensor rotation and IK branch of the point's checked pose
(:func:`planner.sim.search_events.program_search_hook`), all of them in one call after the trial
(:meth:`planner.sim.trial.TrialRunner.run_trial`): :func:`check_searches` gives, for each,
exactly what
:func:`~planner.cell.probe.search_paths.check_search` gives with that pose, ``max_starts=1``
and ``exact_clearance=False``, but solves the IK of all starts in one call, of all paths'
samples in another, and runs the broad phase once over every sample
(:func:`planner.cell.broad.first_failures`). Per search that is one call of each instead of
three, and the per-call work (argument checks, frames, solver set-up) is done once.

Only an analytic (OPW) solver is batched: it returns every branch whatever the seeds, so a
pose's solutions do not depend on the poses solved with it. A numeric solver starts from each
search's own seed, and a search whose start has no usable solution needs the reason
:func:`check_search` words; both go to :func:`check_search` one by one, as do searches of any
branch (``branch < 0``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from calib.arguments import check_positive, check_shape, check_vector3
from calib.frames import invert_transform
from planner.cell.broad import first_failures
from planner.cell.probe.feasibility import singular, tcp_frames
from planner.cell.probe.search_paths import (
    PathFeasibility,
    check_search,
    follow_branch,
    path_verdict,
    sampled_path,
    sensor_angle,
)
from planner.cell.scene import DEFAULT_MARGIN_M

if TYPE_CHECKING:
    from calib.probing import SearchCommand
    from planner.cell.scene import CellScene

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class PosedSearch:
    """A commanded search with the pose its program runs it in.

    Attributes:
        command: the search, robot base frame.
        sensor_x: ``(3,)`` the sensor TCP's x axis, base frame (its component along the
            sensor axis is ignored): the only rotation about the axis tried.
        q_ref: ``(n,)`` joint values the start solution is chosen nearest to (max-abs), rad.
        branch: the IK branch of the start and of every sample (OPW configuration 0-7).
    """

    command: SearchCommand
    sensor_x: FloatArray
    q_ref: FloatArray
    branch: int


def check_searches(
    cell: CellScene,
    searches: Sequence[PosedSearch],
    step_m: float = 0.001,
    max_joint_jump_rad: float = math.radians(5.0),
    tcp: str = "sensor",
    margin_m: float | None = None,
) -> list[PathFeasibility]:
    """Each search's :func:`check_search` with its pose (module docstring), the same answers.

    Args:
        cell: the cell; its joint state is restored afterwards.
        searches: the searches with their poses.
        step_m: largest distance between samples, m.
        max_joint_jump_rad: largest joint change between samples, rad.
        tcp: the TCP that runs the searches.
        margin_m: clearance to work object and fixtures, m (default the cell's 5 mm).

    Returns:
        One :class:`PathFeasibility` per search, in order (``min_clearance_m`` NaN: only the
        verdict is computed).

    Raises:
        As :func:`check_search`.
    """
    out: list[PathFeasibility | None] = [None] * len(searches)

    def one(i: int) -> PathFeasibility:
        ps = searches[i]
        return check_search(
            cell,
            ps.command,
            step_m=step_m,
            max_joint_jump_rad=max_joint_jump_rad,
            tcp=tcp,
            margin_m=margin_m,
            q_ref=ps.q_ref,
            max_starts=1,
            sensor_x=ps.sensor_x,
            branch=ps.branch,
            exact_clearance=False,
        )

    batch = [i for i, ps in enumerate(searches) if ps.branch >= 0]
    if cell.solver.kind != "opw":
        batch = []
    for i in sorted(set(range(len(searches))) - set(batch)):
        out[i] = one(i)
    if batch:
        with cell.saved_state():
            done = _batched(cell, searches, batch, step_m, max_joint_jump_rad, tcp, margin_m)
            for i, res in done:
                out[i] = res if res is not None else one(i)
    missing = [i for i, r in enumerate(out) if r is None]
    if missing:  # every search is answered above, batched or alone
        raise RuntimeError(f"searches {missing} were not checked")
    return [r for r in out if r is not None]


def _batched(
    cell: CellScene,
    searches: Sequence[PosedSearch],
    batch: list[int],
    step_m: float,
    max_joint_jump_rad: float,
    tcp: str,
    margin_m: float | None,
) -> list[tuple[int, PathFeasibility | None]]:
    """The searches ``batch`` (indices into ``searches``) checked together; ``None`` for a
    search whose start has no usable solution (the caller asks :func:`check_search`, which
    words the reason)."""
    step = check_positive(step_m, "step_m")
    jump = check_positive(max_joint_jump_rad, "max_joint_jump_rad")
    margin = DEFAULT_MARGIN_M if margin_m is None else check_positive(margin_m, "margin_m", True)
    T_tcp_flange = invert_transform(cell.T_flange_tcp(tcp))
    # per search, as check_search computes it: the samples and the start frame
    s_of, frames, skip_of, angle_of = [], [], [], []
    for i in batch:
        start, direction, axis, s, skip_from = sampled_path(searches[i].command, step)
        angle = sensor_angle(check_vector3(searches[i].sensor_x, "sensor_x"), start, axis)
        T_start = tcp_frames(start[None], -axis[None], np.array([angle]))[0, 0]
        T_path = T_start[None].repeat(s.size, axis=0)
        T_path[:, :3, 3] = start + s[:, None] * direction
        s_of.append(s)
        frames.append(T_path @ T_tcp_flange)  # (M, 4, 4) flange poses; the first is the start
        skip_of.append(skip_from)
        angle_of.append(angle)
    # the starts: one IK call; each search's start solution nearest its reference (max-abs)
    starts = cell.solver.solve(np.stack([f[0] for f in frames]))
    q_start: list[FloatArray | None] = []
    for row, i in enumerate(batch):
        ps = searches[i]
        ok = starts.valid[row] & (starts.branch[row] == ps.branch)
        if ok.any():
            sing, _ = singular(cell, starts.q[row][ok])
            ok[ok] = ~sing
        if not ok.any():
            q_start.append(None)
            continue
        ref = check_shape(ps.q_ref, (cell.chain.n_joints,), "q_ref")
        motion = np.where(ok, np.abs(np.nan_to_num(starts.q[row] - ref)).max(axis=-1), np.inf)
        q_start.append(starts.q[row, int(np.argmin(motion))])
    # the paths: one IK call over every sample of the searches that start
    live = [row for row, q0 in enumerate(q_start) if q0 is not None]
    out: list[tuple[int, PathFeasibility | None]] = [
        (i, None) for row, i in enumerate(batch) if q_start[row] is None
    ]
    if not live:
        return out
    sol = cell.solver.solve(np.concatenate([frames[row] for row in live]))
    followed = []
    at = 0
    for row in live:
        M = frames[row].shape[0]
        q0 = q_start[row]
        assert q0 is not None
        sl = slice(at, at + M)
        at += M
        q_path, fail_j, reason = follow_branch(
            cell,
            sol.q[sl],
            sol.valid[sl],
            sol.branch[sl],
            frames[row],
            q0,
            searches[batch[row]].branch,
            jump,
        )
        followed.append((q_path, fail_j, reason))
    clear = first_failures(
        cell,
        [
            (q_path[:fail_j], frames[row][:fail_j], s_of[row][:fail_j] > skip_of[row])
            for row, (q_path, fail_j, _) in zip(live, followed, strict=True)
        ],
        margin,
    )
    for row, (q_path, fail_j, reason), (j, cl) in zip(live, followed, clear, strict=True):
        if cl is not None:
            fail_j, reason = j, cl.reason()
        ps = searches[batch[row]]
        out.append(
            (
                batch[row],
                path_verdict(s_of[row], q_path, fail_j, reason, angle_of[row], ps.branch, math.nan),
            )
        )
    return out
