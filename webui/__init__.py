"""The wobjcal web UI (viser): a thin layer that turns browser events into planner/calib calls.

Owns the app (:mod:`webui.app`), starting it (:mod:`webui.server`, ``run()``, ``serve()``),
the autosave files and their lock (:mod:`webui.autosave`), uploads refused by their declared
size (:mod:`webui.upload_guard`), the interface its panels see
(:mod:`webui.context`), the panels (points, files, validation, calibration, heat map) on
one base with one error rule (:mod:`webui.panel`, :mod:`webui.guard`), the
scene and robot drawing, click-to-place (:mod:`webui.surface`), the edited plan with undo/redo
and autosave (:mod:`webui.plan_doc`, :mod:`webui.state`, :mod:`webui.plan_adapter`), and the
one worker thread that owns the cell (:mod:`webui.worker`, :mod:`webui.backend`). Checks,
validation, exports and calibration are the planner's own jobs (:mod:`planner.check`,
:mod:`planner.validate`, ...).
``docs/webui.md`` has the details.
"""
