"""What a plan's validation and its prediction share: the setup of the measuring program, its
models and nominal pose (:func:`prediction_setup`), and with the part's faces and the x-offset
run's targets, what every trial shares (:func:`simulation_setup`).

In :mod:`planner.check`, below the validation that also uses it: ``wobjcal check`` predicts the
layout's quality and landing risk from :func:`prediction_setup`, ``wobjcal validate`` simulates
from :func:`simulation_setup` (after checking the plan); this module imports neither job.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import trimesh

from calib.plan.file import Plan, PlanError
from calib.procedures import RolePoint
from planner.check.simulatable import ValidationModels
from planner.plan_cell import nominal_T_base_wobj
from planner.program.build import build_program, safety_spec
from planner.program.controllers import controller
from planner.sim.setup import SimulationSetup, default_pivot, face_lookup
from planner.sim.xoffset import xoffset_setup

__all__ = ["prediction_setup", "simulation_setup"]


def simulation_setup(
    plan: Plan, models: ValidationModels, mesh: trimesh.Trimesh, fmt: str | None = None
) -> SimulationSetup:
    """What every trial of ``plan`` shares (the part ``mesh`` in wobj, metres) for the program
    of the controller ``fmt`` (``None``: the default), with the x-offset run's targets on the
    stator's bulged slot holes when the plan has one."""
    from planner.cell import disk_cache  # the faces' footprint test, kept across commands

    xo = getattr(models.settings, "xoffset", None)
    xs = None
    if xo is not None and models.geometry is not None:
        g = models.geometry
        grid = xo.grid
        y, z = np.meshgrid(grid.slot_y_m, grid.layer_z_m, indexing="xy")  # (layers, slots)
        if not np.all(g.hole_near(y, z)):
            raise PlanError(
                "procedure.xoffset: the slot grid does not lie on the stator's slot holes"
            )
        # the true hole of each target: at its y and z, pushed out by the bolts' bulge
        xs = xoffset_setup(xo, np.stack([g.side_face_offset_m(y, z), y, z], axis=-1))
    px = tuple(RolePoint("xoffset", p) for row in (xs.points if xs else ()) for p in row)
    return dataclasses.replace(
        prediction_setup(plan, models, fmt),
        faces=face_lookup(
            mesh, models.points + px, models.sensor.footprint_radius_m, cache=disk_cache
        ),
        xoffset=xs,
    )


def prediction_setup(
    plan: Plan, models: ValidationModels, fmt: str | None = None
) -> SimulationSetup:
    """What the prediction of ``plan`` needs (:func:`planner.sim.predict.predict`, the layout
    quality): its points, procedure, nominal pose, models and the measuring program of the
    controller ``fmt`` (``None``: the default); no part faces, no x-offset run.

    Raises:
        InputError: unknown controller.
    """
    vias = {p.id: len(p.via_points) for p in plan.points}
    safety = safety_spec(plan)
    program = build_program(models.points, models.settings, safety, controller(fmt), vias)
    return SimulationSetup(
        program=program,
        T_base_wobj_nominal=nominal_T_base_wobj(plan),
        sensor=models.sensor,
        robot_error=models.robot_error,
        misplacement=models.misplacement,
        pivot_wobj_m=default_pivot(list(models.points)),
        edge_inset_m=models.edge_inset_m,
    )
