"""The "Layout" panel: the layout's predicted quality, live, and the Suggest buttons.

After every edit of the points the plan's quality is predicted again
(:func:`planner.check.job.plan_quality`, what ``wobjcal check`` prints) on this panel's own thread,
the latest edit only (edits that arrive meanwhile are skipped): 1 sigma per degree of freedom,
noise gain, the weakest motion in words, the error at the points of interest, and which points'
gross errors calibrate could not detect with how many points to add
(:func:`redundancy_markdown`). Ticked, the
predicted error is painted on the part (:func:`planner.sim.quality.error_radius`, green small
to red large) and each point of interest carries a sphere of its predicted error (drawn 100
times larger). "Suggest layout" and "Add best point" run :func:`planner.suggest.suggest_plan`
in the cell's worker (it needs the cell) with a progress bar, for the procedure the user picks
(by default the plan's own: an A-H plan is refused with what to pick, never switched silently;
"Add best point" keeps a procedure whose layout grows, best fit or iterative best fit, and grows
a 3-2-1 or A-H plan into a best fit, saying so: :func:`suggest_procedure`)
and the objective (accuracy, or the least cycle time under the target). The suggestion is shown
beside the current layout (:func:`comparison_markdown`: points, predicted error, landing risk,
cycle time, what check refuses) and replaces the points (one undo step) only on "Accept
suggestion"; "Discard" or any edit of the plan drops it.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from concurrent.futures import Future
from typing import TYPE_CHECKING

import numpy as np

from calib.errors import InputError, PlanError
from calib.procedures import DESIGNED, GROWN, PROCEDURES
from planner.check.job import plan_detectability, plan_quality
from planner.sim.quality import DOF_NAMES, LayoutQuality, error_radius
from planner.suggest import DEFAULT_PROCEDURE
from webui.doc_memo import DocMemo
from webui.markdown_text import plain
from webui.panel import Panel
from webui.plan_adapter import plan_from_ui, ui_plan_from_plan
from webui.scene import heat_rgb
from webui.worker import CellWorker

if TYPE_CHECKING:
    from planner.check.results import PlanCheck
    from planner.suggest import SuggestResult
    from webui.backend import CellSession
    from webui.context import AppContext
    from webui.plan_doc import UiPlan

logger = logging.getLogger(__name__)

#: The spheres at the points of interest are drawn this many times their predicted error.
SPHERE_SCALE = 100.0
#: Scene node of the suggestion's points while it waits for accept (wobj frame).
SUGGESTED_NODE = "/wobj/suggested"


def quality_markdown(q: LayoutQuality | None, note: str = "") -> str:
    """The quality as Markdown (mm, deg)."""
    if q is None:
        return f"*Layout quality not predicted:* {note}" if note else ""
    if q.rating == "unobservable":
        return f"**Layout fails:** {q.problem}"
    head = {"ok": "**Layout: ok**", "weak": "**Layout: marginal**"}[q.rating]
    lines = [head + (f" ({q.problem})" if q.problem else ""), ""]
    sig = ", ".join(
        f"{n} {v * (1e3 if i < 3 else 57.29577951308232):.3f} {'mm' if i < 3 else 'deg'}"
        for i, (n, v) in enumerate(zip(DOF_NAMES, q.sigma, strict=True))
    )
    lines.append(f"1 sigma: {sig}  ")
    lines.append(f"noise gain {q.noise_gain:.2f}, condition {q.condition:.1f}  ")
    lines.append(f"weakest: {q.weakest_text}  ")
    for p in q.poi:
        hw = ", ".join(
            f"{h * 1e3:.3f} mm at {lv:g} %"
            for lv, h in zip(p.levels_percent, p.half_width_m, strict=True)
        )
        lines.append(f"{p.label}: {hw}  ")
    return "\n".join(lines)


#: The "Procedure" choices: the plan's own, or another the suggestion switches to (every
#: procedure whose registry entry has a layout design, by its label).
KEEP = "keep the plan's"
PROCEDURE_CHOICES = {KEEP: "", **{PROCEDURES[m].label: m for m in DESIGNED}}
OBJECTIVE_CHOICES = {"accuracy": "accuracy", "least cycle time": "time"}


def _labels(methods: tuple[str, ...]) -> str:
    """The procedures' labels for a message: ``"3-2-1, best fit or iterative best fit"``."""
    names = [PROCEDURES[m].label for m in methods]
    return names[0] if len(names) == 1 else f"{', '.join(names[:-1])} or {names[-1]}"


