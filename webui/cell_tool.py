"""The Cell tab's **Tool** folder: choose the tool (a built-in, or one uploaded as a URDF, a zip
of a URDF with its meshes, or a mesh with its TCP) and the TCP it probes with.

**Tool** lists the built-in tools and every tool of this session's plans (undo history
included); picking one lists its TCPs under **TCP**; **Apply tool** makes both the plan's
(one undoable step: the new cell is built first, then every point is checked again). An upload
is applied at once. A mesh tool is one body (its convex hull) with one TCP, ``sensor``, at the
position (mm) and z-y'-x'' angles (deg) in the flange frame given in the fields; the UI writes
its tool description JSON (:func:`planner.cell.scene.mesh_tool_description`) beside the mesh in
the upload cache, named by its own digest, so an earlier plan's description never changes.
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path
from typing import TYPE_CHECKING

from calib.atomic_io import write_text_atomic
from calib.errors import InputError
from calib.plan.base import resolve_ref
from calib.plan.file import Plan
from calib.units import MESH_UNITS
from planner.builtins import BUILTIN_TOOLS, PREFIX, is_builtin
from planner.cell.scene import Tool, load_tool, mesh_tool_description
from webui.cell_edits import pose_from_fields
from webui.cell_setup_edits import tcp_choice, with_tool
from webui.cell_uploads import CellUploads
from webui.files_panel import check_upload
from webui.tab_selection import set_options
from webui.urdf_zip import unpack_robot_zip

if TYPE_CHECKING:
    from webui.context import AppContext
    from webui.panel import Guard

#: What the tool upload takes: a URDF, a zip of a URDF with its meshes, or a mesh.
TOOL_SUFFIXES = (".urdf", ".zip", ".stl", ".obj", ".ply", ".off", ".glb", ".gltf")
#: The TCP of a mesh tool (the sensor at its sensing distance).
MESH_TCP = "sensor"


def tool_label(ref: str) -> str:
    """How the Tool dropdown shows a tool reference: a built-in as is, a file by its name."""
    return ref if is_builtin(ref) else f"file: {Path(ref).name}"


class ToolSection:
    """The Tool folder of the Cell tab (shared by all tabs).

    Args:
        app: the app whose plan's tool is edited.
        guard: the Cell panel's :meth:`webui.panel.Panel.guard`: runs an edit, a refusal told
            to the tab that acted.
    """

    def __init__(self, app: AppContext, guard: Guard) -> None:
        self._app = app
        self._uploads = CellUploads(app)
        self._refs: dict[str, str] = {}  # dropdown label -> tool reference
        self._tools: dict[str, Tool] = {}  # tool reference -> loaded tool (for its TCPs)
        self._shown: tuple[str, str] | None = None  # the plan's (tool, tcp) the fields show
        gui = app.server.gui
        with gui.add_folder("Tool"):
            self.summary = gui.add_markdown("")
            self.tool = gui.add_dropdown("Tool", ("builtin:cable_feeder",))
            self.tcp = gui.add_dropdown("TCP", ("sensor",), hint="the TCP that probes")
            self.apply = gui.add_button("Apply tool")
            gui.add_markdown(
                "Upload a tool: a URDF, a zip of a URDF with its meshes, or a mesh (STL, OBJ, "
                "PLY, OFF, GLB) with its sensor TCP in the flange frame:"
            )
            self.mesh_tcp = gui.add_vector3("Mesh tool TCP (mm)", (0.0, 0.0, 150.0), step=1.0)
            self.mesh_rot = gui.add_vector3(
                "Mesh tool TCP rot z-y'-x'' (deg)", (0.0, 0.0, 0.0), step=1.0
            )
            self.mesh_units = gui.add_dropdown("Tool mesh units", MESH_UNITS, initial_value="mm")
            self.upload = gui.add_upload_button(
                "Upload tool", mime_type=",".join(TOOL_SUFFIXES), hint=", ".join(TOOL_SUFFIXES)
            )
        self.tool.on_update(lambda ev: guard(ev, self._list_tcps))
        self.apply.on_click(lambda ev: guard(ev, self.apply_tool))
        self.upload.on_upload(
            lambda ev: guard(ev, self.upload_tool, ev.target.value.name, ev.target.value.content)
        )

    # ---- showing ---------------------------------------------------------------------------
    def tool_of(self, ref: str) -> Tool:
        """The tool ``ref`` of a plan (cached; see :meth:`_load`)."""
        return self._load(ref)

    def _load(self, ref: str) -> Tool:
        """The tool ``ref`` (cached), its files resolved against the plan's folder."""
        if ref not in self._tools:
            path = ref if is_builtin(ref) else resolve_ref(ref, self._app.plan_dir)
            self._tools[ref] = load_tool(path)
        return self._tools[ref]

    def refresh(self, plan: Plan) -> None:
        """Show the plan's tool and TCP (only when they changed: a choice not yet applied stays
        while points are edited)."""
        spec = plan.cell.tool
        refs = [PREFIX + name for name in sorted(BUILTIN_TOOLS)]
        for d in self._app.state.docs():
            if isinstance(d.source, Plan) and d.source.cell.tool.name not in refs:
                refs.append(d.source.cell.tool.name)
        if spec.name not in refs:
            refs.append(spec.name)
        self._refs = {}
        for r in refs:  # two uploads of one file name: numbered
            label, k = tool_label(r), 2
            while label in self._refs:
                label, k = f"{tool_label(r)} ({k})", k + 1
            self._refs[label] = r
        set_options(self.tool, tuple(self._refs))
        if self._shown == (spec.name, spec.tcp):
            return
        self._shown = (spec.name, spec.tcp)
        self.tool.value = next(k for k, r in self._refs.items() if r == spec.name)
        try:
            tool = self._load(spec.name)
            tcps = tuple(tool.tcp_names)
            mesh = "a mesh, checked as its convex hull" if tool.urdf_path is None else "a URDF"
            self.summary.content = (
                f"**Tool:** {tool.name} ({mesh}), probing with TCP **{spec.tcp}**; "
                f"TCPs: {', '.join(tcps)}"
            )
        except InputError as exc:  # not an action of a tab: the summary says why, for every tab
            tcps = (spec.tcp,)
            self.summary.content = f"**Tool:** {tool_label(spec.name)}: {exc}"
        set_options(self.tcp, tcps)
        self.tcp.value = spec.tcp if spec.tcp in tcps else tcps[0]

    def _list_tcps(self) -> None:
        """List the TCPs of the tool chosen in the dropdown (nothing applied yet)."""
        ref = self._refs.get(str(self.tool.value))
        if ref is None:
            return
        tool = self._load(ref)
        source = self._app.state.doc.source
        current = source.cell.tool.tcp if isinstance(source, Plan) else MESH_TCP
        set_options(self.tcp, tuple(tool.tcp_names))
        self.tcp.value = tcp_choice(tool, current)

    # ---- edits -----------------------------------------------------------------------------
    def _plan(self) -> Plan:
        source = self._app.state.doc.source
        if not isinstance(source, Plan):
            raise InputError("load a plan first: there is no cell to set up")
        return source

    def apply_tool(self) -> None:
        """Make the chosen tool and TCP the plan's (one undoable step; nothing when they are)."""
        source = self._plan()
        label = str(self.tool.value)
        ref = self._refs.get(label)
        if ref is None:
            raise InputError(f"no tool {label!r}; choose one of {list(self._refs)}")
        tool = self._load(ref)
        tcp = str(self.tcp.value)
        if tcp not in tool.tcp_names:
            raise InputError(f"tool {tool.name!r} has no TCP {tcp!r}; its TCPs: {tool.tcp_names}")
        if (source.cell.tool.name, source.cell.tool.tcp) == (ref, tcp):
            return
        self._app.replace_source(with_tool(source, ref, tcp), f"tool {tool.name}")

    def upload_tool(self, name: str, content: bytes) -> str:
        """Use an uploaded tool at once (one undoable step): a URDF, a zip of a URDF with its
        meshes, or a mesh with the TCP of the fields. Returns the path of what the plan names.

        Raises:
            UploadError: the file is refused (the message names it, not the upload cache).
        """
        source = self._plan()
        lower = name.lower()
        kept: Path | None = None
        ref: Path
        try:
            if lower.endswith(".zip"):
                check_upload(name, content, TOOL_SUFFIXES, "tool")
                kept = self._uploads.folder(content)
                try:
                    ref = unpack_robot_zip(name, content, kept / "tool")
                except InputError as exc:  # its messages speak of a robot, and of the zip
                    raise InputError(f"{name} (a tool zip): {exc}") from None
            elif lower.endswith(".urdf"):
                kept, _ = self._uploads.keep(name, content, TOOL_SUFFIXES, "tool")
                ref = kept
            else:
                kept, _ = self._uploads.keep(name, content, TOOL_SUFFIXES, "tool")
                ref = self._describe_mesh(kept)
            tool = load_tool(ref)
            self._tools[str(ref)] = tool
            plan = with_tool(source, str(ref), tcp_choice(tool, source.cell.tool.tcp))
            self._app.replace_source(plan, f"new tool {name}")
        except Exception as exc:
            raise self._uploads.refused(exc, kept, name) from None
        return str(ref)

    def _describe_mesh(self, mesh: Path) -> Path:
        """Write the description of a mesh tool (TCP of the fields) beside ``mesh``; return it."""
        T = pose_from_fields(self.mesh_tcp.value, self.mesh_rot.value)
        name = re.sub(r"[^A-Za-z0-9_]", "_", mesh.stem)[:40] or "tool"
        text = mesh_tool_description(
            mesh.name,
            {MESH_TCP: T},
            units=str(self.mesh_units.value),
            sensor_tcp=MESH_TCP,
            name=name,
            sensor_links=(name,),  # one body: it is the sensor, and may come to the part
        )
        digest = hashlib.sha256(text.encode("utf-8")).hexdigest()[:8]
        return write_text_atomic(mesh.parent / f"{mesh.stem}-{digest}.tool.json", text)
