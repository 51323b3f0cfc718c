"""The "Files" panel: upload a plan, a work-object mesh or a robot URDF; download plan and programs.

Uploads are size-limited and validated before anything changes: a new cell is built from the
upload first, and only when that works does the session plan change (one undoable step).
A bad upload shows a notification naming the problem and leaves everything as it was.
"""

from __future__ import annotations

import hashlib
import logging
from pathlib import Path
from typing import TYPE_CHECKING, Any

import msgspec

from calib.errors import InputError
from calib.plan.file import Plan, PlanError
from calib.units import MESH_UNITS
from webui.exports import FORMATS, ExportResult, export_program
from webui.plan_adapter import plan_from_ui, plan_json_from_ui, ui_plan_from_bytes, with_source
from webui.state import atomic_write_bytes

if TYPE_CHECKING:
    from webui.context import AppContext

logger = logging.getLogger(__name__)

#: Largest accepted upload, bytes.
MAX_UPLOAD_BYTES = 50 * 1024 * 1024
MESH_SUFFIXES = (".stl", ".obj", ".ply", ".off", ".glb", ".gltf")
UPLOAD_DIR = Path.home() / ".cache" / "wobjcal" / "uploads"


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


class FilesPanel:
    """GUI widgets for uploads and downloads.

    Args:
        app: the app whose plan the files belong to.
        upload_dir: where uploaded meshes and URDFs are kept (they must outlive the request).
    """

    def __init__(self, app: AppContext, upload_dir: Path = UPLOAD_DIR) -> None:
        self._app = app
        self.upload_dir = upload_dir
        gui = app.server.gui
        with app.tab("Files"):
            self.plan_upload = gui.add_upload_button("Upload plan (.json)", mime_type=".json")
            self.units = gui.add_dropdown("Mesh units", MESH_UNITS, initial_value="mm")
            self.mesh_upload = gui.add_upload_button("Upload work-object mesh")
            self.urdf_upload = gui.add_upload_button("Upload robot URDF", mime_type=".urdf")
            self.download = gui.add_button("Download plan JSON")
            self.export_buttons = {fmt: gui.add_button(f"Download {fmt}") for fmt in FORMATS}
        self.plan_upload.on_upload(lambda ev: self._guard(ev, self.upload_plan))
        self.mesh_upload.on_upload(lambda ev: self._guard(ev, self.upload_mesh))
        self.urdf_upload.on_upload(lambda ev: self._guard(ev, self.upload_urdf))
        self.download.on_click(
            lambda ev: self._guard(ev, self.download_plan, ev.client, failure="Not downloaded")
        )
        for fmt, button in self.export_buttons.items():
            button.on_click(self._export_callback(fmt))

    def _export_callback(self, fmt: str) -> Any:
        def callback(event: Any) -> None:
            self._guard(event, self.download_export, event.client, fmt, failure="Not exported")

        return callback

    def _guard(self, event: Any, fn: Any, *args: Any, failure: str = "File not used") -> None:
        """Run ``fn`` (an upload with the event's file when no ``args``); a refusal shows as an
        error notification titled ``failure`` that stays until closed."""
        client = getattr(event, "client", None)
        if not args:
            args = (event.target.value.name, event.target.value.content)
        try:
            with self._app.busy(f"{fn.__name__.replace('_', ' ')}"):
                title = fn(*args)
        except InputError as exc:
            self._app.notify(failure, str(exc), client=client)
        except Exception as exc:  # never a traceback in the browser
            logger.exception("file action failed")
            self._app.notify(failure, f"{type(exc).__name__}: {exc}", client=client)
        else:
            if title:
                self._app.notify(title, "", client=client, error=False)

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
        path = self.upload_dir / digest[:16] / Path(name).name
        atomic_write_bytes(path, content)
        return path, digest

    def _apply_source(
        self, plan: Plan, label: str, kept: Path | None = None, name: str = ""
    ) -> None:
        """Load the cell of ``plan`` and make it the session's (one undoable step); an error
        names the user's file ``name``, not where the upload is ``kept``."""
        try:
            self._app.load_cell(plan, self._app.plan_dir)
        except Exception as exc:
            text = str(exc) if isinstance(exc, InputError) else f"{type(exc).__name__}: {exc}"
            if kept is not None:
                text = text.replace(str(kept), name).replace(str(kept.parent), "uploads")
            raise UploadError(text if name in text else f"{name}: {text}") from None
        self._app.state.update(lambda d: with_source(d, plan), label)

    def upload_mesh(self, name: str, content: bytes) -> str:
        """Use an uploaded mesh (in the chosen units) as the work object."""
        check_upload(name, content, MESH_SUFFIXES, "mesh")
        source = self._current_plan()
        path, digest = self._keep(name, content)
        work_object = msgspec.structs.replace(
            source.work_object, mesh=str(path), units=str(self.units.value), sha256=digest
        )
        self._apply_source(
            msgspec.structs.replace(source, work_object=work_object), "new mesh", path, name
        )
        return f"Work object {name} loaded"

    def upload_urdf(self, name: str, content: bytes) -> str:
        """Use an uploaded URDF (primitive or absolute-path meshes) as the robot."""
        check_upload(name, content, (".urdf",), "robot description")
        source = self._current_plan()
        path, _ = self._keep(name, content)
        robot = msgspec.structs.replace(source.cell.robot, urdf=str(path))
        cell = msgspec.structs.replace(source.cell, robot=robot)
        self._apply_source(msgspec.structs.replace(source, cell=cell), "new robot", path, name)
        return f"Robot {name} loaded"

    def _current_plan(self) -> Plan:
        source = self._app.state.doc.source
        if not isinstance(source, Plan):
            raise PlanError("load a plan first: a mesh or robot belongs to a plan's cell")
        return source

    # ---- downloads -------------------------------------------------------------------------
    def plan_bytes(self) -> tuple[str, bytes]:
        """File name and canonical JSON of the session plan (raises when it is incomplete)."""
        doc = self._app.state.doc
        return f"{doc.name or 'plan'}.json", plan_json_from_ui(doc).encode("utf-8")

    def download_plan(self, client: Any) -> None:
        """Send the session plan JSON to ``client``."""
        name, data = self.plan_bytes()
        client.send_file_download(name, data, save_immediately=True)

    def export(self, fmt: str) -> ExportResult:
        """The session plan as robot program(s) in ``fmt``, made on the cell worker."""
        plan = plan_from_ui(self._app.state.doc)
        plan_dir = self._app.plan_dir
        return self._app.worker.call(
            lambda s: export_program(plan, fmt, plan_dir, None if s is None else s.cell)
        )

    def download_export(self, client: Any, fmt: str) -> str:
        """Send the session plan as robot program(s) in ``fmt`` to ``client``."""
        result = self.export(fmt)
        for name, data in result.files:
            client.send_file_download(name, data, save_immediately=True)
        if result.note:
            self._app.notify(f"{fmt} exported with a note", result.note, client=client)
        return ""
