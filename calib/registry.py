"""Registries: looking a name up, with the one error every registry gives, and loading a
plug-in an entry names.

The registries (procedures, export formats, controllers, sensor simulators, built-in robots,
tools and parts) are plain mappings from a name to an entry; :func:`lookup` is how every caller
reads one, so an unknown name always reads ``unknown <what> '<name>'; known: a, b``, from the
plan field or command-line option that named it.

An entry holds what is cheap to import (the procedures are objects of :mod:`calib`) and names
the rest by reference, ``"module:attribute"`` (a writer, a simulator class, a mesh factory),
imported when first used by :func:`load`: the one way every registry loads a plug-in, so
listing a registry imports none of them.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterable, Mapping
from typing import Any, TypeVar

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


def load(ref: str) -> Any:
    """The object a registry entry names by ``"module:attribute"`` (``attribute`` may be dotted,
    e.g. ``"planner.parts.stator:StatorGeometry.prototype"``), importing its module.

    Raises:
        ValueError: ``ref`` is not ``"module:attribute"``; ImportError, AttributeError: the
            module or attribute does not exist (a defect of the registry, not of user input).
    """
    module, sep, attribute = ref.partition(":")
    if not (module and sep and attribute):
        raise ValueError(f"a registry reference is 'module:attribute', got {ref!r}")
    obj: Any = importlib.import_module(module)
    for name in attribute.split("."):
        obj = getattr(obj, name)
    return obj
