"""Compile the broad phase's numba kernels ahead of use and keep them in numba's cache.

numba compiles a kernel the first time it is called (about 8 s of CPU for all of them, nearly
all of it numba's own typing and lowering: LLVM's optimisation level changes it by < 5 %) and
then loads it from its cache (:mod:`planner.cell.kernel_cache`) in ~0.3 s. Two ways keep a
user from paying the compile on a check:

- ``python -m planner.cell.warmup`` (the install step: ``.ci/test`` and the README's install
  command run it) compiles every kernel into the cache;
- :func:`start_background`, called when the first kernel module is imported with a cache that
  was never warmed, starts that same command in a second process that compiles the kernels in
  the reverse of the order a check first needs them: the check compiles from the front, the
  helper from the back, and each loads what the other already wrote (numba looks in its cache
  before compiling). On a second free core a cold map is ~3 s shorter; under the UI, where the
  cell loads well before the first click, the click finds the kernels compiled.

A marker file (:func:`marker_path`, keyed by the kernels' source, numba's and Python's versions)
says the cache was warmed; the cache itself is still checked by numba entry by entry, so a
stale or missing entry costs a compile, never an answer. ``WOBJCAL_BACKGROUND_COMPILE=0``
turns the helper off.
"""

from __future__ import annotations

import argparse
import hashlib
import importlib
import logging
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numba
from numba.core import sigutils

log = logging.getLogger(__name__)

#: The kernels a check calls from Python (module, function), in the order a map first needs
#: them, with the argument types it calls them with (numba's signature syntax; checked against
#: a real map by ``tests/test_warmup.py``). The helpers they call are compiled with them.
_I, _F, _M, _B = "int64[::1]", "float64[::1]", "float64[:, ::1]", "boolean[:, ::1]"
_T3, _T4, _IM = "float64[:, :, ::1]", "float64[:, :, :, ::1]", "int64[:, ::1]"
KERNELS: tuple[tuple[str, str, str], ...] = (
    (
        "planner.cell.field_kernels",
        "rasterize_band",
        f"({_M}, {_IM}, {_F}, float64, {_I}, float64, {_T3})",
    ),
    (
        "planner.cell.mesh_kernels",
        "shape_vs_mesh",
        f"({_M}, int64, {_F}, {_F}, {_F}, {_M}, int64, int64, int64, {_M}, {_F}, {_IM}, {_I}, "
        f"{_I}, {_I}, {_I}, {_I}, {_I}, {_M}, {_IM}, float64, float64, {_M}, {_M}, {_F}, {_F})",
    ),
    (
        "planner.cell.broad_kernels",
        "parts_state",
        f"({_T4}, {_B}, {_I}, {_I}, {_F}, {_F}, {_M}, {_F}, {_I}, {_I}, {_I}, {_I}, {_T3}, "
        f"{_M}, {_M}, {_M}, {_I}, {_I}, {_M}, {_I}, {_I}, {_I}, {_T3}, {_T3}, {_M}, {_I}, "
        f"{_M}, {_F}, {_IM}, {_I}, float32[::1], {_M}, {_M}, {_M}, {_F}, {_IM}, {_I}, {_I}, "
        f"{_I}, {_I}, {_I}, {_I}, {_M}, {_IM}, boolean)",
    ),
    (
        "planner.cell.broad_kernels",
        "pairs_state",
        f"({_T4}, {_B}, {_I}, {_I}, {_F}, {_F}, {_M}, {_F}, {_I}, {_I}, {_I}, {_I}, {_T3}, "
        f"{_M}, {_M}, {_M}, {_I}, {_I}, {_M}, {_I}, {_I}, boolean)",
    ),
    (
        "planner.cell.bound_kernels",
        "slack_upper",
        f"({_T4}, {_B}, {_I}, {_I}, {_F}, {_F}, {_F}, {_B}, {_I}, {_I}, {_F}, {_F}, {_F}, "
        f"{_I}, {_T3}, {_M}, {_I}, {_I}, {_M}, {_I}, {_I}, {_I}, {_T3}, {_M})",
    ),
)
#: Modules whose source the compiled kernels depend on (the marker's key).
SOURCES = (
    "gjk_kernels",
    "bound_kernels",
    "broad_kernels",
    "field_kernels",
    "mesh_kernels",
    "kernel_cache",
    "warmup",
)
_ENV_OFF = "WOBJCAL_BACKGROUND_COMPILE"
_ENV_CHILD = "WOBJCAL_WARMUP_CHILD"
_started = threading.Lock()
_helper: list[subprocess.Popen[bytes]] = []


