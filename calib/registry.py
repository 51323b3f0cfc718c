"""Looking a name up in a registry, with the one error every registry gives.

The registries (procedures, export formats, controllers, sensor simulators, built-in robots,
tools and parts) are plain mappings from a name to an entry; :func:`lookup` is how every caller
reads one, so an unknown name always reads ``unknown <what> '<name>'; known: a, b``, from the
plan field or command-line option that named it.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import TypeVar

from calib.errors import InputError

T = TypeVar("T")
E = TypeVar("E", bound=InputError)


def unknown_name(what: str, name: object, known: Iterable[str], error: type[E]) -> E:
    """The error for ``name`` missing from a registry of ``what`` whose names are ``known``."""
    names = ", ".join(sorted(known)) or "(none)"
    return error(f"unknown {what} {name!r}; known: {names}")


def lookup(
    registry: Mapping[str, T], name: str, what: str, error: type[InputError] = InputError
) -> T:
    """``registry[name]``, or :func:`unknown_name`'s ``error`` naming ``what`` and the names.

    Args:
        registry: the registry.
        name: the name asked for.
        what: what the registry holds, with the field or option that named it (e.g.
            ``"procedure (procedure.method)"``, ``"format (--format)"``).
        error: the :class:`~calib.errors.InputError` subclass to raise.
    """
    try:
        return registry[name]
    except (KeyError, TypeError):
        raise unknown_name(what, name, registry.keys(), error) from None
