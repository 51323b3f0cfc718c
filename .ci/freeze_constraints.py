"""Print the installed versions of every package ``wobjcal[test]`` pulls in (transitively), as
pip constraints: the body of ``.ci/constraints.txt`` (its three comment lines are kept by hand).

Usage: ``python3 .ci/freeze_constraints.py`` in the environment the goldens were recorded in.
"""

from __future__ import annotations

import importlib.metadata as md

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name


def pinned(root: str = "wobjcal", extras: tuple[str, ...] = ("test",)) -> list[str]:
    """``["name==version", ...]`` of the installed requirements of ``root[extras]``, sorted."""
    seen: dict[str, tuple[str, str]] = {}
    todo: list[tuple[str, tuple[str, ...]]] = [(root, extras)]
    while todo:
        name, wanted = todo.pop()
        try:
            dist = md.distribution(name)
        except md.PackageNotFoundError:
            continue  # a requirement of another platform or Python
        key = canonicalize_name(dist.metadata["Name"])
        if key in seen and not wanted:
            continue
        seen[key] = (dist.metadata["Name"], dist.version)
        for text in dist.requires or []:
            req = Requirement(text)
            if req.marker is None or any(req.marker.evaluate({"extra": e}) for e in ("", *wanted)):
                todo.append((req.name, tuple(req.extras)))
    seen.pop(canonicalize_name(root), None)
    return sorted(f"{n}=={v}" for n, v in seen.values())


if __name__ == "__main__":
    print("\n".join(pinned()))
