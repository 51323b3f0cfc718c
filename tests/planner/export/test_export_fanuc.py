"""Tests of planner.export.fanuc: the TP program parsed back (poses, frames, registers, labels)
and run in a small interpreter of the TP subset it writes (:mod:`tests.fanuc_interp`), against an
ideal misplaced part."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from calib.errors import InputError
from calib.frames import (
    invert_transform,
    make_transform,
    matrix_from_rotvec,
    random_transform,
    transform_points,
)
from calib.plan.file import Plan, load_plan
from calib.probing import SearchCommand
from planner.cli.main import main
from planner.export import FORMATS, export_files
from planner.export import fanuc as F
from planner.export.job import (
    TARGET_KINDS,
    ArmPose,
    ExportJob,
    ToolData,
    build_job,
    default_sensor_rotation,
)
from planner.export_plan.job import export_job_for
from tests.box_part import BoxProbe, distance_to_box
from tests.fanuc_interp import (
    COMMENT,
    Program,
    TPMachine,
    frame_constants,
    parse_ls,
    pose_matrix,
    rot_wpr,
)
from tests.planner.export.test_export_rapid_adaptive import full_misplacement

REPO = Path(__file__).resolve().parents[3]
VALID = REPO / "tests" / "data" / "plans" / "valid_three_two_one.json"
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"


# ------------------------------------------------------------------ parsing the .ls back


def _no_vias(plan: Plan) -> Plan:
    """The plan without via points: the program's structure checked here is each point's own
    moves (the vias' joint moves before them: tests/planner/program/test_vias.py)."""
    import msgspec

    return msgspec.structs.replace(
        plan, points=[msgspec.structs.replace(p, vias=msgspec.UNSET) for p in plan.points]
    )


def point_blocks(lines: list[str]) -> list[dict]:
    """Per point (a block starts at its joint move): its motions in order, the skip levels,
    the P[] copied into the edge start and end registers."""
    blocks: list[dict] = []
    for line in lines:
        if m := re.fullmatch(r"J P\[(\d+)\] \d+% FINE", line):
            blocks.append({"safe": int(m.group(1)), "seq": [("J", "P", int(m.group(1)))]})
            blocks[-1]["levels"] = []
            continue
        if not blocks:
            continue
        b = blocks[-1]
        if m := re.fullmatch(r"SKIP CONDITION DI\[(\d+)\]=(ON|OFF)", line):
            b["levels"].append(m.group(2))
        elif m := re.fullmatch(
            r"L (P|PR)\[(\d+)\] (\d+)mm/sec FINE Skip,LBL\[(\d+)\],PR\[(\d+)\]=LPOS", line
        ):
            b["seq"].append(("S", m.group(1), int(m.group(2)), int(m.group(4)), int(m.group(5))))
            b["speed"] = int(m.group(3))
        elif m := re.fullmatch(r"L (P|PR)\[(\d+)\] \d+mm/sec FINE", line):
            b["seq"].append(("L", m.group(1), int(m.group(2))))
        elif m := re.fullmatch(r"PR\[(\d+)\]=P\[(\d+)\]", line):
            b[{F.PR_EDGE_START: "start", F.PR_EDGE_END: "end"}[int(m.group(1))]] = int(m.group(2))
    return blocks


def _angle_deg(R1: np.ndarray, R2: np.ndarray) -> float:
    c = (np.trace(R1.T @ R2) - 1.0) / 2.0
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def assert_pose(got: np.ndarray, want: np.ndarray, what: object) -> None:
    """Within 1e-8 m and 2e-6 deg (the program's 6 decimals of mm and deg)."""
    assert np.abs(got[:3, 3] - want[:3, 3]).max() < 1e-8, what
    assert _angle_deg(got[:3, :3], want[:3, :3]) < 2e-6, what


# ------------------------------------------------------------------ a TP interpreter


class TPRun(TPMachine):
    """:class:`tests.fanuc_interp.TPMachine` against an ideal box part posed at ``T_base_true``
    (:class:`tests.box_part.BoxProbe` answers the skip motions). ``DI[1]`` is on while the TCP
    is on or inside the part (``stuck``: always that level, and no skip motion finds a change)."""

    def __init__(self, text: str, T_base_true: np.ndarray, stuck: bool | None = None) -> None:
        super().__init__(text, self._box_search)
        self.probe = BoxProbe(T_base_true)
        self.T_true_base = invert_transform(T_base_true)
        self.stuck = stuck

    def di(self) -> bool:
        if self.stuck is not None:
            return self.stuck
        return distance_to_box(transform_points(self.T_true_base, self.here()[:3, 3])) <= 1e-9

    def _box_search(
        self, start: np.ndarray, end: np.ndarray, axis: np.ndarray, neg_flank: bool
    ) -> np.ndarray | str:
        if self.stuck is not None:
            return "ERR_WHLSEARCH"
        length = float(np.linalg.norm(end - start))
        cmd = SearchCommand(
            point_id="",
            kind="edge" if neg_flank else "approach",
            start_m=start,
            direction=(end - start) / length,
            length_m=length,
            sensor_axis=axis,
            T_base_wobj_estimate=np.eye(4),
            nominal_m=start,
        )
        res = self.probe(cmd).point_m
        return "ERR_WHLSEARCH" if res is None else res

    def measured_wobj(self, job: ExportJob) -> dict[str, np.ndarray | int]:
        """Per point: the measured position (nominal wobj frame, m) or the failure code."""
        out: dict[str, np.ndarray | int] = {}
        for i, t in enumerate(job.targets, start=1):
            code = int(self.R[F.R_CODE_BASE + i])
            out[t.point_id] = self.PR[F.PR_MEAS_BASE + i][:3] / 1000.0 if code == 0 else code
        return out


# ------------------------------------------------------------------ jobs


def random_job(plan: Plan, rng: np.random.Generator) -> ExportJob:
    T_base_wobj = random_transform(rng, 2.0, np.pi)
    tool = ToolData(T_flange_tcp=random_transform(rng, 0.3, np.pi))
    rotations = {
        p.id: default_sensor_rotation(p.normal, p.search.edge_direction)
        @ matrix_from_rotvec([0.0, 0.0, rng.uniform(-np.pi, np.pi)])
        for p in plan.points
    }
    return build_job(plan, T_base_wobj, tool, rotations)


#: A configuration for jobs built without a check (these tests are about poses and registers;
#: the configuration has its own tests below).
ANY_ARM = ArmPose((0.1, 0.2, 0.3, 0.4, 0.5, 0.6), True, True, False)


def with_arms(job: ExportJob) -> ExportJob:
    """``job`` with :data:`ANY_ARM` at every target that has no configuration."""
    ts = tuple(
        t if t.arm else replace(t, arm=dict.fromkeys(TARGET_KINDS, ANY_ARM)) for t in job.targets
    )
    return replace(job, targets=ts)


def ls_of(job: ExportJob) -> str:
    files = export_files(with_arms(job), "fanuc")
    assert list(files) == [".ls"]
    return files[".ls"]


def many_points(job: ExportJob, n: int) -> ExportJob:
    """``job`` with ``n`` points: its own, repeated, renamed Q1, Q2, ..."""
    ts = [replace(job.targets[k % len(job.targets)], point_id=f"Q{k + 1}") for k in range(n)]
    return replace(job, targets=tuple(ts))


# ------------------------------------------------------------------ tests


def test_registered_with_the_cli_and_ui() -> None:
    fmt = FORMATS["fanuc"]
    assert (fmt.label, fmt.vendor, fmt.suffixes) == ("TP", "FANUC", (".ls",))
    assert fmt.load() is F.export_fanuc


def test_wpr_convention_round_trips_with_scipy(rng: np.random.Generator) -> None:
    """W, P, R = scipy's extrinsic xyz angles; R = Rz(R) Ry(P) Rx(W), also at P = +-90."""
    mats = list(Rotation.random(200, random_state=7).as_matrix())
    mats += [rot_wpr(30.0, 90.0, -20.0), rot_wpr(-150.0, -90.0, 45.0), rot_wpr(180.0, 0.0, 0.0)]
    for R in mats:
        w, p, r = F.wpr_deg(R)
        assert -90.0 <= p <= 90.0
        scipy_R = Rotation.from_euler("xyz", [w, p, r], degrees=True).as_matrix()
        assert np.abs(scipy_R - R).max() < 1e-12
        assert np.abs(rot_wpr(w, p, r) - R).max() < 1e-12
    # the textbook cases: tool z down is W = 180; a yaw of the frame is R
    assert np.allclose(F.wpr_deg(rot_wpr(180.0, 0.0, 0.0)), (180.0, 0.0, 0.0)) or np.allclose(
        F.wpr_deg(rot_wpr(180.0, 0.0, 0.0)), (-180.0, 0.0, 0.0)
    )
    assert np.allclose(F.wpr_deg(rot_wpr(0.0, 0.0, 35.0)), (0.0, 0.0, 35.0))
    assert np.allclose(F.wpr_deg(rot_wpr(10.0, 20.0, 30.0)), (10.0, 20.0, 30.0))


@pytest.mark.parametrize("path", [VALID, STATOR], ids=["three_two_one", "stator_ah"])
def test_poses_and_frames_parse_back(path: Path, rng: np.random.Generator) -> None:
    plan = _no_vias(load_plan(path))
    job = random_job(plan, rng)
    prog = parse_ls(ls_of(job))
    # frames: UFRAME[9] = PR[1] = T_base_wobj, UTOOL[9] = PR[2] = the sensor TCP
    assert f"UFRAME[{F.UFRAME_NO}]=PR[{F.PR_UFRAME}]" in prog.lines
    assert f"UTOOL[{F.UTOOL_NO}]=PR[{F.PR_UTOOL}]" in prog.lines
    assert_pose(pose_matrix(frame_constants(prog.lines, F.PR_UFRAME)), job.T_base_wobj, "uframe")
    assert_pose(pose_matrix(frame_constants(prog.lines, F.PR_UTOOL)), job.tool.T_flange_tcp, "ut")
    # every P[n]: in the user frame / tool frame of the program, the job's targets
    assert sorted(prog.positions) == list(range(1, len(prog.positions) + 1))
    for pos in prog.positions.values():
        assert (pos.uf, pos.ut, pos.config) == (F.UFRAME_NO, F.UTOOL_NO, "N U T, 0, 0, 0")
    blocks = point_blocks(prog.lines)
    assert len(blocks) == len(job.targets)
    P = {n: pose_matrix(pos.values) for n, pos in prog.positions.items()}
    used: list[int] = []
    for i, (b, t) in enumerate(zip(blocks, job.targets, strict=True), start=1):
        safe = b["safe"]
        assert_pose(P[safe], t.safe_start, (t.point_id, "safe"))
        assert b["speed"] == round(t.speed_m_s * 1000.0)
        face = b["seq"][1][2]
        assert_pose(P[face], t.face_end, (t.point_id, "face"))
        if t.kind == "approach":  # to the safe start, search to the end, back
            assert_pose(P[face], t.T_wobj_end, (t.point_id, "end"))
            assert b["levels"] == ["ON"]
            assert b["seq"] == [
                ("J", "P", safe),
                ("S", "P", face, i, F.PR_MEAS_BASE + i),
                ("L", "P", safe),
            ]
            used += [safe, face]
        else:  # approach the face, to the measured face point, edge search to the end, back
            assert_pose(P[b["start"]], t.T_wobj_start, (t.point_id, "start"))
            assert_pose(P[b["end"]], t.T_wobj_end, (t.point_id, "end"))
            assert b["levels"] == ["ON", "OFF"]
            assert b["seq"] == [
                ("J", "P", safe),
                ("S", "P", face, i, F.PR_FACE),
                ("L", "PR", F.PR_EDGE_START),
                ("S", "PR", F.PR_EDGE_END, i, F.PR_MEAS_BASE + i),
                ("L", "P", safe),
            ]
            used += [safe, face, b["start"], b["end"]]
    assert sorted(used) == sorted(prog.positions)  # every P[] used once, no other


def test_searches_start_outside_the_nominal_surface_by_the_clearance() -> None:
    """In program order, each point's first search starts at its P[safe], at least the safe
    clearance outside the nominal face; the edge search starts at the measured face point."""
    plan = load_plan(VALID)
    job = build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4)))
    prog = parse_ls(ls_of(job))
    for b, t, p in zip(point_blocks(prog.lines), job.targets, plan.points, strict=True):
        start = pose_matrix(prog.positions[b["safe"]].values)[:3, 3]
        face = t.T_wobj_start[:3, 3] if t.kind == "edge" else np.asarray(p.position_m)
        out = float(np.asarray(p.normal) @ (start - face))
        assert out >= job.safety.start_clearance_m(face) - 1e-9
        assert out > p.search.start_offset_m  # moved out: the test plan's start is too close
    # no other motion between the joint move to P[safe] and the first search
    for b in point_blocks(prog.lines):
        assert b["seq"][0] == ("J", "P", b["safe"]) and b["seq"][1][0] == "S"


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("path", [VALID, STATOR], ids=["three_two_one", "stator_ah"])
def test_program_run_against_a_misplaced_part(path: Path, seed: int) -> None:
    """The interpreter runs the program on an ideal part misplaced at the tolerance: no search
    starts within the sensing distance of it, the edge searches start on its face, every
    approach point is found on the true part (the test plan's 20 mm edge search may end before
    the moved edge, code 1)."""
    plan = _no_vias(load_plan(path))
    rng = np.random.default_rng(seed)
    T_nom = make_transform(matrix_from_rotvec([0.0, 0.2, 0.1]), [1.4, -0.3, 0.8])
    T_true = T_nom @ full_misplacement(plan, rng)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=random_transform(rng, 0.3, np.pi)))
    tp = TPRun(ls_of(job), T_true).run()
    assert_pose(tp.uframe[F.UFRAME_NO], T_nom, "uframe")
    assert_pose(tp.utool[F.UTOOL_NO], job.tool.T_flange_tcp, "utool")
    sd = plan.validation.sensor.sensing_distance_m
    T_true_base = invert_transform(T_true)
    for s in tp.searches:
        dist = distance_to_box(transform_points(T_true_base, s["start"]))
        assert (dist > sd) if s["on"] else (abs(dist) < 1e-9), dist
    for T in tp.joint_targets:
        assert distance_to_box(transform_points(T_true_base, T[:3, 3])) > sd
    n_edge = sum(t.kind == "edge" for t in job.targets)
    assert [s["on"] for s in tp.searches].count(False) == n_edge
    # as the header says: to the base with the PR[1] values, then into the true part frame
    T_true_uf = T_true_base @ pose_matrix(frame_constants(tp.prog.lines, F.PR_UFRAME))
    sin_a = np.sin(plan.validation.misplacement.max_angle_rad)
    for t, got in zip(job.targets, tp.measured_wobj(job).values(), strict=True):
        if isinstance(got, int):  # only the short edge search of the test plan may miss
            assert (path, t.kind, got) == (VALID, "edge", 1), (t.point_id, got)
            assert any(not s["on"] and not s["found"] for s in tp.searches)  # it ran, to its end
            continue
        dist = abs(distance_to_box(transform_points(T_true_uf, got)))
        if t.kind == "approach":  # the TCP at the switching event is on the true face
            assert dist < 1e-9, t.point_id
        else:  # the track runs along the nominal direction: off a tilted face by the header's bound
            assert dist <= t.length_m * sin_a + 1e-9, t.point_id


