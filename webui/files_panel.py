"""The "Files" panel: upload a plan, a work-object mesh or a robot URDF; download plan and programs.

Uploads are size-limited and validated before anything changes: a new cell is built from the
upload first, and only when that works does the session plan change (one undoable step).
A bad upload shows a notification naming the problem and leaves everything as it was.
"""

from __future__ import annotations

import hashlib
import logging
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec

from calib import limits
from calib.errors import InputError
from calib.plan.file import Plan, PlanError, plan_to_json
from calib.units import MESH_UNITS
from planner.export import export_file_stem
from webui import autosave, uploads
from webui.exports import FORMATS, ExportResult, export_program
from webui.markdown_text import plain
from webui.panel import Panel, client_of
from webui.part_upload import PendingPart, drop_points, frame_note, off_surface, project_points
from webui.plan_adapter import plan_from_ui, ui_plan_from_bytes, with_source
from webui.state import atomic_write_bytes
from webui.urdf_zip import unpack_robot_zip

if TYPE_CHECKING:
    from webui.context import AppContext
    from webui.plan_doc import UiPlan

logger = logging.getLogger(__name__)

#: Largest accepted upload, bytes (:mod:`calib.limits`).
MAX_UPLOAD_BYTES = limits.MAX_UPLOAD_BYTES
#: A part upload: a mesh trimesh reads, or a CAD file (planner.cad: STEP, IGES) in its own unit.
MESH_SUFFIXES = (".stl", ".obj", ".ply", ".off", ".glb", ".gltf", ".step", ".stp", ".iges", ".igs")
UPLOAD_DIR = Path.home() / ".cache" / "wobjcal" / "uploads"


def _file(event: Any) -> tuple[str, bytes]:
    """The uploaded file's name and bytes of an upload event."""
    return event.target.value.name, event.target.value.content


def _named(text: str, kept: Path | None, name: str) -> str:
    """``text`` about an upload kept at ``kept``, naming the user's file ``name`` instead."""
    if kept is not None:
        text = text.replace(str(kept), name).replace(str(kept.parent), "uploads")
    return text if name in text else f"{name}: {text}"


class UploadError(InputError):
    """An uploaded file is too large, of the wrong kind, or unusable; the message says why."""


def check_upload(name: str, content: bytes, suffixes: tuple[str, ...], what: str) -> None:
    """Refuse an empty, oversized or wrongly named upload with a message naming the file."""
    if len(content) > MAX_UPLOAD_BYTES:
        raise UploadError(
            f"{name}: {len(content) / 2**20:.1f} MiB is larger than the "
            f"{MAX_UPLOAD_BYTES / 2**20:.0f} MiB limit for uploads"
        )
    if not content:
        raise UploadError(f"{name}: the file is empty")
    if not name.lower().endswith(suffixes):
        raise UploadError(f"{name}: a {what} must end in {', '.join(suffixes)}")