def _key() -> str:
    here = Path(__file__).resolve().parent
    h = hashlib.sha256(f"{numba.__version__} {sys.version}".encode())
    for name in SOURCES:
        h.update((here / f"{name}.py").read_bytes())
    return h.hexdigest()[:16]


def marker_path(cache_dir: Path) -> Path:
    """The file that says ``cache_dir`` holds the kernels of this source and numba."""
    return cache_dir / f"warm-{_key()}"


def compile_kernels(reverse: bool = False) -> float:
    """Compile (or load from numba's cache) every kernel of :data:`KERNELS`.

    Args:
        reverse: from the last needed to the first (the background helper's order).

    Returns:
        Wall seconds taken.
    """
    t0 = time.perf_counter()
    for module, name, signature in reversed(KERNELS) if reverse else KERNELS:
        args, _ = sigutils.normalize_signature(signature)
        # a tuple of types, as a call passes them: numba's cache is keyed by what compile()
        # is given, and a string would make an entry a call never finds
        getattr(importlib.import_module(module), name).compile(tuple(args))
    return time.perf_counter() - t0


def start_background(cache_dir: Path | None) -> bool:
    """Start the helper process (module docstring) unless ``cache_dir`` was warmed, it runs
    already, this is the helper, or ``WOBJCAL_BACKGROUND_COMPILE=0``; True when started."""
    if (
        cache_dir is None
        or os.environ.get(_ENV_CHILD)
        or os.environ.get(_ENV_OFF, "1") == "0"
        or marker_path(cache_dir).exists()
    ):
        return False
    with _started:
        if _helper:
            return False
        env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir), **{_ENV_CHILD: "1"})
        src = str(Path(__file__).resolve().parents[2])
        env["PYTHONPATH"] = os.pathsep.join(p for p in (src, env.get("PYTHONPATH")) if p)
        try:
            proc = subprocess.Popen(
                [sys.executable, "-m", "planner.cell.warmup", "--reverse"],
                env=env,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        except OSError as exc:  # no helper: the check compiles what it needs itself
            log.info("no background compile of the kernels: %s", exc)
            return False
        _helper.append(proc)
    threading.Thread(target=proc.wait, name="wobjcal-warmup-reaper", daemon=True).start()
    log.info("compiling the broad phase's kernels in the background (pid %d)", proc.pid)
    return True


def main(argv: list[str] | None = None) -> int:
    """``python -m planner.cell.warmup [--reverse]``: compile every kernel into the cache."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--reverse", action="store_true", help="last needed first (the helper)")
    args = ap.parse_args(argv)
    if os.environ.get(_ENV_CHILD) and hasattr(os, "nice"):
        os.nice(10)  # the helper takes a spare core, never the check's
    from planner.cell.kernel_cache import configure

    cache_dir = configure()
    seconds = compile_kernels(reverse=args.reverse)
    if cache_dir is not None:
        marker = marker_path(cache_dir)
        tmp = marker.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(f"{seconds:.2f} s\n")
        tmp.replace(marker)
    if not os.environ.get(_ENV_CHILD):
        sys.stdout.write(f"wobjcal kernels ready in {cache_dir or 'numba default cache'} ")
        sys.stdout.write(f"({seconds:.1f} s)\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
