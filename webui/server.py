"""Starting the wobjcal UI: the port, the autosave of earlier sessions, serving until stopped.

``run()`` starts the server (127.0.0.1:8080 by default; viser moves on to the next free port
when that one is busy, and ``app.server.get_port()`` is the one bound), restores the newest
autosave of an earlier session of the plan or sets it aside (:mod:`webui.autosave`), and
returns the :class:`webui.app.WobjcalApp`; :func:`serve` keeps it running until Ctrl-C or
SIGTERM. ``wobjcal ui`` calls both.
"""

from __future__ import annotations

import logging
import signal
import threading
from collections.abc import Callable
from pathlib import Path

import viser

from calib.errors import InputError
from webui import demo
from webui.app import WobjcalApp
from webui.autosave import (
    AutosaveLock,
    AutosaveLockedError,
    FoundAutosave,
    clear_restoring,
    default_autosave_path,
    find_newer_autosave,
    mark_restoring,
    restore_unfinished,
    set_aside,
)
from webui.plan_adapter import autosave_bytes, ui_plan_from_file
from webui.plan_doc import UiPlan
from webui.scene import configure_lighting

logger = logging.getLogger(__name__)

__all__ = ["check_port", "run", "serve"]


def check_port(port: object) -> int:
    """``port`` as a TCP port number 0-65535 (0: any free port).

    Raises:
        InputError: not an integer in that range (``--port 99999`` used to hang the server).
    """
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise InputError(f"port: must be a whole number 0-65535 (0: any free port), got {port!r}")
    return port


def _restore(found: FoundAutosave, plan_dir: Path) -> UiPlan:
    """The session plan an autosave holds (its file references resolve from ``plan_dir``)."""
    from calib.plan.file import check_plan_files, plan_from_json
    from webui.plan_adapter import ui_plan_from_plan

    plan = plan_from_json(found.path.read_text(encoding="utf-8"), source=str(found.path))
    check_plan_files(plan, plan_dir, source=str(found.path))
    return ui_plan_from_plan(plan, name=plan.name or found.path.stem)


def run(
    plan_path: str | Path | None = None,
    host: str = "127.0.0.1",
    port: int = 8080,
    block: bool = True,
    autosave_path: str | Path | None = "auto",
    fresh: bool = False,
) -> WobjcalApp:
    """Start the wobjcal UI on ``http://host:port`` with a plan file or the built-in demo.

    Args:
        plan_path: a ``wobjcal.plan/1`` file; ``None`` opens the built-in stator-section demo.
        host: interface to bind; 127.0.0.1 (this machine only) unless told otherwise.
        port: TCP port (0-65535; 0 any free one); when it is busy viser binds the next free
            one: ``app.server.get_port()`` is the one bound.
        block: serve until interrupted (Ctrl-C or SIGTERM), then stop; ``False`` returns at
            once.
        autosave_path: where the session plan autosaves; ``"auto"`` (default): one file per
            plan and bound port under ``~/.cache/wobjcal/autosave/`` (see
            :func:`webui.autosave.default_autosave_path`); ``None`` disables autosave.
        fresh: start from the plan file even when a newer autosave of an earlier session
            exists (it is renamed ``<file>.<time>.bak``, not overwritten); by default it is
            restored. Either way ``app.autosave_note`` says what happened (the CLI prints it,
            each new tab shows it).

    Returns:
        The running app (``app.server`` is the viser server; ``app.stop()`` ends it).

    Raises:
        InputError: a bad port, a plan that cannot be loaded, or an autosave file held by
            another running server.
    """
    check_port(port)
    if plan_path is not None:
        ui_plan, plan_dir = ui_plan_from_file(Path(plan_path)), Path(plan_path).parent
    else:
        ui_plan, plan_dir = demo.demo_ui_plan()
    server = viser.ViserServer(host=host, port=port, label="wobjcal", verbose=block)
    bound = server.get_port()
    try:
        auto = autosave_path == "auto"
        path = (
            default_autosave_path(plan_path, bound)
            if auto
            else (None if autosave_path is None else Path(autosave_path))
        )
        lock = None
        note = ""
        restoring: Path | None = None
        if path is not None:
            found = find_newer_autosave(  # before taking our lock: it would hide our file
                plan_path,
                autosave_bytes(ui_plan),
                folder=None if auto else path.parent / ".none",
                also=path,
            )
            try:
                lock = AutosaveLock(path)
            except AutosaveLockedError as exc:
                raise InputError(str(exc)) from None
            if found is not None and not fresh and restore_unfinished(found.path):
                aside = set_aside(found.path)
                clear_restoring(found.path)
                note = (
                    f"not restored: the last start from the autosave {found.path} did not finish "
                    "(the server ran out of memory, was killed or failed while loading it), so "
                    f"it is not loaded again; started from the plan; the autosave is kept as "
                    f"{aside}: to open it, copy it beside the plan file and run "
                    "`wobjcal ui COPY.json`"
                )
            elif found is not None and not fresh:
                try:
                    mark_restoring(found.path)  # cleared once the restored session has loaded
                    restoring = found.path
                    ui_plan = _restore(found, plan_dir)
                    note = f"restored the edits of the last session from {found.describe()}"
                except (InputError, OSError) as exc:
                    clear_restoring(found.path)
                    restoring = None
                    aside = set_aside(found.path)
                    note = (
                        f"not restored: {found.path} is unusable ({exc}); started from the plan, "
                        f"the autosave is kept as {aside}"
                    )
            elif found is not None:
                aside = set_aside(found.path)
                clear_restoring(found.path)
                note = f"started fresh; the last session's autosave is kept as {aside}"
    except BaseException:
        server.stop()
        raise
    server.gui.configure_theme(control_width="large", show_share_button=False)
    configure_lighting(server.scene)  # cheap to render in software WebGL (issue 14 latency)
    # the control panel docked on the right: the 3D view is the rest of the window, nothing
    # floats over the cell (the framing of the first view relies on it)
    server.gui.main_panel.dock_right()
    logger.info("wobjcal UI at http://%s:%d", host, bound)
    if path is not None:
        logger.info("the session plan autosaves to %s", path)
    app = WobjcalApp(server, ui_plan, plan_dir, autosave_path=path)  # the cell, the checks
    if restoring is not None:  # loaded: a later start may restore this session's autosave
        clear_restoring(restoring)
    app.autosave_lock, app.autosave_note = lock, note
    app.files_panel.prune_stale()  # uploads no plan and no autosave uses (issue 27)
    if note:
        logger.warning("%s", note)
    if not block:
        return app
    serve(app)
    return app


#: Exit codes of :func:`serve` (as ``docs/cli.md`` documents them: 128 + the signal).
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143


def serve(app: WobjcalApp, announce: Callable[[], None] | None = None) -> int:
    """Serve until Ctrl-C or SIGTERM, then stop the app (server, worker, autosave lock).

    Args:
        app: the running app (:func:`run` with ``block=False``).
        announce: called once the signals stop the app, before serving (the CLI prints the
            address there): a Ctrl-C right after the address is read still stops the app.

    Returns:
        The exit code: 130 after Ctrl-C, 143 after SIGTERM.
    """
    stop = threading.Event()
    previous = None
    code = EXIT_TERMINATED
    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, lambda *_: stop.set())
    try:
        if announce is not None:
            announce()
        while not stop.wait(0.5):
            pass
    except KeyboardInterrupt:
        logger.info("stopping the wobjcal UI")
        code = EXIT_INTERRUPTED
    finally:
        app.stop()
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    return code
