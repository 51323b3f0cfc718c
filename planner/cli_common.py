"""Helpers shared by the ``wobjcal`` commands: consoles, plan loading, JSON output."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

from rich.console import Console

from calib.plan import Plan, load_plan

#: Where the shipped plans live.
PLANS_DIR = Path(__file__).resolve().parent.parent / "assets" / "plans"
#: The built-in demo plan (the paper's A-H plan on the built-in stator cell).
DEMO_PLAN = PLANS_DIR / "stator_section_ah.json"


def stdout() -> Console:
    """A console on the current ``sys.stdout`` (tests capture it); no colour when piped."""
    return Console(file=sys.stdout, highlight=False, soft_wrap=True)


def stderr() -> Console:
    """A console on the current ``sys.stderr`` for progress and notes."""
    return Console(file=sys.stderr, highlight=False)


def read_plan(path: str) -> tuple[Plan, Path]:
    """Load the plan at ``path`` strictly; return it and its directory (for relative paths)."""
    p = Path(path)
    return load_plan(p), p.resolve().parent


def print_json(obj: Any) -> None:
    """Print ``obj`` as indented JSON on stdout (keys sorted, finite numbers only)."""
    sys.stdout.write(json.dumps(obj, indent=2, sort_keys=True, allow_nan=False) + "\n")
