"""``.ci/constraints.txt``: CI installs through it, so it must pin every package the project
names (its dependencies and its ``test`` extra), each at a version the project accepts."""

from __future__ import annotations

import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

REPO = Path(__file__).resolve().parents[1]


def _pins() -> dict[str, str]:
    out: dict[str, str] = {}
    for line in (REPO / ".ci" / "constraints.txt").read_text().splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        name, _, version = line.partition("==")
        assert version, f"not a pin: {line!r}"
        out[canonicalize_name(name)] = version
    return out


def test_every_named_dependency_is_pinned_within_its_range() -> None:
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    named = [*project["dependencies"], *project["optional-dependencies"]["test"]]
    pins = _pins()
    missing, outside = [], []
    for text in named:
        req = Requirement(text)
        if req.marker is not None and not req.marker.evaluate({"extra": "test"}):
            continue
        pin = pins.get(canonicalize_name(req.name))
        if pin is None:
            missing.append(req.name)
        elif not req.specifier.contains(pin, prereleases=True):
            outside.append(f"{req.name}=={pin} (wants {req.specifier})")
    assert missing == [] and outside == [], (
        "regenerate: python3 .ci/freeze_constraints.py (see the file's header)"
    )


def test_ci_installs_through_the_constraints() -> None:
    assert "-c .ci/constraints.txt" in (REPO / ".ci" / "test").read_text()
