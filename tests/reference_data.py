"""Where the tests find ``../shared/reference`` (real inputs nobody here made), and the mark of
the tests that run a shipped plate plan, whose mesh lives there.

The shipped plate plans (``assets/plans/plate_holes_*.json``) name
``../shared/reference/parts/plate_holes.STL`` as their mesh (trimesh's MIT-licensed plate; not
copied into the project). A test that runs one is marked ``reference`` (a whole test, or only
its plate cases with :func:`plate_case`); ``tests/conftest.py`` skips those where the mesh is
absent, and lets them fail under CI. Where the mesh is present (CI), :func:`watched` fails a
test that opens it without that mark or the ``reference_dir`` fixture: such a test would fail,
not skip, in a clone without ``../shared``. It sees opens on the test's own thread, in setup
and call; not those of other threads or of subprocesses (a CLI run in a child), and a module
fixture's open is laid to the test that sets it up first.
"""

from __future__ import annotations

import json
import os
import threading
from collections.abc import Generator, Iterable
from pathlib import Path
from typing import Any

import pytest

REFERENCE = Path(__file__).resolve().parent.parent.parent / "shared" / "reference"
#: The shipped plate plans' mesh.
PLATE_MESH = REFERENCE / "parts" / "plate_holes.STL"


def plate_case(*values: Any, id: str | None = None, marks: Any = ()) -> Any:
    """A ``parametrize`` case that runs a shipped plate plan: ``pytest.param`` marked
    ``reference`` (besides ``marks``)."""
    extra = marks if isinstance(marks, (list, tuple)) else (marks,)
    return pytest.param(*values, id=id, marks=(pytest.mark.reference, *extra))


def plan_cases(paths: Iterable[Path]) -> list[Any]:
    """Plan files as ``parametrize`` cases (id: the file's stem), those whose mesh is the
    plate's (:data:`PLATE_MESH`, by the plan's ``work_object.mesh``) marked ``reference``."""
    out = []
    for path in paths:
        mesh = str(json.loads(path.read_text()).get("work_object", {}).get("mesh", ""))
        case = plate_case if Path(mesh).name == PLATE_MESH.name else pytest.param
        out.append(case(path, id=path.stem))
    return out


class _PlateOpens:
    """An audit hook (:func:`sys.addaudithook`) that notes an ``open`` of :data:`PLATE_MESH` by
    the thread running the current test (other threads, e.g. a server's left from an earlier
    test, are not counted). It never raises: an audit hook's exception would fail the open."""

    def __init__(self) -> None:
        self.thread: int | None = None
        self.opened = False
        self._real = os.path.realpath(PLATE_MESH)
        self._ident = threading.get_ident  # kept: module globals are gone at shutdown

    def __call__(self, event: str, args: tuple[Any, ...]) -> None:
        try:
            if event != "open" or self.opened or self.thread != self._ident():
                return
            name = os.fsdecode(args[0])
            if name.endswith(PLATE_MESH.name) and os.path.realpath(name) == self._real:
                self.opened = True
        except Exception:  # an fd, another type of path, an interpreter shutting down
            return


PLATE_OPENS = _PlateOpens()


def watched(item: pytest.Item) -> Generator[None, Any, Any]:
    """The body of a ``pytest_runtest_setup``/``_call`` wrapper: fails ``item`` when it opened
    :data:`PLATE_MESH` unmarked (see the module docstring)."""
    PLATE_OPENS.thread, PLATE_OPENS.opened = threading.get_ident(), False
    try:
        result = yield
    finally:
        PLATE_OPENS.thread = None
    # the fixtures asked for by name too (request.getfixturevalue): pytest's request knows them
    request = getattr(item, "_request", None)
    names = getattr(request, "fixturenames", None) or getattr(item, "fixturenames", ())
    allowed = item.get_closest_marker("reference") or "reference_dir" in names
    if PLATE_OPENS.opened and not allowed:
        pytest.fail(
            f"{item.nodeid} opens {PLATE_MESH} (a shipped plate plan's mesh) but is not marked "
            "'reference': mark it (or its plate cases, tests.reference_data.plate_case), or load "
            "the plan with check_files=False if it needs no mesh",
            pytrace=False,
        )
    return result


def ur5_stator_plan(reference_dir: Path, folder: Path, edge_event_offset_m: float | None) -> Path:
    """The shipped stator A-H plan with the vendor UR5 (``reference_dir``'s) as its robot and
    the given edge-event offset (``None``: the sensor model's), saved in ``folder``; its path."""
    import msgspec

    from calib.plan.file import load_plan, save_plan
    from planner.suggest import moved_plan

    stator = Path(__file__).resolve().parents[1] / "assets" / "plans" / "stator_section_ah.json"
    plan = load_plan(stator)
    urdf = str(reference_dir / "robots" / "ur5" / "ur5.urdf")
    plan = msgspec.structs.replace(
        plan,
        cell=msgspec.structs.replace(
            plan.cell, robot=msgspec.structs.replace(plan.cell.robot, urdf=urdf)
        ),
        procedure=msgspec.structs.replace(plan.procedure, edge_event_offset_m=edge_event_offset_m),
    )
    path = folder / "stator_ur5.json"
    save_plan(moved_plan(plan, stator.parent, folder), path)
    return path
