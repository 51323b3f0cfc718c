"""The ``wobjcal`` command line: ``main(argv) -> int``.

Owns one module per command group: :mod:`~planner.cli.check`, :mod:`~planner.cli.validate`,
:mod:`~planner.cli.calibrate`, :mod:`~planner.cli.export`, :mod:`~planner.cli.misc` (``schema``,
``ui``, ``demo``), the parser and error handling in :mod:`~planner.cli.main`, and consoles and
JSON output in :mod:`~planner.cli.common`. Each command is thin: it reads the files, calls the
plan-level job (:func:`planner.check.job.check_plan`, :func:`planner.validate.job.validate_plan`,
:func:`planner.calibrate.job.calibrate_plan`, :func:`planner.export_plan.job.export_program`) and
prints. Exit codes: 0 ok, 1 a problem found, 2 bad input. ``docs/cli.md`` has every command.
"""

from planner.cli.main import main

__all__ = ["main"]
