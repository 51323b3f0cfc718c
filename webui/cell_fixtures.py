"""The Cell tab's **Fixtures** folder: add a box, a cylinder or a mesh, or delete a fixture.

**Shape** chooses what **Add fixture** adds: a box of **Box size (mm)** (edges along the world
axes) or a cylinder of **Cylinder radius, length (mm)** (about the world's z axis), centred at
**Fixture position (mm)** (world); **Upload fixture mesh** adds a mesh (in **Fixture mesh
units**, its file's frame at that position). **Fixture name** names it (left empty: the shape's
or the file's name, numbered when taken; a name in use is refused). **Delete fixture** removes
the fixture chosen under **Fixture**. Each change builds the new cell first, then is one
undoable, autosaved step, and every point is checked again; moving a fixture is the panel's
**Move** above.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from calib.errors import InputError
from calib.plan.file import Plan
from calib.units import MESH_UNITS
from webui.cell_edits import FIXTURE_PREFIX
from webui.cell_setup_edits import (
    FIXTURE_SHAPES,
    box_fixture,
    cylinder_fixture,
    fixture_names,
    free_fixture_name,
    mesh_fixture,
    with_fixture,
    without_fixture,
)
from webui.cell_uploads import CellUploads
from webui.files_panel import MESH_SUFFIXES
from webui.tab_selection import set_options

if TYPE_CHECKING:
    from calib.plan.cell import FixtureSpec
    from webui.context import AppContext
    from webui.panel import Guard

NO_FIXTURE = "(no fixture)"
#: A fixture mesh: any mesh the work object takes except CAD files (they carry bodies).
FIXTURE_MESH_SUFFIXES = tuple(
    s for s in MESH_SUFFIXES if s not in (".step", ".stp", ".iges", ".igs")
)


class FixturesSection:
    """The Fixtures folder of the Cell tab (shared by all tabs).

    Args:
        app: the app whose plan's fixtures are edited.
        guard: the Cell panel's :meth:`webui.panel.Panel.guard`: runs an edit, a refusal told
            to the tab that acted.
        on_added: called with the ``Move`` target of a fixture just added (the panel shows it).
    """

    def __init__(self, app: AppContext, guard: Guard, on_added: Any) -> None:
        self._app = app
        self._uploads = CellUploads(app)
        self._on_added = on_added
        gui = app.server.gui
        source = app.state.doc.source
        at = (0.0, 0.0, 0.0)
        if isinstance(source, Plan):  # new fixtures start at the part
            p = np.round(np.asarray(source.work_object.T_world_wobj.position_m) * 1000.0, 3)
            at = (float(p[0]), float(p[1]), float(p[2]))
        with gui.add_folder("Fixtures"):
            self.chosen = gui.add_dropdown("Fixture", (NO_FIXTURE,))
            self.delete = gui.add_button("Delete fixture", color="red")
            self.shape = gui.add_dropdown("Shape", FIXTURE_SHAPES, initial_value="box")
            self.name = gui.add_text("Fixture name", "", hint="empty: the shape's name")
            self.position = gui.add_vector3("Fixture position (mm)", at, step=1.0)
            self.box_size = gui.add_vector3("Box size (mm)", (100.0, 100.0, 100.0), step=1.0)
            self.cylinder = gui.add_vector2(
                "Cylinder radius, length (mm)", (50.0, 200.0), step=1.0, visible=False
            )
            self.add = gui.add_button("Add fixture")
            self.units = gui.add_dropdown("Fixture mesh units", MESH_UNITS, initial_value="mm")
            # always shown: viser 1.1.1's page shows an upload button even when told to hide it
            self.upload = gui.add_upload_button(
                "Upload fixture mesh", mime_type=",".join(FIXTURE_MESH_SUFFIXES)
            )
        self.shape.on_update(lambda _ev: self._show_shape())
        self.delete.on_click(lambda ev: guard(ev, self.delete_fixture, str(self.chosen.value)))
        self.add.on_click(lambda ev: guard(ev, self.add_fixture))
        self.upload.on_upload(
            lambda ev: guard(ev, self.upload_fixture, ev.target.value.name, ev.target.value.content)
        )

    def _show_shape(self) -> None:
        shape = str(self.shape.value)
        self.box_size.visible = shape == "box"
        self.cylinder.visible = shape == "cylinder"

    def refresh(self, plan: Plan) -> None:
        """List the plan's fixtures."""
        set_options(self.chosen, fixture_names(plan) or (NO_FIXTURE,))

    # ---- edits -----------------------------------------------------------------------------
    def _plan(self) -> Plan:
        source = self._app.state.doc.source
        if not isinstance(source, Plan):
            raise InputError("load a plan first: there is no cell to set up")
        return source

    def _name(self, plan: Plan, shape: str) -> str:
        typed = str(self.name.value).strip()
        return typed or free_fixture_name(plan, shape)

    def _added(self, fixture: FixtureSpec) -> None:
        """After a fixture was added: choose it here and as the panel's Move target."""
        self.refresh(self._plan())
        self.chosen.value = fixture.name
        self.name.value = ""
        self._on_added(FIXTURE_PREFIX + fixture.name)

    def add_fixture(self) -> str:
        """Add the box or cylinder of the fields (one undoable step); returns its name."""
        plan = self._plan()
        shape = str(self.shape.value)
        position = self.position.value
        if shape == "box":
            fixture = box_fixture(plan, self._name(plan, shape), self.box_size.value, position)
        elif shape == "cylinder":
            r, h = self.cylinder.value
            fixture = cylinder_fixture(plan, self._name(plan, shape), r, h, position)
        else:
            raise InputError(f"shape: one of {', '.join(FIXTURE_SHAPES)}, got {shape!r}")
        self._app.replace_source(with_fixture(plan, fixture), f"add fixture {fixture.name}")
        self._added(fixture)
        return fixture.name

    def upload_fixture(self, name: str, content: bytes) -> str:
        """Add an uploaded mesh as a fixture (units and position of the fields; one undoable
        step); returns the fixture's name.

        Raises:
            UploadError: the file is refused (the message names it, not the upload cache).
        """
        plan = self._plan()
        kept: Path | None = None
        try:
            kept, digest = self._uploads.keep(name, content, FIXTURE_MESH_SUFFIXES, "mesh")
            stem = re.sub(r"[^A-Za-z0-9_]", "_", Path(name).stem)[:40] or "mesh"
            units = str(self.units.value)
            fixture = mesh_fixture(
                plan, self._name(plan, stem), str(kept), units, digest, self.position.value
            )
            self._app.replace_source(with_fixture(plan, fixture), f"add fixture {fixture.name}")
        except Exception as exc:
            raise self._uploads.refused(exc, kept, name) from None
        self._added(fixture)
        return fixture.name

    def delete_fixture(self, name: str) -> None:
        """Delete the fixture ``name`` (one undoable step)."""
        plan = self._plan()
        if name == NO_FIXTURE:
            raise InputError("the cell has no fixture to delete")
        self._app.replace_source(without_fixture(plan, name), f"delete fixture {name}")
