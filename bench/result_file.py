"""Writing a bench's result file: ``bench/results/<name>.json``, atomically, the same way for
every bench (a crash never leaves half a file; floats from numpy are written as numbers)."""

from __future__ import annotations

import json
import logging
from pathlib import Path
from typing import Any

from calib.atomic_io import write_text_atomic


def write_result(path: Path, result: dict[str, Any], echo: bool = True) -> None:
    """Write ``result`` as indented JSON to ``path`` (its folder made if missing) and, with
    ``echo``, log it (the bench's output on the console)."""
    text = json.dumps(result, indent=2, default=float) + "\n"
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(path, text)
    if echo:
        logging.getLogger("bench").warning("%s", text.rstrip())
