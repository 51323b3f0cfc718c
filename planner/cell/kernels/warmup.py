"""Compile the broad phase's numba kernels ahead of use and keep them in numba's cache.

numba compiles a kernel the first time it is called (about 8 s of CPU for all of them, nearly
all of it numba's own typing and lowering: LLVM's optimisation level changes it by < 5 %) and
then loads it from its cache (:mod:`planner.cell.kernels.kernel_cache`) in ~0.3 s. Two ways keep a
user from paying the compile on a check:

- ``python -m planner.cell.kernels.warmup`` (the install step: ``.ci/test`` and the README's install
  command run it) compiles every kernel into the cache;
- :func:`planner.cell.kernels.kernel_cache.start_background`, called when the first kernel module is
  imported with a cache that was never warmed, starts that command in a second process at low
  priority, which compiles the kernels in the reverse of the order a check first needs them:
  the check compiles from the front, the helper from the back, and each loads what the other
  already wrote (numba looks in its cache before compiling). Under the UI, where the cell
  loads well before the first click, the click finds the kernels compiled; a cold map in a
  script gains only what a spare core gives (figures in ``docs/cell.md``).

A marker file (:func:`~planner.cell.kernels.kernel_cache.marker_path`, keyed by the kernels' source,
numba's and Python's versions) says the cache was warmed; numba still checks each entry
against its source and the CPU, so a stale or missing entry costs a compile, never an answer.
``WOBJCAL_BACKGROUND_COMPILE=0`` turns the helper off.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import os
import sys
import time

from numba.core import sigutils

from planner.cell.disk_cache import warn_once
from planner.cell.kernels.kernel_cache import CHILD_ENV, configure, marker_path

#: The kernels a check calls from Python (module, function), in the order a map first needs
#: them, with the argument types it calls them with (numba's signature syntax; checked against
#: a real map by ``tests/planner/cell/kernels/test_warmup.py``). The helpers they call are compiled
#: with them.
_I, _F, _M, _B = "int64[::1]", "float64[::1]", "float64[:, ::1]", "boolean[:, ::1]"
_T3, _T4, _IM = "float64[:, :, ::1]", "float64[:, :, :, ::1]", "int64[:, ::1]"
KERNELS: tuple[tuple[str, str, str], ...] = (
    (
        "planner.cell.kernels.field_kernels",
        "rasterize_band",
        f"({_M}, {_IM}, {_F}, float64, {_I}, float64, {_T3})",
    ),
    (
        "planner.cell.kernels.mesh_kernels",
        "shape_vs_mesh",
        f"({_M}, int64, {_F}, {_F}, {_F}, {_M}, int64, int64, int64, {_M}, {_F}, {_IM}, {_I}, "
        f"{_I}, {_I}, {_I}, {_I}, {_I}, {_M}, {_IM}, float64, float64, {_M}, {_M}, {_F}, {_F})",
    ),
    (
        "planner.cell.kernels.broad_kernels",
        "parts_state",
        f"({_T4}, {_B}, {_I}, {_I}, {_F}, {_F}, {_M}, {_F}, {_I}, {_I}, {_I}, {_I}, {_T3}, "
        f"{_M}, {_M}, {_M}, {_I}, {_I}, {_M}, {_I}, {_I}, {_I}, {_T3}, {_T3}, {_M}, {_I}, "
        f"{_M}, {_F}, {_IM}, {_I}, float32[::1], {_M}, {_M}, {_M}, {_F}, {_IM}, {_I}, {_I}, "
        f"{_I}, {_I}, {_I}, {_I}, {_M}, {_IM}, boolean)",
    ),
    (
        "planner.cell.kernels.broad_kernels",
        "pairs_state",
        f"({_T4}, {_B}, {_I}, {_I}, {_F}, {_F}, {_M}, {_F}, {_I}, {_I}, {_I}, {_I}, {_T3}, "
        f"{_M}, {_M}, {_M}, {_I}, {_I}, {_M}, {_I}, {_I}, boolean)",
    ),
    (
        "planner.cell.kernels.bound_kernels",
        "slack_upper",
        f"({_T4}, {_B}, {_I}, {_I}, {_F}, {_F}, {_F}, {_B}, {_I}, {_I}, {_F}, {_F}, {_F}, "
        f"{_I}, {_T3}, {_M}, {_I}, {_I}, {_M}, {_I}, {_I}, {_I}, {_T3}, {_M})",
    ),
)


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


def main(argv: list[str] | None = None) -> int:
    """``python -m planner.cell.kernels.warmup [--reverse]``: compile every kernel into the
    cache."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--reverse", action="store_true", help="last needed first (the helper)")
    args = ap.parse_args(argv)
    if os.environ.get(CHILD_ENV) and hasattr(os, "nice"):
        os.nice(10)  # the helper takes a spare core, never the check's
    cache_dir = configure()
    seconds = compile_kernels(reverse=args.reverse)
    if cache_dir is not None:
        marker = marker_path(cache_dir)
        tmp = marker.with_suffix(f".{os.getpid()}.tmp")
        try:
            tmp.write_text(f"{seconds:.2f} s\n")
            tmp.replace(marker)
        except OSError as exc:  # a cache is optional: the next process warms it again
            warn_once("numba", f"cannot write {marker}: {exc.strerror or exc}")
            with contextlib.suppress(OSError):
                tmp.unlink()
    if not os.environ.get(CHILD_ENV):
        sys.stdout.write(f"wobjcal kernels ready in {cache_dir or 'numba default cache'} ")
        sys.stdout.write(f"({seconds:.1f} s)\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
