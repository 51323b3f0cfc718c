"""suggest on a part with one reachable face: the thin interface plate of the reference CAD
(``base_interface_AP214.STEP``, 599 x 639 x 4.8 mm, modelled in inches).

Its 4.8 mm sides hold no 18 mm footprint, its underside faces the pedestal, and no edge track
stays clear of its holes under a 10 mm / 2 deg bound: no layout fixes all six degrees of
freedom. The command refuses in one message that says so, naming the edge searches it looked
for (an empty set of edge candidates once raised a numpy error from inside suggest), exit 2,
and writes nothing.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import msgspec
import pytest

from calib.models import Misplacement, ProximitySensor
from calib.plan.file import Pose, file_sha256, load_plan, save_plan
from planner.cli import main

pytest.importorskip("OCP", reason="STEP parts need cadquery-ocp-novtk (pyproject dependencies)")

REPO = Path(__file__).resolve().parents[3]
TEMPLATE = REPO / "assets" / "plans" / "plate_holes_best_fit.json"
PART = "base_interface_AP214.STEP"


@pytest.fixture
def plate_plan(reference_dir: Path, tmp_path: Path) -> Path:
    """The shipped plate plan with the STEP plate as its work object, on the pedestal."""
    shutil.copy(reference_dir / "cad" / PART, tmp_path / PART)
    rep = msgspec.structs.replace
    plan = load_plan(TEMPLATE)
    work_object = rep(
        plan.work_object,
        mesh=PART,
        units="auto",
        sha256=file_sha256(tmp_path / PART),
        T_world_wobj=Pose(position_m=(1.30, 0.05, 0.75), quat_wxyz=(1.0, 0.0, 0.0, 0.0)),
    )
    validation = rep(
        plan.validation,
        sensor=ProximitySensor(face_diameter_m=0.018),
        misplacement=Misplacement(max_translation_m=0.010, max_angle_rad=math.radians(2.0)),
    )
    plan = rep(plan, name="interface_plate", work_object=work_object, validation=validation)
    return save_plan(plan, tmp_path / "interface_plate.json")


@pytest.mark.slow
@pytest.mark.parametrize("procedure", ["best_fit", "three_two_one"])
def test_a_part_with_one_reachable_face_is_refused_in_one_message(
    plate_plan: Path, procedure: str, capsys: pytest.CaptureFixture[str]
) -> None:
    out = plate_plan.parent / "suggested.json"
    code = main(["suggest", str(plate_plan), "--procedure", procedure, "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "Traceback" not in err and not out.exists()
    assert "no layout fixes all 6 degrees of freedom" in err, err
    assert "normal +z" in err and "feasible poses" in err, err  # the one face it can reach
    assert "edge searches: none" in err and "clear of holes and other edges" in err, err