@pytest.mark.parametrize("path", [VALID, STATOR], ids=["three_two_one", "stator_ah"])
def test_nominal_part_gives_the_plan_points(path: Path, rng: np.random.Generator) -> None:
    """On the part at its nominal pose every PR[10 + i] is the plan's point i (user frame)."""
    plan = _no_vias(load_plan(path))
    job = random_job(plan, rng)
    tp = TPRun(ls_of(job), job.T_base_wobj).run()
    for p in plan.points:
        got = tp.measured_wobj(job)[p.id]
        assert not isinstance(got, int)
        assert np.abs(got - np.asarray(p.position_m)).max() < 1e-8, p.id


def test_failure_codes() -> None:
    """1: the part is not there (every search runs to its end); 2: the input is already on."""
    plan = load_plan(VALID)
    job = build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4)))
    away = make_transform(np.eye(3), [5.0, 0.0, 0.0])
    tp = TPRun(ls_of(job), away).run()
    assert set(tp.measured_wobj(job).values()) == {1}
    assert all(not s["found"] and s["on"] for s in tp.searches)  # edge points stop after 1
    tp = TPRun(ls_of(job), np.eye(4), stuck=True).run()
    assert set(tp.measured_wobj(job).values()) == {2}
    assert tp.searches == []  # no search started with the input on
    # 3 until the point runs: set for every point before the first motion
    lines = parse_ls(ls_of(job)).lines
    first_motion = next(k for k, x in enumerate(lines) if x.startswith("J "))
    init = [k for k, x in enumerate(lines) if re.fullmatch(r"R\[\d+\]=3", x)]
    assert [lines[k] for k in init] == [f"R[{F.R_CODE_BASE + i}]=3" for i in range(1, 7)]
    assert max(init) < first_motion


