"""What a validation's fork server (:mod:`planner.sim.pool`) loads once, before it forks
its workers: the trial and prediction code, and the compiled kernels a trial runs (numba and
the kernels' machine code): the float64 step of a ray cast
(:func:`planner.sim.hit_kernel.load_kernel`), which each worker otherwise loaded at its first
cast (about 0.4 s a worker), the touch probe's sweep (:mod:`planner.sim.sweep_kernel`) and the
steered updates' Gauss-Newton loop (:mod:`planner.program.update_kernel`).

numba's cache directory is left as a worker would find it (this imports nothing of the cell
package, which points it at wobjcal's); no ray is cast (Embree's threads must not exist in a
process that forks).
"""

from __future__ import annotations

from planner.program import update_kernel
from planner.sim import predict, sweep_kernel, trial
from planner.sim.hit_kernel import load_kernel

__all__ = ["predict", "trial"]

load_kernel()
sweep_kernel.load_kernel()
update_kernel.load_kernel()
