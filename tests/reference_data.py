"""Where the tests find ``../shared/reference`` (real inputs nobody here made), and the mark of
the tests that run a shipped plate plan, whose mesh lives there.

The shipped plate plans (``assets/plans/plate_holes_*.json``) name
``../shared/reference/parts/plate_holes.STL`` as their mesh (trimesh's MIT-licensed plate; not
copied into the project). A test that runs one is marked ``reference`` (a whole test, or only
its plate cases with :func:`plate_case`); ``tests/conftest.py`` skips those where the mesh is
absent, and lets them fail under CI.
"""

from __future__ import annotations

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
