"""Where numba keeps the machine code of the broad phase's kernels: wobjcal's per-user cache.

The kernels (:mod:`~planner.cell.kernels.gjk_kernels`, :mod:`~planner.cell.kernels.field_kernels`,
:mod:`~planner.cell.kernels.mesh_kernels`, :mod:`~planner.cell.kernels.broad_kernels`) are compiled
with ``cache=True``. By default numba writes its cache next to the source (``__pycache__``), which a
read-only install cannot. :func:`configure` points numba at ``<cache root>/numba``
(``$WOBJCAL_CACHE_DIR/numba``, default ``~/.cache/wobjcal/numba``), beside the distance fields
and allowed-collision lists, so one directory holds every derived file and emptying it is a
true cold start. ``NUMBA_CACHE_DIR``, when set, wins. When the directory cannot be created or
written, numba's own fallbacks apply (next to the source, then its user-wide directory). A
kernel numba then cannot save or load (a full disk, an unreadable file) is compiled in memory
with one warning per process (:func:`guard_cache_io`): the cache is optional, a command that
finds it broken is slower, never failed.

The kernels live in a subdirectory named by a hash of all the kernel modules' sources
(:func:`source_key`), and other versions' subdirectories are deleted: numba checks a cached
kernel only against its *own* file's stamp, but a cached caller contains the machine code of
the helpers it calls from other files (``broad_kernels`` calls ``gjk_kernels``), so a change to
a helper alone would otherwise leave its callers running the old code. With the key, a changed
source costs a compile, never an answer.

Each kernel module calls :func:`configure` before its first ``@njit``: numba picks the
directory when a function is decorated. The first call also starts the background compile of
:mod:`planner.cell.kernels.warmup` when that directory was never warmed (:func:`start_background`).
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import os
import shutil
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numba

from planner.cell.disk_cache import cache_root, warn_once

log = logging.getLogger(__name__)
#: numba's settings (attributes made at run time, so untyped).
_CONFIG: Any = numba.config


def kernel_cache_dir() -> Path | None:
    """The directory numba caches kernels in, or ``None`` when numba chose it itself."""
    return Path(_CONFIG.CACHE_DIR) if _CONFIG.CACHE_DIR else None


def configure() -> Path | None:
    """Point numba's cache at wobjcal's (see the module docstring); idempotent.

    Returns:
        The directory in use, or ``None`` when numba's defaults apply (not writable).
    """
    guard_cache_io()
    if _CONFIG.CACHE_DIR:  # NUMBA_CACHE_DIR or an earlier call
        return Path(_CONFIG.CACHE_DIR)
    key = source_key()
    path = cache_root() / "numba" / key
    if _writable(path):
        _CONFIG.CACHE_DIR = str(path)
        _remove_other_versions(path.parent, key)
        start_background(path)
        return path
    return None


def guard_cache_io() -> None:
    """Make a failure of numba's cache I/O a slower compile, not an error (idempotent).

    numba saves and loads each kernel inside ``Cache._guard_against_spurious_io_errors``,
    which on Windows swallows ``EACCES`` and elsewhere lets everything through: a full disk
    under the cache made ``wobjcal check`` fail. Here any :class:`OSError` there is swallowed
    (numba then compiles, or keeps the compiled kernel in memory) and told once per process.
    """
    from numba.core import caching

    cache_class: Any = caching.Cache
    if getattr(cache_class, "_wobjcal_guarded", False):
        return

    @contextlib.contextmanager
    def guard(cache: Any) -> Iterator[None]:
        try:
            yield
        except OSError as exc:
            where = getattr(cache, "cache_path", "numba's cache")
            warn_once("numba", f"cannot use the kernel cache {where}: {exc.strerror or exc}")

    cache_class._guard_against_spurious_io_errors = guard
    cache_class._wobjcal_guarded = True


def _remove_other_versions(root: Path, key: str) -> None:
    """Delete the kernels of other sources (best effort: another process of another version
    that loses its cache only compiles again)."""
    try:
        entries = list(root.iterdir())
    except OSError:
        return
    for d in entries:
        if d.is_dir() and d.name != key and len(d.name) == len(key) and _is_hex(d.name):
            shutil.rmtree(d, ignore_errors=True)


def _is_hex(name: str) -> bool:
    return all(c in "0123456789abcdef" for c in name)


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
        if not os.access(path, os.W_OK):
            raise PermissionError(f"{path} is not writable")
    except OSError as exc:
        log.info("numba kernels cached by numba's defaults: %s", exc)
        return False
    return True


#: Modules whose source the compiled kernels depend on (the marker's key).
SOURCES = (
    "gjk_kernels",
    "bound_kernels",
    "broad_kernels",
    "field_kernels",
    "mesh_kernels",
    "kernel_cache",
    "lazy_kernel",
    "warmup",
)
_ENV_OFF = "WOBJCAL_BACKGROUND_COMPILE"
#: Set in the helper process (it starts no helper of its own).
CHILD_ENV = "WOBJCAL_WARMUP_CHILD"
_started = threading.Lock()
_helper: list[subprocess.Popen[bytes]] = []


def source_key(here: Path | None = None) -> str:
    """16 hex digits of the kernels' sources (:data:`SOURCES` in ``here``, default this
    package), numba's and Python's versions: the name of the cache directory."""
    here = Path(__file__).resolve().parent if here is None else here
    h = hashlib.sha256(f"{numba.__version__} {sys.version}".encode())
    for name in SOURCES:
        h.update((here / f"{name}.py").read_bytes())
    return h.hexdigest()[:16]


def marker_path(cache_dir: Path) -> Path:
    """The file that says ``cache_dir`` holds the kernels of this source and numba."""
    return cache_dir / f"warm-{source_key()}"


def start_background(cache_dir: Path | None) -> bool:
    """Start the helper process of :mod:`planner.cell.kernels.warmup` unless ``cache_dir`` was
    warmed, it runs already, this is the helper, or ``WOBJCAL_BACKGROUND_COMPILE=0``; True
    when started."""
    if (
        cache_dir is None
        or os.environ.get(CHILD_ENV)
        or os.environ.get(_ENV_OFF, "1") == "0"
        or marker_path(cache_dir).exists()
    ):
        return False
    with _started:
        if _helper:
            return False
        env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir), **{CHILD_ENV: "1"})
        src = str(Path(__file__).resolve().parents[3])
        env["PYTHONPATH"] = os.pathsep.join(p for p in (src, env.get("PYTHONPATH")) if p)
        try:
            proc = subprocess.Popen(
                # -P: never the current directory on sys.path (a user's folder could shadow
                # a module); cwd: the source tree, whose planner is the one imported here
                [sys.executable, "-P", "-m", "planner.cell.kernels.warmup", "--reverse"],
                cwd=src,
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
