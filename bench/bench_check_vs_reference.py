"""``wobjcal check`` of the demo against a reference commit: whole commands, interleaved.

The command is the user's, ``python3 -m planner check PLAN --json``, run in our tree and in the
reference's (``bench.reference_tree``: each its own code on the path and its own cache
directory, filled by an untimed run of each side first, so both are warm). Pairs alternate
which tree goes first (``bench.interleaved``); each pair's ratio is reference / ours (> 1:
ours is faster). Issue 24's target is "no slower": ours checks more than b68e00a did (the
landing of every search, the cycle time, the program of a controller), in the same command.

The answer is each point's id, status, pose status and whether its search path is feasible,
with the plan's overall verdict and the exit code (``same_statuses``).

    python -m bench.bench_check_vs_reference --reference /tmp/wt-ref --repeats 5
"""

from __future__ import annotations

import argparse
import hashlib
import json
import tempfile
from pathlib import Path
from typing import Any

from bench.interleaved import interleaved
from bench.reference_tree import ROOT, adopt_orphans, run_header, run_in_tree
from bench.result_file import write_result

RESULTS = ROOT / "bench" / "results"
PLAN = "assets/plans/stator_section_ah.json"


def _statuses(stdout: str) -> str | None:
    """A digest of the verdicts in the check's JSON (``None``: no JSON)."""
    try:
        report = json.loads(stdout)
    except json.JSONDecodeError:
        return None
    if not isinstance(report, dict):
        return None
    key = [report.get("feasible")] + [
        [p.get("id"), p.get("status"), p.get("pose_status"), p.get("path_feasible")]
        for p in report.get("points", [])
    ]
    return hashlib.sha256(json.dumps(key).encode()).hexdigest()[:16]


def run_check(tree: Path, cache: Path) -> dict[str, Any]:
    """One whole ``check --json`` of the demo plan in ``tree``."""
    run = run_in_tree(tree, ["-m", "planner", "check", PLAN, "--json"], cache)
    run["statuses_sha256"] = _statuses(run.pop("stdout"))
    if run["exit_code"] not in (0, 1) or run["statuses_sha256"] is None:
        raise SystemExit(f"{tree} check failed ({run['exit_code']}): {run['stderr_last']}")
    return run


def main(argv: list[str] | None = None) -> int:
    """Run the comparison; write ``bench/results/check_vs_<name>.json``."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--reference", type=Path, required=True, help="the reference worktree")
    ap.add_argument("--ours", type=Path, default=ROOT, help="our tree (default: this one)")
    ap.add_argument("--name", default="b68e00a", help="the reference's name in the result file")
    ap.add_argument("--repeats", type=int, default=5, help="pairs")
    ap.add_argument("--out", type=Path, default=None, help="result file (default by --name)")
    args = ap.parse_args(argv)
    adopt_orphans()
    ours, reference = args.ours.resolve(), args.reference.resolve()
    out_path = args.out or RESULTS / f"check_vs_{args.name}.json"
    result: dict[str, Any] = run_header(ours, reference, args.name)
    result["command"] = f"python3 -m planner check {PLAN} --json"
    with tempfile.TemporaryDirectory(prefix="wobjcal-check-bench-") as tmp:
        cache = {ours: Path(tmp) / "cache-ours", reference: Path(tmp) / "cache-reference"}
        for tree in (reference, ours):  # fill both caches, untimed
            run_check(tree, cache[tree])
        result["demo"] = interleaved(
            ours,
            reference,
            args.repeats,
            lambda tree: run_check(tree, cache[tree]),
            "statuses_sha256",
            "same_statuses",
            "check demo",
        )
    write_result(out_path, result, echo=False)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
