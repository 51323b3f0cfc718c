"""Functions a test runs on a validation's worker process (importable there by name)."""

from __future__ import annotations


def nothing() -> None:
    """A worker's initializer that does nothing."""


def kernel_state() -> str:
    """``"<kernel loaded before the first cast> <compiled signatures after it>"`` in this
    worker: ``"True 1"`` when the fork server loaded the kernel for the types a cast passes."""
    import numpy as np
    import trimesh

    from planner.sim import hit_kernel
    from planner.sim.raycast import MeshRayCaster

    loaded = bool(hit_kernel._COMPILED)
    caster = MeshRayCaster(trimesh.creation.box([1.0, 1.0, 1.0]))
    dist, _tri = caster.first_hits_ids(np.array([[0.0, 0.0, 2.0]]), np.array([[0.0, 0.0, -1.0]]))
    assert abs(float(dist[0]) - 1.5) < 1e-12
    return f"{loaded} {len(hit_kernel._COMPILED[0].signatures)}"