class FilesPanel(Panel):
    """GUI widgets for uploads and downloads.

    Args:
        app: the app whose plan the files belong to.
        upload_dir: where uploaded meshes and URDFs are kept (they must outlive the request).
    """

    TAB = "Files"
    REFUSED = "File not used"
    ACTION = "file action"

    def __init__(self, app: AppContext, upload_dir: Path = UPLOAD_DIR) -> None:
        super().__init__(app)
        self.upload_dir = upload_dir
        #: the upload folders this session wrote (removed at the end unless its plan uses them)
        self.created: set[Path] = set()
        gui = app.server.gui
        with app.tab(self.TAB):
            self.plan_upload = gui.add_upload_button("Upload plan (.json)", mime_type=".json")
            self.mesh_upload = gui.add_upload_button("Upload work-object mesh")
            self.units = gui.add_dropdown("Mesh units", MESH_UNITS, initial_value="mm")
            self.keep_frame = gui.add_checkbox(
                "Keep work-object frame",
                False,
                hint="a new part keeps the earlier part's 3-point frame (T_wobj_mesh); "
                "unticked it starts with the file's own frame",
            )
            self.pending_md = gui.add_markdown("")
            self.accept = gui.add_button("Use this part", color="green", visible=False)
            self.cancel = gui.add_button("Cancel upload", visible=False)
            self.off_md = gui.add_markdown("")
            self.project_off = gui.add_button("Project them onto the part", visible=False)
            self.drop_off = gui.add_button("Drop them", color="red", visible=False)
            self.urdf_upload = gui.add_upload_button(
                "Upload robot URDF (.urdf, or .zip with meshes)", mime_type=".urdf,.zip"
            )
            self.download = gui.add_button("Download plan JSON")
            self.download_bundle = gui.add_button(
                "Download plan with its files (.zip)",
                hint="the plan and every file it refers to (part, robot and its packages, "
                "tool, fixture meshes), its references relative to the zip's folder",
            )
            self.export_buttons = {fmt: gui.add_button(f"Download {fmt}") for fmt in FORMATS}
            self.export_md = gui.add_markdown("")
            self.export_anyway = gui.add_button("Export anyway", color="red", visible=False)
        self.plan_upload.on_upload(lambda ev: self.guard(ev, self.upload_plan, *_file(ev)))
        self.mesh_upload.on_upload(lambda ev: self.guard(ev, self.stage_mesh, *_file(ev)))
        self.units.on_update(lambda ev: self.guard(ev, self._show_pending, title="Units"))
        self.accept.on_click(lambda ev: self.guard(ev, self.accept_mesh))
        self.cancel.on_click(lambda ev: self.guard(ev, self.cancel_mesh, title="Not done"))
        self.project_off.on_click(lambda ev: self.guard(ev, self.fix_off_surface, "project"))
        self.drop_off.on_click(lambda ev: self.guard(ev, self.fix_off_surface, "drop"))
        self.pending: PendingPart | None = None
        #: ``{point id: distance, m}`` of the points off the surface after the last new part.
        self.off: dict[str, float] = {}
        self.urdf_upload.on_upload(lambda ev: self.guard(ev, self.upload_urdf, *_file(ev)))
        self.download.on_click(
            lambda ev: self.guard(ev, self.download_plan, ev.client, title="Not downloaded")
        )
        self.download_bundle.on_click(
            lambda ev: self.guard(ev, self.download_zip, ev.client, title="Not downloaded")
        )
        for fmt, button in self.export_buttons.items():
            button.on_click(self._export_callback(fmt))
        #: the format whose program check refused, waiting for "Export anyway", and the plan
        #: the refusal shown is about
        self.refused_format: str | None = None
        self._refused_doc: UiPlan | None = None
        self.export_anyway.on_click(
            lambda ev: self.guard(ev, self.download_anyway, ev.client, title="Not exported")
        )
        app.state.subscribe(lambda change: self._clear_refusal())

    def _export_callback(self, fmt: str) -> Any:
        def callback(event: Any) -> None:
            self.guard(event, self.download_export, event.client, fmt, title="Not exported")

        return callback

    def guard(self, event: Any, fn: Callable[..., Any], *args: Any, **options: Any) -> Any:
        """:meth:`Panel.guard`, and more: the busy line names the file action while it runs
        (an upload or a bundle takes seconds), and the title ``fn`` returns, when not empty,
        is told to the tab as a note (what was done, e.g. a plan exported despite its check)."""
        with self._app.busy(f"{fn.__name__.replace('_', ' ')}"):
            title = super().guard(event, fn, *args, **options)
        if title:
            self._app.notify(title, "", client=client_of(event), error=False)
        return title

    # ---- uploads ---------------------------------------------------------------------------
    def upload_plan(self, name: str, content: bytes) -> str:
        """Replace the session plan with an uploaded plan file (one undoable step)."""
        check_upload(name, content, (".json",), "plan file")
        ui = ui_plan_from_bytes(content, source=name)
        if ui.source is None:  # ui_plan_from_bytes always keeps the loaded plan
            raise InputError(f"{name}: no plan in the file")
        self._app.load_cell(ui.source, self._app.plan_dir)
        self._app.state.apply(ui, f"load plan {name}")
        return f"Plan {name} loaded"

    def _keep(self, name: str, content: bytes) -> tuple[Path, str]:
        digest = hashlib.sha256(content).hexdigest()
        path = self._new_folder(digest, len(content)) / Path(name).name
        atomic_write_bytes(path, content)
        return path, digest

    # ---- the upload folders (webui.uploads) --------------------------------------------------
    def _new_folder(self, digest: str, size: int) -> Path:
        """The folder an upload is kept in; room is made for it first (issue 27)."""
        folder = self.upload_dir / digest[:16]
        if not folder.exists():
            uploads.check_room(self.upload_dir, size, self.in_use(), self._autosave_dir())
            self.created.add(folder)
        return folder

    def in_use(self) -> list[str]:
        """File references of the session's plans (undo history included) and of the mesh
        waiting for its units."""
        refs = [
            r
            for d in self._app.state.docs()
            if isinstance(d.source, Plan)
            for r in uploads.plan_refs(d.source)
        ]
        return refs + ([] if self.pending is None else [str(self.pending.path)])

    def _autosave_dir(self) -> Path | None:
        """The autosave folder beside the uploads (``None`` when it is elsewhere, as in tests:
        then only the folders this session wrote are ever removed)."""
        folder = autosave.AUTOSAVE_DIR
        return folder if folder.parent == self.upload_dir.parent else None

    def _discard(self, path: Path | None) -> None:
        """Remove the folder of an upload refused, cancelled or replaced, unless a plan uses it."""
        if path is None or not path.is_relative_to(self.upload_dir):
            return
        folder = self.upload_dir / path.relative_to(self.upload_dir).parts[0]
        if folder in self.created or self._autosave_dir() is not None:
            uploads.remove_unused(self.upload_dir, [folder], self.in_use(), self._autosave_dir())

    def prune_stale(self) -> list[Path]:
        """At start: remove the upload folders no plan and no autosave uses (older than
        :data:`webui.uploads.RECENT_S`)."""
        folder = self._autosave_dir()
        return [] if folder is None else uploads.prune(self.upload_dir, self.in_use(), folder)

    def close(self) -> None:
        """At the end: remove the upload folders this session wrote that its plan does not use
        (its undo history ends here; its autosave keeps what the plan uses)."""
        doc = self._app.state.doc
        refs = uploads.plan_refs(doc.source) if isinstance(doc.source, Plan) else []
        uploads.remove_unused(self.upload_dir, self.created, refs, self._autosave_dir())

    def _apply_source(
        self, plan: Plan, label: str, kept: Path | None = None, name: str = ""
    ) -> None:
        """Load the cell of ``plan`` and make it the session's (one undoable step); an error
        names the user's file ``name``, not where the upload is ``kept``."""
        try:
            self._app.load_cell(plan, self._app.plan_dir)
        except Exception as exc:
            text = str(exc) if isinstance(exc, InputError) else f"{type(exc).__name__}: {exc}"
            raise UploadError(_named(text, kept, name)) from None
        self._app.state.update(lambda d: with_source(d, plan), label)

    def stage_mesh(self, name: str, content: bytes) -> str:
        """Keep an uploaded mesh and show its size in the chosen units; nothing changes until
        :meth:`accept_mesh` (the **Use this part** button)."""
        check_upload(name, content, MESH_SUFFIXES, "mesh")
        self._current_plan()
        path, digest = self._keep(name, content)
        try:
            pending = PendingPart.read(name, path, digest)
        except InputError as exc:
            self._discard(path)
            raise UploadError(_named(str(exc), path, name)) from None
        before, self.pending = self.pending, pending
        self._discard(None if before is None else before.path)  # replaced
        self._show_pending()
        return ""

    def _show_pending(self) -> None:
        pending = self.pending
        if pending is None:
            self.pending_md.content = ""
            self.accept.visible = self.cancel.visible = False
            return
        text = pending.describe(str(self.units.value))
        self.pending_md.content = f"**New part:** {text}. Check the size, then use it."
        self.accept.visible = self.cancel.visible = True

    def cancel_mesh(self) -> str:
        """Forget the uploaded mesh waiting for its units (its file too, unless a plan uses it)."""
        before, self.pending = self.pending, None
        self._discard(None if before is None else before.path)
        self._show_pending()
        return ""

    def accept_mesh(self) -> str:
        """Use the waiting mesh, in the chosen units, as the work object (one undoable step);
        then list the points that are no longer on its surface."""
        pending = self.pending
        if pending is None:
            raise InputError("upload a mesh first: no part is waiting")
        source = self._current_plan()
        old_frame = source.work_object.mesh_pose
        keep = old_frame is not None and bool(self.keep_frame.value)
        work_object = msgspec.structs.replace(
            source.work_object,
            mesh=str(pending.path),
            units=pending.units or str(self.units.value),
            sha256=pending.digest,
            T_wobj_mesh=source.work_object.T_wobj_mesh if keep else msgspec.UNSET,
            body=msgspec.UNSET,  # a multi-body CAD upload is refused: the plan file chooses
        )
        plan = msgspec.structs.replace(source, work_object=work_object)
        self._apply_source(plan, "new mesh", pending.path, pending.name)
        self.pending = None
        self._show_pending()
        self._list_off_surface()
        return f"Work object {pending.name} loaded{frame_note(old_frame is not None, keep)}"

    def upload_mesh(self, name: str, content: bytes) -> str:
        """Use an uploaded mesh (in the chosen units) as the work object at once (scripts)."""
        self.stage_mesh(name, content)
        return self.accept_mesh()

    def refresh_off_surface(self, part_changed: bool) -> None:
        """After a change of the plan, once its cell is the one shown (the app calls it): the
        points off the part listed again when the part changed (an undo or redo of a new part)
        or when some were listed (another plan, an edit), so the list is always of the plan and
        the part shown, never of the one before."""
        if part_changed or self.off:
            self._list_off_surface()

    def _list_off_surface(self) -> None:
        view = self._app.view
        self.off = {} if view is None else off_surface(self._app.state.doc, view.wobj_mesh)
        if self.off:
            items = ", ".join(f"{pid} ({d * 1e3:.1f} mm)" for pid, d in self.off.items())
            self.off_md.content = f"**Points off the new part's surface:** {items}"
        else:
            self.off_md.content = ""
        self.project_off.visible = self.drop_off.visible = bool(self.off)

    def fix_off_surface(self, how: str) -> str:
        """Project (``"project"``) or drop (``"drop"``) the points listed as off the surface,
        in one undoable step."""
        ids = [pid for pid in self.off if pid in self._app.state.doc.ids]
        picker = self._app.picker
        if not ids or picker is None:
            raise InputError("no points are off the surface")
        if how == "project":
            self._app.state.update(lambda d: project_points(d, picker, ids), "project points")
        else:
            self._app.state.update(lambda d: drop_points(d, ids), "drop points")
        self._list_off_surface()
        return f"{len(ids)} point{'s' if len(ids) > 1 else ''} {how}ed"

    def upload_urdf(self, name: str, content: bytes) -> str:
        """Use an uploaded robot as the robot: a URDF (primitive or absolute-path meshes) or a
        zip of a URDF with its meshes (:func:`webui.urdf_zip.unpack_robot_zip`)."""
        check_upload(name, content, (".urdf", ".zip"), "robot description")
        source = self._current_plan()
        if name.lower().endswith(".zip"):
            folder = self._new_folder(hashlib.sha256(content).hexdigest(), len(content))
            try:
                path = unpack_robot_zip(name, content, folder / "robot")
            except BaseException:
                self._discard(folder)
                raise
            kept = path
        else:
            path, _ = self._keep(name, content)
            kept = path
        robot = msgspec.structs.replace(source.cell.robot, urdf=str(path))
        cell = msgspec.structs.replace(source.cell, robot=robot)
        try:
            self._apply_source(msgspec.structs.replace(source, cell=cell), "new robot", kept, name)
        except BaseException:
            self._discard(path)
            raise
        return f"Robot {name} loaded"

    def _current_plan(self) -> Plan:
        source = self._app.state.doc.source
        if not isinstance(source, Plan):
            raise PlanError("load a plan first: a mesh or robot belongs to a plan's cell")
        return source

    # ---- downloads -------------------------------------------------------------------------
    def plan_bytes(self) -> tuple[str, bytes]:
        """File name (after the plan's name, as the program downloads) and canonical JSON of
        the session plan (raises when it is incomplete)."""
        plan = plan_from_ui(self._app.state.doc)
        return f"{export_file_stem(plan.name, 'json')}.json", plan_to_json(plan).encode("utf-8")

    def download_plan(self, client: Any) -> None:
        """Send the session plan JSON to ``client``."""
        name, data = self.plan_bytes()
        client.send_file_download(name, data, save_immediately=True)

    def bundle_bytes(self) -> tuple[str, bytes]:
        """File name (after the plan's name) and the zip of the session plan with every file
        it refers to (:func:`calib.plan.bundle.plan_bundle`): unpacked anywhere, its plan
        loads and finds its part, robot, tool and fixtures, none in the server's upload cache."""
        from calib.plan.bundle import plan_bundle

        plan = plan_from_ui(self._app.state.doc)
        stem = export_file_stem(plan.name, "json")
        return f"{stem}.zip", plan_bundle(plan, self._app.plan_dir, stem)

    def download_zip(self, client: Any) -> None:
        """Send the session plan with its files as a zip to ``client``."""
        name, data = self.bundle_bytes()
        client.send_file_download(name, data, save_immediately=True)

    def export(self, fmt: str, doc: UiPlan | None = None) -> ExportResult:
        """The session plan (or ``doc``) as robot program(s) in ``fmt``, made on the cell
        worker."""
        plan = plan_from_ui(self._app.state.doc if doc is None else doc)
        plan_dir = self._app.plan_dir
        return self._app.worker.call(
            lambda s: export_program(plan, fmt, plan_dir, None if s is None else s.cell)
        )

    def download_export(self, client: Any, fmt: str, force: bool = False) -> str:
        """Send the session plan as robot program(s) in ``fmt`` to ``client`` when ``wobjcal
        check --format`` passes it; else show why in the panel, offer "Export anyway" and
        raise (nothing is sent). ``force``: send it all the same (its header says why check
        refuses it)."""
        doc = self._app.state.doc
        if force and self._refused_doc is not doc:
            self._clear_refusal()
            raise InputError(
                "the plan changed since check's reasons were shown: download it again to see "
                "what check says now"
            )
        result = self.export(fmt, doc)
        if result.refusals and not force:
            self.refused_format, self._refused_doc = fmt, doc
            self.export_md.content = (
                f"**{fmt} not downloaded**: `wobjcal check` refuses this plan for the {fmt} "
                "program:\n\n"
                + "\n".join(f"- {plain(r)}" for r in result.refusals)
                + "\n\n**Export anyway** downloads it with these reasons in its header."
            )
            self.export_anyway.visible = True
            n = len(result.refusals)
            raise InputError(
                f"wobjcal check refuses the plan for {fmt} ({n} problem{'s' if n > 1 else ''}, "
                f"listed in the Files tab): {result.refusals[0]}"
            )
        for name, data in result.files:
            client.send_file_download(name, data, save_immediately=True)
        self._clear_refusal()
        if result.note:
            self._app.notify(f"{fmt} exported with a note", result.note, client=client)
        if result.refusals:
            return f"{fmt} exported although check refuses it: its header says why"
        return ""

    def download_anyway(self, client: Any) -> str:
        """ "Export anyway": the program check refused last, sent with the reasons in its
        header."""
        fmt = self.refused_format
        if fmt is None:
            raise InputError("nothing to export anyway: download a program first")
        return self.download_export(client, fmt, force=True)

    def _clear_refusal(self) -> None:
        """Hide the last refusal (the plan changed, or a program was sent)."""
        if self.refused_format is None:
            return
        self.refused_format = self._refused_doc = None
        self.export_md.content = ""
        self.export_anyway.visible = False
