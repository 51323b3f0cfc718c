"""The allowed-collision list (ACL) of a robot + tool, sampled once and cached.

The list is worked out once per robot + tool by sampling random in-limit configurations
(pybullet-planning's ``get_collision_fn`` idea: compute once, return a fast predicate). A pair
of robot/tool links is *allowed* (never reported) when it is adjacent (parent and child, or the
tool's root on the flange link) or when it is closer than the self margin in at least
:data:`ALWAYS_FRACTION` of the samples (e.g. vendor wrist meshes that overlap in every pose).
A tool link is never allowed against a robot link other than those it is mounted on (the flange
link and the links fixed to it): a tool that sticks through the wrist in every sample is a
wrongly mounted tool, not a pair to ignore.
Pairs that never came near are recorded as ``never`` but are still checked: Bullet's broadphase
skips far pairs for free, so skipping them would save nothing and could hide a rare real
collision. The list is cached in memory and on disk (JSON, ``$WOBJCAL_CACHE_DIR/acl`` or
``~/.cache/wobjcal/acl``), keyed by a hash of the URDF texts and the settings.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from calib.atomic_io import write_bytes_atomic
from planner.cell.disk_cache import warn_once
from planner.cell.scene.bodies import BodyLinks
from planner.cell.scene.pybullet_client import pb

log = logging.getLogger(__name__)

#: A pair closer than the self margin in at least this fraction of the samples is allowed.
ALWAYS_FRACTION = 0.95
#: Bump when the ACL rule changes, so cached lists are recomputed.
ACL_VERSION = 2

Pair = tuple[str, str]
_MEMORY_CACHE: dict[str, AllowedCollisions] = {}


def pair(a: str, b: str) -> Pair:
    """The canonical (sorted) form of a link pair."""
    return (a, b) if a <= b else (b, a)


@dataclass(frozen=True)
class AllowedCollisions:
    """The allowed-collision list of one robot + tool.

    Attributes:
        allowed: link pairs never reported (adjacent, or near in almost every sample).
        never: pairs never closer than the self margin in the samples (still checked).
        near_fraction: pair -> fraction of samples closer than the self margin.
        n_samples: number of random configurations sampled.
        key: the cache key (hash of the URDF texts and settings).
    """

    allowed: frozenset[Pair]
    never: frozenset[Pair]
    near_fraction: dict[Pair, float] = field(repr=False)
    n_samples: int
    key: str

    def to_json(self) -> str:
        """Canonical JSON text of the list."""
        return json.dumps(
            {
                "schema": f"wobjcal.acl/{ACL_VERSION}",
                "allowed": sorted(self.allowed),
                "never": sorted(self.never),
                "near_fraction": sorted([*k, v] for k, v in self.near_fraction.items()),
                "n_samples": self.n_samples,
                "key": self.key,
            },
            indent=1,
            sort_keys=True,
        )

    @classmethod
    def from_json(cls, text: str) -> AllowedCollisions:
        """Inverse of :meth:`to_json`."""
        d = json.loads(text)
        return cls(
            allowed=frozenset(pair(*p) for p in d["allowed"]),
            never=frozenset(pair(*p) for p in d["never"]),
            near_fraction={pair(a, b): float(f) for a, b, f in d["near_fraction"]},
            n_samples=int(d["n_samples"]),
            key=str(d["key"]),
        )


def sample_configurations(
    lower: np.ndarray, upper: np.ndarray, n: int, rng: np.random.Generator
) -> np.ndarray:
    """``(n, dof)`` configurations uniform within the limits (``[-pi, pi]`` where unlimited)."""
    lo = np.where(np.isfinite(lower), lower, -np.pi)
    hi = np.where(np.isfinite(upper), upper, np.pi)
    return rng.uniform(lo, hi, size=(int(n), len(lo)))


def cache_dir() -> Path:
    """Directory of cached ACLs: ``$WOBJCAL_CACHE_DIR/acl`` or ``~/.cache/wobjcal/acl``."""
    root = os.environ.get("WOBJCAL_CACHE_DIR") or Path.home() / ".cache" / "wobjcal"
    return Path(root) / "acl"


def acl_key(texts: Iterable[bytes], settings: str) -> str:
    """Cache key: sha256 of the URDF texts and the settings string."""
    h = hashlib.sha256(f"acl{ACL_VERSION}:{settings}".encode())
    for t in texts:
        h.update(hashlib.sha256(t).digest())
    return h.hexdigest()[:32]


def compute_acl(
    client: int,
    robot: BodyLinks,
    tool: BodyLinks | None,
    names: Callable[[int, int], str],
    set_config: Callable[[np.ndarray], None],
    samples: np.ndarray,
    adjacent: Iterable[Pair],
    self_margin_m: float,
    key: str,
    use_cache: bool = True,
    mount_links: Iterable[str] = (),
) -> AllowedCollisions:
    """Sample configurations and classify robot/tool link pairs (see the module docstring).

    Args:
        client: PyBullet client id.
        robot: the robot body; ``tool``: the tool body, or ``None``.
        names: ``(body_id, link_index) -> link name`` as used in reports.
        set_config: puts the robot (and tool) in configuration ``q (n,)``.
        samples: ``(S, n)`` random in-limit configurations, rad.
        adjacent: pairs always allowed (parent-child links, tool root on the flange link).
        self_margin_m: a pair closer than this counts as near, m.
        key: cache key (see :func:`acl_key`).
        use_cache: read and write the memory and disk caches.
        mount_links: robot links the tool is mounted on: the only robot links a tool link may
            be allowed against (besides ``adjacent`` pairs).
    """
    if use_cache and key in _MEMORY_CACHE:
        return _MEMORY_CACHE[key]
    path = cache_dir() / f"{key}.json"
    if use_cache and path.is_file():
        try:
            acl = AllowedCollisions.from_json(path.read_text())
            _MEMORY_CACHE[key] = acl
            return acl
        except (OSError, ValueError, KeyError, TypeError):
            log.warning("ignoring unreadable ACL cache %s", path)
    counts: dict[Pair, int] = {}
    bodies = [(robot.body_id, robot.body_id)]
    if tool is not None:
        bodies.append((robot.body_id, tool.body_id))
    for q in samples:
        set_config(q)
        seen: set[Pair] = set()
        for a, b in bodies:
            for pt in pb.getClosestPoints(a, b, self_margin_m, physicsClientId=client):
                if a == b and pt[3] == pt[4]:
                    continue
                seen.add(pair(names(a, pt[3]), names(b, pt[4])))
        for p in seen:
            counts[p] = counts.get(p, 0) + 1
    all_pairs = _all_pairs(robot, tool, names)
    n = max(len(samples), 1)
    frac = {p: counts.get(p, 0) / n for p in all_pairs}
    tool_names = {names(tool.body_id, i) for i in tool.names} if tool is not None else set()
    mount = set(mount_links)

    def may_allow(p: Pair) -> bool:
        a, b = p
        if a in tool_names or b in tool_names:  # tool-robot: only against the mount links
            return (b if a in tool_names else a) in mount
        return True

    sampled = {p for p, f in frac.items() if f >= ALWAYS_FRACTION and may_allow(p)}
    for a, b in sorted(p for p, f in frac.items() if f >= ALWAYS_FRACTION and not may_allow(p)):
        log.warning(
            "%s and %s are within %.1f mm in %.0f %% of the sampled poses: the tool is mounted "
            "through the robot (check the plan's cell.tool.T_flange_tool); checked, not allowed",
            a,
            b,
            self_margin_m * 1e3,
            100 * frac[(a, b)],
        )
    allowed = {pair(*p) for p in adjacent} | sampled
    never = {p for p, f in frac.items() if f == 0.0 and p not in allowed}
    acl = AllowedCollisions(frozenset(allowed), frozenset(never), frac, len(samples), key)
    if use_cache:
        _MEMORY_CACHE[key] = acl
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_bytes_atomic(path, acl.to_json().encode())
        except OSError as exc:  # a cache is optional: told once, never a failed command
            warn_once("acl", f"cannot write ACL cache {path}: {exc.strerror or exc}")
    return acl


def _all_pairs(robot: BodyLinks, tool: BodyLinks | None, names: Callable[[int, int], str]):
    r = [names(robot.body_id, i) for i in robot.names]
    t = [names(tool.body_id, i) for i in tool.names] if tool is not None else []
    out = {pair(a, b) for i, a in enumerate(r) for b in r[i + 1 :]}
    out |= {pair(a, b) for a in r for b in t}
    return out
