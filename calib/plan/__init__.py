"""The versioned files of wobjcal: the plan (``wobjcal.plan/1``) and the measurements.

Owns:
    - :mod:`calib.plan.file`: :class:`Plan` and its parts (:class:`PlanPoint`,
      :class:`Search`), strict loading (:func:`load_plan`, :func:`plan_from_json`), canonical
      saving (:func:`save_plan`, :func:`plan_to_json`), file references and their digests;
    - :mod:`calib.plan.cell`: the cell part (robot, tool, fixtures, work object, poses);
    - :mod:`calib.plan.models`: the validation settings (the physical models themselves are in
      :mod:`calib.models`, the procedure settings in :mod:`calib.procedures`);
    - :mod:`calib.plan.json_io`: strict JSON decoding with errors naming the JSON path, and the
      generated JSON Schemas (``assets/schema/``);
    - :mod:`calib.plan.measurements`: the measured-points file (``wobjcal.measurements/1``);
    - :mod:`calib.plan.base`: built-in references, mesh units, sha256 checks;
    - :mod:`calib.plan.bundle`: a plan with its files as one ZIP archive (:func:`plan_bundle`)
      and which fields hold file references (:func:`file_refs`, :func:`rebased_plan`);
      imported from there, not from ``calib.plan``.

Pure: msgspec and numpy, no simulator. Public names are importable from ``calib.plan``.
"""

from calib.plan.file import (
    BUILTIN_PREFIX,
    PLAN_SCHEMA,
    SUPPORTED_PLAN_SCHEMAS,
    CellSpec,
    FixtureSpec,
    Plan,
    PlanError,
    PlanPoint,
    Pose,
    RobotSpec,
    Search,
    ToolSpec,
    ValidationSpec,
    ViaPoint,
    WorkObjectSpec,
    check_plan_files,
    file_sha256,
    load_plan,
    plan_from_json,
    plan_to_json,
    resolve_ref,
    save_plan,
)

__all__ = [
    "BUILTIN_PREFIX",
    "PLAN_SCHEMA",
    "SUPPORTED_PLAN_SCHEMAS",
    "CellSpec",
    "FixtureSpec",
    "Plan",
    "PlanError",
    "PlanPoint",
    "Pose",
    "RobotSpec",
    "Search",
    "ToolSpec",
    "ValidationSpec",
    "ViaPoint",
    "WorkObjectSpec",
    "check_plan_files",
    "file_sha256",
    "load_plan",
    "plan_from_json",
    "plan_to_json",
    "resolve_ref",
    "save_plan",
]