def suggest_procedure(picked: str, plan_method: str, add: int, objective: str) -> tuple[str, str]:
    """The procedure and the objective a suggestion is designed for.

    Args:
        picked: the procedure picked under "Suggested procedure" (``""``: keep the plan's).
        plan_method: the plan's own procedure.
        add: points to add ("Add best point"), 0 for a whole new layout.
        objective: ``"accuracy"`` or ``"time"`` (:data:`OBJECTIVE_CHOICES`).

    With ``add``, a procedure whose layout grows (:data:`calib.procedures.GROWN`: best fit,
    iterative best fit) is kept, and the objective is accuracy; a plan of one that takes
    exactly its own points (3-2-1, A-H), kept, becomes a best fit of all its points
    (:data:`planner.suggest.DEFAULT_PROCEDURE`; suggest's message says so).

    Raises:
        InputError: the procedure is one Suggest cannot design (A-H), one that cannot grow
            picked for "Add best point", or the least cycle time asked of one that does not
            grow; the message says what to pick.
    """
    procedure = picked or plan_method
    if add:
        if procedure in GROWN:
            return procedure, "accuracy"
        if picked:  # picked on purpose: not switched silently
            raise InputError(
                f"Add best point grows a layout point by point, which {PROCEDURES[picked].label} "
                f"cannot (it takes exactly its own points): pick {_labels(GROWN)} under "
                "Suggested procedure, or keep the plan's"
            )
        return DEFAULT_PROCEDURE, "accuracy"  # the plan of all the points, as suggest says
    if procedure not in DESIGNED:
        raise InputError(
            f"the plan's procedure is {plan_method}, whose points Suggest cannot design: pick "
            f"{_labels(DESIGNED)} under Suggested procedure to suggest one instead (the plan's "
            "points are replaced only when you accept)"
        )
    if objective == "time" and procedure not in GROWN:
        raise InputError(
            f"the least cycle time is designed for a layout that grows point by point "
            f"({_labels(GROWN)}): pick one of them under Suggested procedure, or accuracy "
            "under Objective"
        )
    return procedure, objective


def _layout_line(
    n: int, method: str, worst_m: float, level: float, check: PlanCheck | None
) -> list[str]:
    """One column of :func:`comparison_markdown`."""
    landing = "-"
    cycle = "-"
    verdict = "not checked"
    if check is not None:
        if check.landing is not None:
            landing = f"{check.landing.failed * 100:.1f} %"
        if check.cycle is not None:
            cycle = f"{check.cycle.total_s:.1f} s"
        bad = len(check.infeasible) + bool(check.layout) + bool(check.error)
        verdict = "passes" if not bad else f"refuses {bad}"
    err = f"{worst_m * 1e3:.3f} mm" if math.isfinite(worst_m) else "-"
    return [str(n), method, f"{err} at {level:g} %", landing, cycle, verdict]


def comparison_markdown(
    before_n: int,
    before_method: str,
    before_check: PlanCheck | None,
    res: SuggestResult,
) -> str:
    """The current layout and the suggestion side by side (Markdown): points, procedure,
    predicted error at the points of interest, landing risk (share of misplaced calibrations
    with a search gone wrong), cycle time, check."""
    level = res.confidence_percent
    q = before_check.quality if before_check is not None else None
    before_worst = q.worst_poi_m(level) if q is not None else math.nan
    a = _layout_line(before_n, before_method, before_worst, level, before_check)
    b = _layout_line(len(res.plan.points), res.plan.method, res.worst_m, level, res.check)
    rows = (
        "points",
        "procedure",
        "predicted error",
        "landing risk",
        "cycle time",
        "check",
    )
    lines = ["| | now | suggested |", "|---|---|---|"]
    lines += [f"| {r} | {x} | {y} |" for r, x, y in zip(rows, a, b, strict=True)]
    from planner.program.controllers import controller

    label = controller(None).label
    return f"**Suggestion (not applied)**, judged for the {label} program\n\n" + "\n".join(lines)