def test_structure_labels_registers_and_name() -> None:
    plan = _no_vias(load_plan(STATOR))
    job = build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4)))
    prog = parse_ls(ls_of(job))
    assert prog.name == "WOBJCALSTATORSECTIONAH" == F.program_name(job.name)
    _check_structure(prog, len(job.targets))
    text = "\n".join(x[1:] for x in prog.lines if x.startswith("!"))
    assert "NOMINAL FRAME" in text and "not adaptive" in text
    assert "SAFE FOR: part misplaced up to 20.0 mm" in " ".join(text.split())
    assert f"PR[{F.PR_MEAS_BASE + 1}]..PR[{F.PR_MEAS_BASE + 8}]" in text
    assert "Points: 1=A, 2=B, 3=C, 4=D, 5=E, 6=F, 7=G," in " ".join(text.split())


def _check_structure(prog: Program, n: int) -> None:
    """Name, labels, register and frame numbers of a program with ``n`` points."""
    assert re.fullmatch(r"[A-Z][A-Z0-9_]{0,35}", prog.name)
    defined = [int(x) for x in re.findall(r"^LBL\[(\d+)\]$", "\n".join(prog.lines), re.M)]
    assert len(defined) == len(set(defined)) == n
    jumped = re.findall(r"LBL\[(\d+)\]", "\n".join(x for x in prog.lines if "LBL" in x))
    assert {int(x) for x in jumped} <= set(defined)
    body = "\n".join(x for x in prog.lines if not x.startswith("!"))
    prs = {int(x) for x in re.findall(r"PR\[(\d+)", body)}
    rs = {int(x) for x in re.findall(r"(?<!P)R\[(\d+)", body)}
    assert prs <= {1, 2, 3, 4, 5} | set(range(F.PR_MEAS_BASE + 1, F.PR_MEAS_BASE + n + 1))
    assert max(prs) <= F.PR_COUNT and min(prs) >= 1
    assert rs <= set(F.R_TMP) | set(range(F.R_CODE_BASE + 1, F.R_CODE_BASE + n + 1))
    assert max(rs) <= F.R_COUNT
    assert set(re.findall(r"UFRAME\[(\d+)\]", body)) == {str(F.UFRAME_NO)} and F.UFRAME_NO <= 9
    assert set(re.findall(r"UTOOL\[(\d+)\]", body)) == {str(F.UTOOL_NO)} and F.UTOOL_NO <= 10
    for x in prog.lines:
        if x.startswith("!"):
            assert re.fullmatch(COMMENT, x), x
    assert re.search(r'^COMMENT\t\t= "[^"]{0,16}";$', prog.attr, re.M)


