"""``wobjcal schema``, ``wobjcal ui`` and ``wobjcal demo``."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from typing import Any

from calib.atomic_io import write_text_atomic
from calib.plan.file import load_plan
from calib.plan.json_io import json_schema
from planner.cli.common import stderr
from planner.demo import DEMO_PLAN


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add the commands of this module to the subparsers ``sub``."""
    p = add(
        sub,
        "schema",
        "print the JSON Schema of plan (or measurements) files",
        "Print the JSON Schema generated from the plan types (wobjcal.plan/1), or with\n"
        "--measurements that of measurement files (wobjcal.measurements/1).",
        "wobjcal schema > wobjcal.plan-1.schema.json",
    )
    p.add_argument("--measurements", action="store_true", help="the measurements schema")
    p.set_defaults(handler=cmd_schema)

    for name, help_, example in (
        (
            "ui",
            "open the planning web UI (default: the built-in demo plan)",
            "wobjcal ui my_plan.json --port 8090",
        ),
        (
            "demo",
            "open the web UI on the built-in stator-section cell and its A-H plan",
            "wobjcal demo\nwobjcal demo --write-plan stator_section_ah.json",
        ),
    ):
        p = add(
            sub,
            name,
            help_,
            f"{help_[0].upper()}{help_[1:]}. Serves on http://HOST:PORT until Ctrl-C; binds to\n"
            "127.0.0.1 (this machine only) unless --host says otherwise.",
            example,
        )
        if name == "ui":
            p.add_argument("plan", nargs="?", metavar="PLAN", help="plan file (wobjcal.plan/1)")
        else:
            p.add_argument(
                "--write-plan",
                metavar="FILE",
                help="write the built-in A-H plan to FILE instead of starting the UI",
            )
        p.add_argument("--host", default="127.0.0.1", help="interface to bind (default 127.0.0.1)")
        p.add_argument(
            "--port",
            type=port_arg,
            default=8080,
            help="TCP port 0-65535 (default 8080; 0: any free port); when it is busy the next "
            "free one is used and printed",
        )
        p.add_argument(
            "--fresh",
            action="store_true",
            help="start from the plan even when a newer autosave of the last session exists "
            "(it is kept as .bak); by default it is restored, and said so",
        )
        p.set_defaults(handler=cmd_ui)


def port_arg(text: str) -> int:
    """An argparse ``type`` for a TCP port 0-65535."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if not 0 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"must be 0-65535 (0: any free port), got {value}")
    return value


def cmd_schema(args: argparse.Namespace) -> int:
    """Print a JSON Schema."""
    if args.measurements:
        from calib.plan.measurements import Measurements

        sys.stdout.write(json_schema(Measurements))
    else:
        from calib.plan.file import Plan

        sys.stdout.write(json_schema(Plan))
    return 0


def cmd_ui(args: argparse.Namespace) -> int:
    """Start the web UI (``webui.server.run``), imported only here."""
    write_plan = getattr(args, "write_plan", None)
    if write_plan:
        from planner.demo import stator_plan_text

        write_text_atomic(write_plan, stator_plan_text())
        stderr().print(f"wrote the built-in A-H plan to {write_plan}")
        return 0
    plan = getattr(args, "plan", None)
    if plan is not None:
        load_plan(plan)  # a clear error now, before a server starts

    from webui.server import run, serve  # the one place planner imports webui (viser), lazily

    app = run(plan, host=args.host, port=args.port, block=False, fresh=args.fresh)

    def announce() -> None:  # inside serve: a Ctrl-C as soon as the address shows stops the app
        bound = app.server.get_port()
        err = stderr()
        if args.port not in (0, bound):
            err.print(f"port {args.port} is busy: serving on {bound}", markup=False)
        err.print(
            f"wobjcal UI on http://{args.host}:{bound} "
            f"({plan or 'built-in demo ' + DEMO_PLAN.name}); Ctrl-C stops it",
            markup=False,
        )
        if app.state.autosave_path is not None:
            err.print(f"the session plan autosaves to {app.state.autosave_path}", markup=False)
        if app.autosave_note:
            err.print(app.autosave_note, markup=False)

    return serve(app, announce)  # 130 after Ctrl-C, 143 after SIGTERM (docs/cli.md)