def redundancy_markdown(doc: UiPlan) -> str:
    """Which points' gross errors calibrate could not detect, and how many points to add
    (what ``wobjcal check`` says, :func:`planner.check.job.plan_detectability`), or ``""``."""
    try:
        d = plan_detectability(plan_from_ui(doc))
    except PlanError:
        return ""
    if d is None or d.ok:
        return ""
    how = f"*Add best point* {d.add} time(s), or `wobjcal suggest PLAN --add {d.add} -o OUT`"
    return "**Redundancy:** " + d.message(how=how).replace("|", "/")


class LayoutPanel(Panel):
    """Live layout quality and the Suggest buttons, shared by all tabs.

    Args:
        app: the app whose plan is rated.
    """

    TAB = "Layout"
    REFUSED = "Not suggested"
    ACTION = "suggest"

    def __init__(self, app: AppContext) -> None:
        super().__init__(app)
        self._worker: CellWorker[None] = CellWorker(None, name="wobjcal-layout")
        self._generation = 0
        self._lock = threading.Lock()
        self._suggesting = threading.Event()
        self.last: LayoutQuality | None = None
        self.last_note = ""
        self.last_seconds = 0.0
        #: the quality, its note and the panel's text of plans rated before on this part: an
        #: undo or redo back to one shows it again without rating it again
        self._memo: DocMemo[tuple[LayoutQuality | None, str, str]] = DocMemo()
        self._memo_view: object = None
        self._painted = False
        gui = app.server.gui
        with app.tab(self.TAB):
            self.quality_md = gui.add_markdown("")
            self.show_map = gui.add_checkbox("Show predicted error on part", False)
            self.target = gui.add_number("Target (mm)", 0.3, min=0.001, max=100.0, step=0.01)
            self.max_points = gui.add_number("Max points", 8, min=6, max=40, step=1)
            self.procedure = gui.add_dropdown(
                "Suggested procedure", tuple(PROCEDURE_CHOICES), initial_value=KEEP
            )
            self.objective = gui.add_dropdown(
                "Objective", tuple(OBJECTIVE_CHOICES), initial_value="accuracy"
            )
            self.suggest_button = gui.add_button("Suggest layout", color="blue")
            self.add_button = gui.add_button("Add best point")
            self.progress = gui.add_progress_bar(0.0, visible=False, animated=True)
            self.compare_md = gui.add_markdown("")
            self.accept_button = gui.add_button("Accept suggestion", color="green", visible=False)
            self.discard_button = gui.add_button("Discard suggestion", visible=False)
        #: the suggestion shown and not yet accepted, and its label for the undo step
        self.pending: SuggestResult | None = None
        self._pending_for: UiPlan | None = None
        self.suggest_button.on_click(lambda e: self.guard(e, self.suggest, 0))
        self.add_button.on_click(lambda e: self.guard(e, self.suggest, 1))
        self.accept_button.on_click(lambda e: self.guard(e, self.accept, title="Not applied"))
        self.discard_button.on_click(lambda _e: self.discard())
        self.show_map.on_update(lambda _e: self._paint())
        app.state.subscribe(self._on_change)

    # ---- live quality ----------------------------------------------------------------------
    def _on_change(self, change: object) -> None:
        """A suggestion made for the plan as it was goes; the app calls :meth:`refresh` once
        it has sent the edit's rows (``WobjcalApp._on_change``: the rating, on this panel's
        thread, does not slow them)."""
        if self.pending is not None and getattr(change, "label", "") != "suggest layout":
            self.discard()  # made for the plan as it was

    def refresh(self) -> Future[LayoutQuality | None]:
        """Predict the quality of the current points on the panel's thread (the latest edit
        wins: a job whose edit was overtaken returns at once)."""
        with self._lock:
            self._generation += 1
            gen = self._generation
        return self._worker.submit(self._job, gen)

    def _job(self, _res: None, gen: int) -> LayoutQuality | None:
        if gen != self._generation:
            return self.last
        t0 = time.perf_counter()
        doc = self._app.state.doc
        view = self._app.view
        if view is not self._memo_view:  # another part or cell: nothing rated before holds
            self._memo.clear()
            self._memo_view = view
        known = self._memo.get(doc)
        if known is None:
            q, note = self.compute(doc)
            text = "\n\n".join(
                t for t in (quality_markdown(q, note), redundancy_markdown(doc)) if t
            )
            known = (q, note, text)
            self._memo.put(doc, known)
        q, note, text = known
        self.last, self.last_note = q, note
        self.last_seconds = time.perf_counter() - t0
        if self.quality_md.content != text:
            self.quality_md.content = text
        self._paint()
        return q

    def compute(self, doc: UiPlan) -> tuple[LayoutQuality | None, str]:
        """The quality of ``doc``'s points, or why there is none."""
        view = self._app.view
        if view is None:
            return None, "no work object loaded"
        try:
            plan = plan_from_ui(doc)
        except PlanError as exc:
            return None, str(exc)
        return plan_quality(plan, view.wobj_mesh)

    def _paint(self) -> None:
        """The predicted error on the part and the spheres at the points of interest, or
        neither when the box is not ticked."""
        scene = self._app.server.scene
        view, q = self._app.view, self.last
        if not self.show_map.value or view is None or q is None or q.rating == "unobservable":
            if self._painted:  # leave another panel's colours alone
                self._app.scene.color_work_object(None, layer="quality")
                scene.remove_by_name("/wobj/poi")
                self._painted = False
            return
        self._painted = True
        level = q.poi[0].levels_percent[0] if q.poi else 95.5
        r = error_radius(np.asarray(view.wobj_mesh.vertices), q.covariance, level)
        lo, hi = float(r.min()), float(r.max())
        self._app.scene.color_work_object(
            heat_rgb(1.0 - (r - lo) / max(hi - lo, 1e-12)), layer="quality"
        )
        for i, p in enumerate(q.poi):
            scene.add_icosphere(
                f"/wobj/poi/{i}",
                radius=float(max(p.at(level) * SPHERE_SCALE, 1e-3)),
                color=(60, 110, 220),
                position=np.asarray(p.position_m, dtype=np.float64),
                opacity=0.5,
            )

    # ---- suggest ---------------------------------------------------------------------------
    def suggest(self, add: int = 0) -> Future[SuggestResult]:
        """Suggest a layout (``add``: keep the points, add this many) in the cell's worker,
        for the procedure and objective picked in the panel; the returned future completes once
        the suggestion is shown beside the current layout (:meth:`accept` applies it).

        Raises:
            InputError: a suggestion is already running, there is no plan, or the procedure
                and objective do not go together (:func:`suggest_procedure`: the plan's own
                procedure, the default, is one Suggest cannot design, A-H): pick another.
        """
        from planner.check.job import check_plan
        from planner.suggest import suggest_plan

        made_for = self._app.state.doc  # a suggestion is for this plan only
        plan = plan_from_ui(made_for)
        if self._suggesting.is_set():
            raise InputError("a suggestion is already running")
        procedure, objective = suggest_procedure(
            PROCEDURE_CHOICES.get(str(self.procedure.value), ""),
            plan.method,
            add,
            OBJECTIVE_CHOICES.get(str(self.objective.value), "accuracy"),
        )
        self.discard()
        self._suggesting.set()
        self.suggest_button.disabled = self.add_button.disabled = True
        self.progress.value, self.progress.visible = 0.0, True
        target = float(self.target.value) * 1e-3
        n_max = int(self.max_points.value)
        plan_dir = self._app.plan_dir
        stages = ("planar faces", "candidates", "feasibility", "design", "front", "prediction")

        def progress(stage: str, done: int, total: int) -> None:
            k = stages.index(stage) if stage in stages else 0
            self.progress.value = 100.0 * (k + done / max(total, 1)) / len(stages)

        def job(session: CellSession | None) -> tuple[PlanCheck | None, SuggestResult]:
            if session is None or session.cell is None:
                raise InputError("no cell is loaded")
            try:
                before = check_plan(plan, cell=session.cell) if plan.points else None
            except InputError:
                before = None  # the comparison says "not checked"
            try:
                res = suggest_plan(
                    plan,
                    plan_dir,
                    target_m=None if add else target,
                    max_points=n_max,
                    add=add,
                    progress=progress,
                    cell=session.cell,
                    procedure=procedure,
                    objective=objective,
                )
            except InputError as exc:  # said as the page's button, not the command's flag
                text = str(exc)
                if text.startswith("--add: "):
                    raise InputError("Add best point: " + text.removeprefix("--add: ")) from None
                raise
            return before, res

        n_before, method_before = len(plan.points), plan.method
        done: Future[SuggestResult] = Future()  # set once the suggestion is shown
        fut = self._app.worker.submit(job)
        fut.add_done_callback(lambda f: self._suggested(f, done, n_before, method_before, made_for))
        return done

    def _suggested(
        self,
        fut: Future[tuple[PlanCheck | None, SuggestResult]],
        done: Future[SuggestResult],
        n_before: int,
        method_before: str,
        made_for: UiPlan,
    ) -> None:
        self.progress.visible = False
        self.suggest_button.disabled = self.add_button.disabled = False
        self._suggesting.clear()  # before the future completes: its caller may suggest again
        # the run's outcome, failure included, is every tab's: the suggestion is shown to all
        try:
            before, res = fut.result()
        except Exception as exc:  # the message names the faces tried and why
            if not isinstance(exc, InputError):
                logger.exception("suggest failed")
            self._app.notify("No layout suggested", str(exc))
            done.set_exception(exc)
            return
        if self._app.state.doc is not made_for:  # edited while it ran: it would undo that
            why = "the plan changed while the suggestion ran: suggest again for the plan as it is"
            self._app.notify("Suggestion dropped", why)
            done.set_exception(InputError(why))
            return
        self.pending, self._pending_for = res, made_for
        self.compare_md.content = (
            comparison_markdown(n_before, method_before, before, res) + f"\n\n{plain(res.message)}"
        )
        self.accept_button.visible = self.discard_button.visible = True
        self._draw_pending(res)
        title = "Layout suggested: accept or discard it" if res.met else "Best layout found"
        self._app.notify(title, res.message, error=not res.met)
        done.set_result(res)

    def accept(self) -> None:
        """Replace the plan's points with the suggestion shown (one undo step).

        Raises:
            InputError: there is none (discarded, or the plan changed since).
        """
        res = self.pending
        if res is None:
            raise InputError("no suggestion to accept: suggest one first")
        if self._app.state.doc is not self._pending_for:
            self.discard()
            raise InputError("the plan changed since the suggestion was made: suggest again")
        doc = ui_plan_from_plan(res.plan, name=self._app.state.doc.name)
        self._app.state.apply(doc, "suggest layout")
        self.discard()

    def discard(self) -> None:
        """Drop the suggestion shown (nothing changes in the plan)."""
        self.pending = None
        self.compare_md.content = ""
        self.accept_button.visible = self.discard_button.visible = False
        self._app.server.scene.remove_by_name(SUGGESTED_NODE)

    def _draw_pending(self, res: SuggestResult) -> None:
        """The suggested points as translucent green spheres on the part, beside the plan's
        own markers (wobj frame)."""
        scene = self._app.server.scene
        scene.remove_by_name(SUGGESTED_NODE)
        r = max(float(res.plan.validation.sensor.footprint_radius_m), 0.003)
        for p in res.plan.points:
            scene.add_icosphere(
                f"{SUGGESTED_NODE}/{p.id}",
                radius=r,
                color=(40, 170, 80),
                position=np.asarray(p.position_m, dtype=np.float64),
                opacity=0.55,
            )

    def close(self) -> None:
        """Stop the panel's thread."""
        self._worker.close(timeout=1.0)