def test_sixty_points_and_the_limit() -> None:
    plan = load_plan(VALID)
    job = many_points(build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4))), 60)
    text = ls_of(job)
    prog = parse_ls(text)
    _check_structure(prog, 60)
    assert sorted(prog.positions) == list(range(1, len(prog.positions) + 1))
    assert len(prog.positions) == 10 * (5 * 2 + 4)  # 5 approach and 1 edge point, 10 times
    tp = TPRun(text, np.eye(4)).run()  # every point is measured, each in its own PR
    got = tp.measured_wobj(job)
    assert all(not isinstance(v, int) for v in got.values())
    assert max(tp.PR) == F.PR_MEAS_BASE + 60
    _check_structure(parse_ls(ls_of(many_points(job, F.MAX_POINTS))), F.MAX_POINTS)
    with pytest.raises(InputError, match="at most 90 points"):
        ls_of(many_points(job, F.MAX_POINTS + 1))


def test_hostile_point_id_and_names_cannot_inject() -> None:
    plan = load_plan(VALID)
    job = build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4)))
    evil = "A;\n  1: CALL EVIL ;\r\"'!/END"
    targets = (replace(job.targets[0], point_id=evil), *job.targets[1:])
    job = replace(job, targets=targets, plan_name="x;\n/POS\nP[1]{", name='9 "bad";\nCALL')
    text = ls_of(job)
    prog = parse_ls(text)  # still exactly one of each section, numbered lines, LINE_COUNT
    _check_structure(prog, len(job.targets))
    assert prog.name == "W9__BAD___CALL"
    for line in prog.lines:
        assert "CALL" not in line or line.startswith("!"), line
        assert ";" not in line and '"' not in line and "'" not in line
    assert "\r" not in text and text.count("CALL EVIL") == 0
    TPRun(text, np.eye(4)).run()  # runs: every line is one of the known instructions
    assert prog.positions[1].comment.endswith(" safe")


