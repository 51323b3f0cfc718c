"""The cell of the feasibility benchmarks, and the plain PyBullet loop they are compared with.

The built-in IRB 4400 with the cable-feeder tool faces a 0.8 x 0.6 x 0.4 m box subdivided into
114,688 triangles (a concave static PyBullet mesh) standing on a 1.2 x 1.0 m table. Used by
``bench.bench_feasibility`` and by ``bench.feasibility_cold`` (the cold reachability map, run
in a fresh process).
"""

from __future__ import annotations

import numpy as np
import pybullet as pb
import trimesh

from calib.frames import invert_transform, make_transform
from planner.cell.cell import Cell
from planner.cell.probe.feasibility import tcp_frames
from planner.cell.scene.bodies import pb_pose
from planner.cell.scene.collision import DEFAULT_MARGIN_M

T_WORLD_WOBJ = make_transform(p=[1.5, 0.0, 0.4])
#: The table under the box: its top at the box's bottom face (z = 0.2 m).
TABLE_SIZE_M = (1.2, 1.0, 0.05)
T_WORLD_TABLE = make_transform(p=[1.5, 0.0, 0.175])


def work_object() -> trimesh.Trimesh:
    """A 0.8 x 0.6 x 0.4 m box subdivided to 114,688 triangles."""
    return trimesh.creation.box([0.8, 0.6, 0.4]).subdivide_to_size(0.012)


def bench_cell(mesh: trimesh.Trimesh | None = None, **cell_kw: object) -> Cell:
    """The benchmark cell: robot, tool, the box part and the table."""
    cell = Cell(**cell_kw)  # type: ignore[arg-type]
    cell.set_work_object(work_object() if mesh is None else mesh, "m", T_WORLD_WOBJ, name="box")
    cell.add_fixture("table", size_m=TABLE_SIZE_M, T_world_fixture=T_WORLD_TABLE)
    return cell


def run_plain_loop(cell: Cell, pts: np.ndarray, nrm: np.ndarray) -> dict[str, object]:
    """Per point and rotation: PyBullet IK from home, limits, then ``getClosestPoints`` of
    robot and tool against the part and the table (5 mm; the sensor exempt down to contact
    with the part; no self-collision); stop at the first rotation that passes."""
    c, robot, tool = cell.client, cell.robot.body_id, cell.tool_body
    assert tool is not None and cell.tool is not None
    bodies = list(cell.checker.environment)
    wobj = cell.checker.wobj_body
    joints, flange = cell.joint_indices, cell.flange_index
    n = len(joints)
    sensor = {i for i, name in tool.names.items() if name in cell.tool.sensor_links}
    angles = np.radians(np.arange(0, 360, 15))
    T_world = (
        cell.T_world_wobj
        @ tcp_frames(pts, nrm, angles)
        @ invert_transform(cell.T_flange_tcp("sensor"))
    )
    lo, hi = cell.chain.lower, cell.chain.upper
    per_point = [False] * len(pts)
    for i in range(len(pts)):
        for r in range(angles.size):
            for j, v in zip(joints, cell.home_q):
                pb.resetJointState(robot, j, float(v), physicsClientId=c)
            pos, quat = pb_pose(T_world[i, r])
            q = np.array(
                pb.calculateInverseKinematics(
                    robot, flange, pos, quat, jointDamping=[1e-3] * n, maxNumIterations=100,
                    residualThreshold=1e-10, physicsClientId=c,
                )[:n]
            )  # fmt: skip
            if np.any(q < lo) or np.any(q > hi):
                continue
            for j, v in zip(joints, q):
                pb.resetJointState(robot, j, float(v), physicsClientId=c)
            state = pb.getLinkState(robot, flange, computeForwardKinematics=True, physicsClientId=c)
            if np.linalg.norm(np.subtract(state[4], pos)) > 1e-3:
                continue
            q_err = np.abs(np.subtract(state[5], quat)).max()
            if min(q_err, np.abs(np.add(state[5], quat)).max()) > 5e-3:
                continue
            off_p, off_q = pb.getDynamicsInfo(tool.body_id, -1, physicsClientId=c)[3:5]
            bp, bq = pb.multiplyTransforms(state[4], state[5], off_p, off_q)
            pb.resetBasePositionAndOrientation(tool.body_id, bp, bq, physicsClientId=c)
            hits = False
            for env in bodies:
                for body in (robot, tool.body_id):
                    for p in pb.getClosestPoints(body, env, DEFAULT_MARGIN_M, physicsClientId=c):
                        exempt = body == tool.body_id and env == wobj and p[3] in sensor
                        if not (exempt and p[8] >= 0.0):
                            hits = True
            if not hits:
                per_point[i] = True
                break
    return {"per_point": per_point, "feasible": sum(per_point)}
