"""A numba kernel with one fixed signature, compiled on first use instead of at import.

``@nb.njit("float64(int64, ...)")`` gives a kernel one compiled version shared by all its
callers: a call with constant arguments (``f(W, 0, x)``) converts them to the signature's
types, where a kernel without a signature would compile a literal-typed copy per constant
(seconds each). But numba compiles a signature-given kernel when the module is imported:
every process that imports the broad phase paid ~3.3 s for the helpers of
:mod:`~planner.cell.kernels.gjk_kernels` and :mod:`~planner.cell.kernels.bound_kernels` before its
first line ran, and the background compile (:mod:`planner.cell.kernels.warmup`) paid the same again
at the same time, so neither could load what the other compiled.

:func:`lazy_njit` keeps the one-signature rule and moves the compile to the first use (a
caller being typed or a call from Python): then numba looks in its cache first, so a kernel
the helper process compiled is loaded (~10 ms), not compiled again. After that first compile
the kernel takes no new signature, exactly like an eager one: constants convert, and a call
whose types do not convert is a typing error, not a silent new copy.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numba as nb
from numba.core import sigutils
from numba.core.compiler_lock import global_compiler_lock


def lazy_njit(signature: str, **options: Any) -> Callable[[Callable[..., Any]], Any]:
    """``@nb.njit(signature, cache=True, **options)``, compiled on first use (module docstring).

    Args:
        signature: numba's signature string with the return type, e.g.
            ``"float64(float64[:, ::1], int64)"``.
        **options: further ``nb.njit`` options (``cache=True`` is always set).

    Returns:
        A decorator giving a numba dispatcher.
    """
    args, ret = sigutils.normalize_signature(signature)
    fixed = ret(*args) if ret is not None else tuple(args)

    def decorate(fn: Callable[..., Any]) -> Any:
        disp = nb.njit(cache=True, **options)(fn)
        compile_any = disp.compile

        def compile_fixed(_requested: object) -> Any:
            """Whatever was asked for (numba asks with the caller's types, literals
            included), compile the fixed signature, then take no other."""
            with global_compiler_lock:  # re-entrant: numba's compile takes it too
                if not disp._can_compile:
                    return disp.overloads[tuple(args)].entry_point
                entry = compile_any(fixed)
                disp.disable_compile()
                return entry

        def compile_for_args(*_args: Any, **_kws: Any) -> Any:
            """A first call from Python: compile, then hand numba back the dispatcher, which
            it calls with the arguments: matched as by an eager kernel (types that do not
            convert raise TypeError, never run the fixed version on the wrong memory)."""
            compile_fixed(None)
            return disp

        # numba calls ``self.compile`` when a caller is typed (get_call_template) and
        # ``self._compile_for_args`` on a call from Python it has no version for; instance
        # attributes win over both methods
        disp.compile = compile_fixed
        disp._compile_for_args = compile_for_args
        return disp

    return decorate