def test_program_name_limits() -> None:
    assert F.program_name("WobjcalStatorSectionAh") == "WOBJCALSTATORSECTIONAH"
    assert F.program_name("x" * 50) == "X" * 36
    assert F.program_name("1st plan") == "W1ST_PLAN"
    assert F.program_name("Ärger") == "W_RGER"
    for line in F.comment_lines("a`b'c\"d;e!f\n" + "long " * 30 + "é"):
        assert re.fullmatch(COMMENT, "!" + line) and len(line) <= 32


@pytest.mark.slow
def test_cli_export_and_help(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "X.ls"
    # the TP program runs A-H nominal: D, E, G land over the slot holes in about a quarter of
    # calibrations, so the export refuses it (exit 1, nothing written) unless forced
    assert main(["export", str(STATOR), "--format", "fanuc", "-o", str(out)]) == 1
    assert not out.exists() and "land" in capsys.readouterr().err
    assert main(["export", str(STATOR), "--format", "fanuc", "-o", str(out), "--force"]) == 0
    assert main(["export", "--help"]) == 0
    assert "fanuc" in capsys.readouterr().out
    prog = parse_ls(out.read_text())
    assert prog.name == "WOBJCALSTATORSECTIONAH"
    plan = load_plan(STATOR)
    job, _ = export_job_for(plan, STATOR.parent, None)  # frames, tool, positions
    assert_pose(pose_matrix(frame_constants(prog.lines, F.PR_UFRAME)), job.T_base_wobj, "uf")
    assert_pose(pose_matrix(frame_constants(prog.lines, F.PR_UTOOL)), job.tool.T_flange_tcp, "ut")
    vias = sum(len(p.via_points) for p in plan.points)
    assert vias and len(prog.joints) == vias  # the shipped plan's vias, as joint positions
    blocks = [b for b in point_blocks(prog.lines) if b["safe"] in prog.positions]  # not vias
    for b, t in zip(blocks, job.targets, strict=True):
        got = prog.positions[b["safe"]].values[:3] / 1000.0
        assert np.abs(got - t.safe_start[:3, 3]).max() < 1e-8  # orientations come from check


# ------------------------------------------------------------------ configuration (issue 10)
#: ROS-Industrial's FANUC M-10iA joints (fanuc_m10ia_support): FANUC's joint directions, with
#: J3, J5 about -y and J4, J6 about -x; boxes instead of meshes.
_M10IA_JOINTS = [  # name, origin xyz, axis xyz, lower, upper
    ("joint_1", "0 0 0", "0 0 1", -3.14, 3.14),
    ("joint_2", "0.15 -0.04 0.45", "0 1 0", -1.57, 2.79),
    ("joint_3", "0 -0.0225 0.6", "0 -1 0", -3.14, 4.61),
    ("joint_4", "0.1805 0.0625 0.2", "-1 0 0", -3.31, 3.31),
    ("joint_5", "0.4595 -0.0565 0", "0 -1 0", -3.31, 3.31),
    ("joint_6", "0.1 0.0565 0", "-1 0 0", -6.28, 6.28),
]
_LINKS = ["base_link", "link_1", "link_2", "link_3", "link_4", "link_5", "link_6"]
M10IA = (
    '<robot name="m10ia">'
    + "".join(f'<link name="{n}"/>' for n in [*_LINKS, "tool0"])
    + "".join(
        f'<joint name="{n}" type="revolute"><origin xyz="{o}"/><parent link="{_LINKS[k]}"/>'
        f'<child link="{_LINKS[k + 1]}"/><axis xyz="{a}"/>'
        f'<limit lower="{lo}" upper="{hi}" effort="0" velocity="1"/></joint>'
        for k, (n, o, a, lo, hi) in enumerate(_M10IA_JOINTS)
    )
    + '<joint name="joint_6-tool0" type="fixed"><parent link="link_6"/><child link="tool0"/>'
    "</joint></robot>"
)


def _config(robot, q) -> str:  # type: ignore[no-untyped-def]
    from planner.robot.kinematics.branches import posture

    f = posture(robot, np.asarray(q, dtype=float))
    return F.config_text(ArmPose(tuple(q), f.front, f.elbow_up, f.wrist_flipped))


def test_fanuc_config_of_a_fanuc_arm_in_fanuc_joint_directions(tmp_path: Path) -> None:
    """The M-10iA's tool-down home (J5 = -90, FANUC's) is 'N U T'; J5 = +90 is the flipped
    wrist; the elbow bent back is 'D'; the wrist behind axis 1 is 'B'; turn numbers follow
    J4, J6, J1."""
    from planner.robot.kinematics.chain import KinematicChain
    from planner.robot.kinematics.opw_from_urdf import opw_from_chain

    path = tmp_path / "m10ia.urdf"
    path.write_text(M10IA)
    robot = opw_from_chain(KinematicChain.from_urdf(path))
    deg = np.radians
    assert _config(robot, deg([0, 0, 0, 0, -90, 0])) == "N U T, 0, 0, 0"
    T_down = robot.fk(deg([0, 0, 0, 0, -90, 0]))
    assert np.allclose(T_down[:3, 0], [0, 0, -1], atol=1e-9)  # tool0 x (out of the flange) down
    assert _config(robot, deg([0, 0, 0, 0, 90, 0])) == "F U T, 0, 0, 0"
    assert _config(robot, deg([0, 0, 0, 200, -90, 270])) == "N U T, 1, 1, 0"
    assert _config(robot, deg([-170, 0, 0, -200, -30, -300])) == "N U T, -1, -1, 0"
    # the same flange pose on other branches: each flag read from the pose, not the branch index
    sols, ok = robot.ik_branches(robot.fk(deg([20, 10, -20, 30, -60, 40]))[None])
    got = {_config(robot, q)[:5] for q in sols[0][ok[0]]}
    assert {g[0] for g in got} == {"N", "F"} and {g[2] for g in got} == {"U", "D"}
    assert {g[4] for g in got} == {"T", "B"} and len(got) == 8  # eight branches, eight configs


@pytest.mark.slow
def test_fanuc_config_comes_from_the_checked_pose(tmp_path: Path) -> None:
    """The shipped plan: every position's CONFIG is its own IK solution's next to the checked
    pose, the same flags as the check's ABB confdata on this ABB-like arm (cfx bits)."""
    from planner.check.job import check_plan
    from planner.export_plan.job import export_program

    plan = _no_vias(load_plan(STATOR))
    result = export_program(plan, STATOR.parent, "fanuc")
    check = check_plan(plan, STATOR.parent)
    prog = parse_ls(result.files[".ls"])
    for b, c in zip(point_blocks(prog.lines), check.points, strict=True):
        assert c.confdata is not None
        cfx = c.confdata[3]
        flags = f"{'F' if cfx & 1 else 'N'} {'D' if cfx & 2 else 'U'} {'B' if cfx & 4 else 'T'}"
        want = f"{flags}, 0, 0, 0"
        for kind in ("safe", "end", "face", "start"):
            if kind in b:
                assert prog.positions[b[kind]].config == want, (c.point_id, kind)


def test_fanuc_without_a_checked_pose_keeps_the_robots_configuration(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: refused (exit 2), so --force could not write an infeasible plan. Without a
    checked pose there is no CONFIG to derive, and none is guessed: each such target is a PR
    made from LPOS and its six components (the robot keeps its configuration, as a KRL target
    without S and T), the header names the points, and the program measures what the one with
    configurations measures."""
    plan = _no_vias(load_plan(STATOR))
    rng = np.random.default_rng(3)
    T_nom = make_transform(matrix_from_rotvec([0.0, 0.2, 0.1]), [1.4, -0.3, 0.8])
    T_true = T_nom @ full_misplacement(plan, rng)
    job = build_job(plan, T_nom, ToolData(T_flange_tcp=random_transform(rng, 0.3, np.pi)))
    text = export_files(job, "fanuc")[".ls"]
    prog = parse_ls(text)
    assert prog.positions == {}  # no Cartesian P[], so no CONFIG written anywhere
    header = " ".join(c[1:] for c in prog.lines if c.startswith("!"))
    ids = ", ".join(t.point_id for t in job.targets)
    assert f"NO CONFIG for points {ids} (no checked robot pose)" in header
    assert "made from LPOS" in header and "T1" in header
    assert f"J PR[{F.PR_SAFE}] {F.JOINT_PCT}% FINE" in prog.lines
    assert prog.lines.count(f"PR[{F.PR_SAFE}]=LPOS") == len(job.targets)
    run = TPRun(text, T_true).run()
    want = TPRun(ls_of(job), T_true).run()
    got, ref = run.measured_wobj(job), want.measured_wobj(job)
    assert got.keys() == ref.keys()
    for pid in ref:
        assert np.allclose(got[pid], ref[pid], atol=1e-9), pid
    assert [s["start"].tolist() for s in run.searches] == [
        s["start"].tolist() for s in want.searches
    ]
    # the command line: --no-check writes it too (the header says NOT CHECKED)
    out = tmp_path / "x.ls"
    code = main(["export", str(STATOR), "--format", "fanuc", "--no-check", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    assert "NOT CHECKED" in out.read_text() and "NO CONFIG for points" in out.read_text()
