"""Every number a user sets is bounded (issue 27, item 2, "never exhaust the machine"): refused
before any work with the bound and why, or held within a stated memory budget; uploads bounded
per tab and in total and cleaned when no longer used; an autosave whose restore crashed the
server is not restored again. Each test failed before the change (the old behaviour is in its
docstring)."""

from __future__ import annotations

import io
import json
import os
import time
import tracemalloc
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from viser import _messages

from calib import limits
from calib.errors import InputError, PlanError, ShapeError
from calib.plan.file import load_plan, plan_from_json
from planner.cli.main import main
from planner.errors import MeshError, URDFError

REPO = Path(__file__).resolve().parent.parent
STATOR = REPO / "assets" / "plans" / "stator_section_ah.json"
PLATE = REPO / "assets" / "plans" / "plate_holes_best_fit.json"


def _doc(path: Path = STATOR) -> dict[str, Any]:
    return json.loads(path.read_text())


def _set(doc: dict[str, Any], keys: list[Any], value: object) -> str:
    node: Any = doc
    for key in keys[:-1]:
        node = node[key]
    node[keys[-1]] = value
    return json.dumps(doc)


# ---- sensors, every kind ----------------------------------------------------------------------
@pytest.mark.parametrize(
    ("plan", "keys", "value", "message"),
    [
        # before: a touch probe took n_rays = 10^9 (10.9 GB, killed)
        (PLATE, ["n_rays"], 10**9, r"n_rays: must be at most 65,536, got 1,000,000,000 \(each"),
        (STATOR, ["n_rays"], 10**9, r"n_rays: must be at most 65,536, got 1,000,000,000 \(each"),
        # before: 65,536 scan rays took 1 GB for two trials (every 2.5 mm step at once)
        (STATOR, ["n_scan_rays"], 65_536, r"n_scan_rays: must be at most 1,024, got 65,536 \("),
    ],
)
def test_the_rays_of_every_sensor_kind_are_bounded(
    plan: Path, keys: list[str], value: int, message: str
) -> None:
    doc = _doc(plan)
    with pytest.raises(PlanError, match=message):
        plan_from_json(_set(doc, ["validation", "sensor", *keys], value))


# ---- plan sizes -------------------------------------------------------------------------------
def _many_points(n: int) -> str:
    doc = _doc(PLATE)
    base = doc["points"]
    doc["points"] = [dict(base[i % len(base)], id=f"P{i}") for i in range(n)]
    return json.dumps(doc)


@pytest.mark.slow
def test_a_plan_of_10000_points_is_refused_before_any_work(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: `check` ran 258 s and 6.8 GB; `ui` died (2.24 GiB for a (10000, 10000, 3)
    array under a 2.5 GB limit) and printed only `wobjcal ui: error: `."""
    with pytest.raises(PlanError, match=r"points: 10,000 points, at most 500 \(a calibration"):
        plan_from_json(_many_points(10_000))
    plan_from_json(_many_points(500))  # the largest accepted
    path = tmp_path / "big.json"
    path.write_text(_many_points(10_000))
    t0 = time.perf_counter()
    assert main(["check", str(path)]) == 2
    assert time.perf_counter() - t0 < 20
    assert "10,000 points, at most 500" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("keys", "value", "message"),
    [
        (["points", 0, "search", "overtravel_m"], 1e6, r"overtravel_m: 1e\+06 m, at most 1 m"),
        (["points", 0, "search", "start_offset_m"], 5.0, r"start_offset_m: 5 m, at most 1 m"),
        (["points", 0, "vias"], [{"q_rad": [0.0] * 6}] * 65, r"vias: 65 vias, at most 64"),
        (["validation", "report", "levels_percent"], [50.0] * 11, r"11 levels, at most 10"),
        (
            ["validation", "report", "regions"],
            [{"name": f"r{i}"} for i in range(101)],
            r"regions: 101 rows, at most 100",
        ),
        (
            ["validation", "report", "regions"],
            [{"name": "part", "max_points": 10**6}],
            r"max_points: must be at most 20,000, got 1,000,000 \(validate keeps",
        ),
        (["procedure", "xoffset", "grid", "n_slots"], 10**6, r"n_slots: 1,000,000, at most 1,000"),
        (["procedure", "xoffset", "grid", "n_layers"], 10**4, r"n_layers: 10,000, at most 100"),
        (["procedure", "xoffset", "teeth"], [1, 3] * 1000, r"teeth: 2,000 values, at most 42"),
        (
            ["cell", "fixtures"],
            [{"name": f"f{i}", "box_size_m": [1, 1, 1]} for i in range(65)],
            r"fixtures: 65 fixtures, at most 64",
        ),
    ],
)
def test_plan_counts_and_lengths_are_bounded(keys: list[Any], value: object, message: str) -> None:
    """Before: each was taken as is (a search of 1,000 km, 10^6 report points per trial, ...)."""
    with pytest.raises(PlanError, match=message):
        plan_from_json(_set(_doc(), keys, value))


def test_fit_iterations_are_bounded() -> None:
    doc = _doc(PLATE)
    with pytest.raises(PlanError, match=r"max_iterations: must be at most 1,000, got 10,000,000"):
        plan_from_json(_set(doc, ["procedure", "max_iterations"], 10**7))


# ---- validate: protocol, trials x searches x report points, trials x rays ---------------------
def test_a_huge_protocol_is_refused_by_the_command_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Before: `validate --protocol 100000x100000` reached 4 GB in 106 s with no output."""
    t0 = time.perf_counter()
    assert main(["validate", str(STATOR), "--protocol", "100000x100000"]) == 2
    assert time.perf_counter() - t0 < 10
    err = capsys.readouterr().err
    assert "100000x100000 is 10,000,000,000 trials, at most 100,000" in err
    assert main(["validate", str(STATOR), "--protocol", "9" * 5000 + "x2"]) == 2
    assert "more than 10^12 trials" in capsys.readouterr().err


def test_the_protocol_of_the_python_api_is_bounded() -> None:
    from planner.sim.montecarlo import simulate

    with pytest.raises(ShapeError, match=r"protocol: 100,000 x 100,000 trials, at most 100,000"):
        simulate(None, None, [], 10, np.random.default_rng(0), protocol=(100_000, 100_000))  # type: ignore[arg-type]


def test_a_run_that_would_not_fit_in_memory_is_refused_before_any_work(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Before: 100,000 trials of the A-H plan were accepted (~19 kB of results a trial and the
    default region's 2,000 points x 3 x 8 bytes a trial and fit: some 10 GB)."""
    from planner.sim.budget import check_run_size, run_size

    plan = load_plan(STATOR)
    size = run_size(plan, trials=100_000)
    assert size.searches == 54  # 12 searches of the program, 42 of the x-offset run
    with pytest.raises(InputError, match=r"at most 768 MiB .* at most [\d,]+ trials of this plan"):
        check_run_size(size)
    check_run_size(run_size(plan, trials=2_000, protocol=(20, 20)))  # the paper's: fine
    t0 = time.perf_counter()
    assert main(["validate", str(STATOR), "--trials", "100000"]) == 2
    assert time.perf_counter() - t0 < 20, "refused before the check and the simulation"
    assert "MiB of results until the report" in capsys.readouterr().err


@pytest.mark.reference
def test_the_part_leaves_its_share_of_the_budget() -> None:
    """Before: a 786,432-triangle part and 200 trials took `validate` to 2.3 GB; the results
    now get what the part leaves of the 2 GB."""
    import dataclasses

    from planner.sim.budget import check_run_size, run_size

    size = run_size(load_plan(PLATE), trials=6_000)
    check_run_size(size)
    with pytest.raises(InputError, match=r"at most 44\d MiB, what a 500,000-triangle part leaves"):
        check_run_size(dataclasses.replace(size, triangles=500_000))
    check_run_size(dataclasses.replace(size, trials=4_000, triangles=500_000))


def test_trials_times_rays_is_bounded() -> None:
    """Before: 100,000 trials with 65,536 rays were accepted (3.5 x 10^11 ray casts: weeks)."""
    from planner.sim.budget import check_run_size, run_size

    text = _set(_doc(), ["validation", "sensor", "n_rays"], 65_536)
    plan = plan_from_json(text)
    with pytest.raises(InputError, match=r"ray casts, at most 2e\+09 .* at most [\d,]+ trials"):
        check_run_size(run_size(plan, trials=5_000))
    check_run_size(run_size(plan, trials=400))


@pytest.mark.slow
def test_report_samples_are_made_a_few_points_at_a_time() -> None:
    """Before: a row's error vectors were made all at once: 2,000 trials x 2,000 points held
    ~400 MB of transients per row (a 4,000-trial run peaked at 1,066 MB)."""
    from planner.sim import rows

    rng = np.random.default_rng(1)
    delta = rng.normal(0, 1e-4, (2000, 6))
    spec = rows.RowSpec(
        "xyz_part", "p", "mm", (95.5,), points_wobj=rng.normal(0, 0.3, (2000, 3)), components="xyz"
    )
    tracemalloc.start()
    samples, bias = rows.samples_and_bias(spec, delta)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert samples.shape == (4_000_000,)
    assert peak < 32e6 + 100e6, f"peak {peak / 1e6:.0f} MB"  # the samples and one chunk
    T = rows.small_motion(delta)  # the errors all at once, by the definition (R p + t - p)
    e = np.einsum("nij,mj->nmi", T[:, :3, :3], spec.points_wobj) + T[:, None, :3, 3]
    e = e - spec.points_wobj
    mean = e.mean(axis=0)
    # equal to rounding: the rows compute (R - I) p + t, by chunks of points
    np.testing.assert_allclose(samples, rows.measure(e - mean, "xyz").ravel(), rtol=0, atol=1e-14)
    assert bias == pytest.approx(float(np.mean(np.linalg.norm(mean, axis=1))), rel=1e-9)


# ---- meshes and URDFs -------------------------------------------------------------------------
def _sparse_stl(path: Path, n: int) -> Path:
    """A binary STL whose header says ``n`` triangles, of the matching size (sparse: no disk)."""
    with path.open("wb") as f:
        f.write(b"\0" * 80 + n.to_bytes(4, "little"))
        f.truncate(84 + 50 * n)
    return path


def test_a_mesh_above_500000_triangles_is_refused_from_its_header(tmp_path: Path) -> None:
    """Before: 2,000,000 triangles were taken (a 786,432-triangle part took `check` to
    1,420 MB and `validate` to 2,324 MB, so 2 million would be ~6 GB)."""
    from planner.cell.scene.fixtures import Fixture
    from planner.cell.scene.workobject import load_work_object

    big = _sparse_stl(tmp_path / "scan.stl", 1_500_000)
    t0 = time.perf_counter()
    with pytest.raises(
        MeshError, match=r"1,500,000 triangles; wobjcal takes at most 500,000 \(validate"
    ):
        load_work_object(big, units="mm")
    with pytest.raises(MeshError, match=r"the cell's other meshes leave 10 of the 500,000"):
        Fixture.from_mesh(
            "clamp", _sparse_stl(tmp_path / "c.stl", 11), units="mm", max_triangles=10
        )
    assert time.perf_counter() - t0 < 2, "refused from the header, before parsing"


def test_the_cells_meshes_share_one_triangle_budget(tmp_path: Path) -> None:
    """Before: each fixture could bring 2,000,000 triangles more."""
    from planner.plan_cell import open_cell
    from webui.testing import box_plan

    plan_path = box_plan(tmp_path)
    doc = json.loads(plan_path.read_text())
    _sparse_stl(tmp_path / "pallet.stl", limits.MAX_CELL_TRIANGLES - 5)
    doc["cell"]["fixtures"] = [{"name": "pallet", "mesh": "pallet.stl", "units": "mm"}]
    plan = plan_from_json(json.dumps(doc))
    with pytest.raises(
        MeshError,
        match=r"499,995 triangles; the cell's other meshes leave 499,988 of the 500,000",
    ):
        open_cell(plan, tmp_path).close()


def test_a_urdf_of_too_many_links_is_refused_before_it_is_parsed() -> None:
    """Before: every link was parsed and the tree checked pairwise (quadratic: 10,000 links
    took 10 s, 50,000 about 4 minutes); 10,000 now parse in 2 s, more are refused at once."""
    from planner.robot.urdf import parse_urdf

    n = 50_000
    links = "".join(f'<link name="l{i}"/>' for i in range(n))
    joints = "".join(
        f'<joint name="j{i}" type="fixed"><parent link="l{i}"/><child link="l{i + 1}"/></joint>'
        for i in range(n - 1)
    )
    t0 = time.perf_counter()
    with pytest.raises(URDFError, match=r"50,000 <link> elements, at most 10,000 \(an arm has"):
        parse_urdf(f'<robot name="r">{links}{joints}</robot>')
    assert time.perf_counter() - t0 < 3


def test_a_urdf_whose_meshes_are_too_large_is_refused(tmp_path: Path) -> None:
    """Before: any size was handed to PyBullet and the drawings."""
    from planner.robot.urdf import load_urdf

    with (tmp_path / "huge.stl").open("wb") as f:
        f.truncate(200 * limits.MiB)
    link = (
        '<link name="{0}"><visual><geometry><mesh filename="huge.stl"/></geometry></visual></link>'
    )
    urdf = tmp_path / "r.urdf"
    urdf.write_text(
        f'<robot name="r">{link.format("a")}{link.format("b")}<joint name="j" type="revolute">'
        '<parent link="a"/><child link="b"/><axis xyz="0 0 1"/>'
        '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>'
    )
    with pytest.raises(URDFError, match=r"its 1 mesh files hold 200.0 MiB, at most 128 MiB"):
        load_urdf(urdf)


# ---- uploads: per tab, in total, zips, cleaning ----------------------------------------------
class _FakeServer:
    """What :func:`webui.upload_guard.guard_uploads` uses of a viser server."""

    def __init__(self) -> None:
        self.seen: list[tuple[str, object]] = []
        start, part = _messages.FileTransferStartUpload, _messages.FileTransferPart
        self.gui = type("Gui", (), {"_current_file_upload_states": {}})()

        def viser_start(client: object, m: Any) -> None:
            self.gui._current_file_upload_states[m.transfer_uuid] = m
            self.seen.append(("start", m.transfer_uuid))

        def viser_part(client: object, m: Any) -> None:
            self.seen.append(("part", m.transfer_uuid))

        handlers = {start: [viser_start], part: [viser_part]}
        self._websock_server = type("Ws", (), {"_incoming_handlers": handlers})()
        self.disconnect: list[Any] = []

    def on_client_disconnect(self, fn: Any) -> None:
        self.disconnect.append(fn)

    def send(self, client: int, message: object) -> None:
        for handler in self._websock_server._incoming_handlers[type(message)]:
            handler(client, message)


def _start(uuid: str, size: int) -> _messages.FileTransferStartUpload:
    return _messages.FileTransferStartUpload(
        source_component_uuid="b",
        transfer_uuid=uuid,
        filename=f"{uuid}.stl",
        mime_type="model/stl",
        part_count=100,
        size_bytes=size,
    )


def test_unfinished_uploads_are_bounded_per_tab_and_in_total() -> None:
    """Before: 24 unfinished uploads from one tab took the server from 697 to 1,552 MB."""
    from webui.upload_guard import guard_uploads

    server = _FakeServer()
    said: list[tuple[int, str]] = []
    guard_uploads(server, 50 << 20, lambda c, n, m: said.append((c, m)))  # type: ignore[arg-type]
    states = server.gui._current_file_upload_states
    server.send(1, _start("a1", 40 << 20))
    server.send(1, _start("a2", 40 << 20))
    server.send(1, _start("a3", 1 << 20))  # a third from the same tab
    assert set(states) == {"a1", "a2"}
    assert "a3.stl: this tab has 2 uploads under way, at most 2" in said[-1][1]
    server.send(2, _start("b1", 49 << 20))  # another tab: 129 MiB in all
    assert "b1" not in states and "at most 128 MiB at a time for all tabs" in said[-1][1]
    server.send(2, _start("b2", 40 << 20))
    assert "b2" in states
    server.send(1, _messages.FileTransferPart(None, "a1", 0, b"x" * 10))
    assert ("part", "a1") in server.seen
    for fn in server.disconnect:  # tab 1 leaves: its uploads no longer count
        fn(type("Client", (), {"client_id": 1})())
    assert "a1" not in states and "a2" not in states
    server.send(2, _start("b3", 40 << 20))
    assert "b3" in states


def test_a_silent_upload_is_dropped_when_another_starts(monkeypatch: pytest.MonkeyPatch) -> None:
    from webui import upload_guard

    server = _FakeServer()
    upload_guard.guard_uploads(server, 50 << 20, lambda c, n, m: None, idle_s=60.0)  # type: ignore[arg-type]
    states = server.gui._current_file_upload_states
    now = time.monotonic()
    server.send(1, _start("old1", 1000))
    server.send(1, _start("old2", 1000))
    monkeypatch.setattr(upload_guard.time, "monotonic", lambda: now + 61.0)
    server.send(1, _start("new", 1000))
    assert set(states) == {"new"}


def _zip(name: str, size: int) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED, compresslevel=9) as z:
        z.writestr("r/robot.urdf", '<robot name="r"><link name="a"/></robot>')
        with z.open(f"r/meshes/{name}", "w") as f:
            chunk = b"\0" * (1 << 20)
            for _ in range(size >> 20):
                f.write(chunk)
    return buf.getvalue()


@pytest.mark.slow
def test_a_zip_bomb_is_refused_before_unpacking(tmp_path: Path) -> None:
    """Before: a 513 KB zip that unpacks to 450 MiB was accepted (the limit was 500 MiB, and
    each file was read whole into memory)."""
    from webui.urdf_zip import unpack_robot_zip

    bomb = _zip("big.stl", 450 << 20)
    assert len(bomb) < 1 << 20
    with pytest.raises(InputError, match=r"unpacks to 450 MiB, at most 128 MiB"):
        unpack_robot_zip("bomb.zip", bomb, tmp_path / "a")
    small = _zip("zeros.stl", 20 << 20)
    with pytest.raises(InputError, match=r"times its size, at most 100 .*zip bomb"):
        unpack_robot_zip("small.zip", small, tmp_path / "b")
    assert not (tmp_path / "a").exists() and not (tmp_path / "b").exists()


def test_unused_upload_folders_are_cleaned(tmp_path: Path) -> None:
    """Before: every upload stayed in ~/.cache/wobjcal/uploads for ever."""
    from webui import uploads

    up, auto = tmp_path / "uploads", tmp_path / "autosave"
    folders = {}
    for i, name in enumerate(("a" * 16, "b" * 16, "c" * 16, "d" * 16)):
        folders[name] = up / name
        (up / name).mkdir(parents=True)
        (up / name / "part.stl").write_bytes(b"x" * 1000)
        os.utime(up / name, (1000.0 + i, 1000.0 + i))  # long ago, oldest first
    auto.mkdir()
    (auto / "plan-1-8080.json").write_text(json.dumps({"mesh": str(up / ("b" * 16) / "p.stl")}))
    os.utime(up / ("d" * 16), None)  # written just now: maybe another server's
    removed = uploads.prune(up, [str(up / ("c" * 16) / "part.stl")], auto)
    assert [p.name for p in removed] == ["a" * 16]  # b: an autosave, c: in use, d: recent
    with pytest.raises(InputError, match=r"exceed the 0 MiB kept for uploads"):
        uploads.check_room(up, 10, [str(up / ("c" * 16))], auto, limit=1500)
    assert not (up / ("d" * 16)).exists(), "the oldest unused went first"
    assert (up / ("b" * 16)).exists() and (up / ("c" * 16)).exists()


# ---- the autosave a crash left, and errors without a message --------------------------------
def _edited_autosave(plan: Path, port: int) -> Path:
    from webui import autosave

    doc = json.loads(plan.read_text())
    doc["points"] = [p for p in doc["points"] if p["id"] != "P1"]
    path = autosave.default_autosave_path(plan, port)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(doc))
    later = plan.stat().st_mtime + 10
    os.utime(path, (later, later))
    return path


@pytest.mark.slow
def test_an_autosave_whose_restore_crashed_is_not_restored_again(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Before: an autosave that crashed the server was restored at every start until
    --fresh, without a word."""
    import webui.server
    from webui import autosave
    from webui.testing import box_plan, free_port

    monkeypatch.setattr(autosave, "AUTOSAVE_DIR", tmp_path / "autosave")
    plan = box_plan(tmp_path / "plan")
    saved = _edited_autosave(plan, 1)
    real = webui.server.WobjcalApp

    def crash(*args: Any, **kwargs: Any) -> Any:
        raise MemoryError

    monkeypatch.setattr(webui.server, "WobjcalApp", crash)
    with pytest.raises(MemoryError):
        webui.server.run(plan, port=free_port(), block=False)
    assert autosave.restore_unfinished(saved), "the unfinished restore left its mark"
    monkeypatch.setattr(webui.server, "WobjcalApp", real)
    app = webui.server.run(plan, port=free_port(), block=False)
    try:
        assert "P1" in app.state.doc.ids, "started from the plan"
        note = app.autosave_note
        assert note.startswith(f"not restored: the last start from the autosave {saved} ")
        assert "kept as" in note and "wobjcal ui COPY.json" in note
        assert not saved.exists() and not autosave.restore_unfinished(saved)
        assert list(saved.parent.glob("*.bak"))
    finally:
        app.stop()
    again = _edited_autosave(plan, 2)  # a restore that finishes leaves no mark
    app = webui.server.run(plan, port=free_port(), block=False)
    try:
        assert "P1" not in app.state.doc.ids and app.autosave_note.startswith("restored")
        assert not autosave.restore_unfinished(again)
    finally:
        app.stop()


def test_an_error_without_a_message_is_named(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before: `wobjcal ui` printed only `wobjcal ui: error: ` (a TimeoutError has no text)."""
    import webui.server
    from webui.testing import box_plan

    plan = box_plan(tmp_path)

    def timeout(*args: Any, **kwargs: Any) -> Any:
        raise TimeoutError

    monkeypatch.setattr(webui.server, "run", timeout)
    assert main(["ui", str(plan)]) == 2
    assert "wobjcal ui: error: TimeoutError: a step did not finish within its time limit" in (
        capsys.readouterr().err
    )

    def oom(*args: Any, **kwargs: Any) -> Any:
        raise MemoryError

    monkeypatch.setattr(webui.server, "run", oom)
    assert main(["ui", str(plan)]) == 2
    assert "internal error: out of memory (MemoryError: the machine ran out of memory)" in (
        capsys.readouterr().err
    )


def test_suggest_points_of_interest_are_bounded(capsys: pytest.CaptureFixture[str]) -> None:
    """Before: --at took any number of points (each a row of the design's prediction)."""
    at = ";".join(["0,-600,-150"] * 101)
    assert main(["suggest", str(STATOR), "--at", at, "-o", "/dev/null"]) == 2
    assert "101 points, at most 100" in capsys.readouterr().err
