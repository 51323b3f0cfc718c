"""``wobjcal suggest`` against a reference commit: whole commands, interleaved, same answers.

Each case is the user's command, ``python3 -m planner suggest PLAN ARGS -o OUT``, run in our
tree and in the reference's (see ``bench.reference_tree``: each its own code on the path and
its own cache directory, filled by an untimed run of each side first, so both are warm: the
kernels compiled, the part's distance field and allowed-collision lists on disk). Pairs
alternate which tree goes first; each pair's ratio is reference / ours (> 1: ours is faster).

The answer is the written plan's points (id, role, position, normal, search kind, edge
direction; positions and directions to 1e-9) and the command's exit code; both are recorded
per run and compared with the reference's first run (``same_points``). The whole written plan
may differ where the two commits write other fields (search sizing, vias); that is recorded
as ``same_file`` and not counted against the answers.

Cases (flags that both commits have): ``demo`` is the stator cell ``wobjcal ui`` opens, with
the target of ``docs/cli.md``'s example; ``plate`` the machined plate's best fit, with the
target and size of ``docs/cycle_time.md``'s plate example.

    python -m bench.bench_suggest_vs_reference --reference /tmp/wt-ref --ours /tmp/wt-head
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
CASES: dict[str, list[str]] = {
    "demo": ["assets/plans/stator_section_ah.json", "--target", "0.3"],
    "plate": ["assets/plans/plate_holes_best_fit.json", "--target", "0.07", "--max-points", "9"],
}


def _points_key(plan: dict[str, Any]) -> list[Any]:
    def r(v: Any) -> Any:
        return None if v is None else [round(float(x), 9) for x in v]

    return [
        [
            p.get("id"),
            p.get("role"),
            r(p.get("position_m")),
            r(p.get("normal")),
            (p.get("search") or {}).get("kind"),
            r((p.get("search") or {}).get("edge_direction")),
        ]
        for p in plan.get("points", [])
    ]


def _answer(out_file: Path) -> dict[str, Any]:
    if not out_file.exists():
        return {"points": None, "points_sha256": None, "file_sha256": None}
    text = out_file.read_text()
    key = _points_key(json.loads(text))
    return {
        "points": len(key),
        "points_sha256": hashlib.sha256(json.dumps(key).encode()).hexdigest()[:16],
        "file_sha256": hashlib.sha256(text.encode()).hexdigest()[:16],
    }


def plan_in(tree: Path, plan: str, tmp: Path) -> str:
    """``plan`` as ``tree`` has it; when its part's mesh is a relative path that does not
    resolve from the worktree (the shipped plate names ``../../../shared/...``, which holds
    from the main checkout only), a copy in ``tmp`` with that path made absolute, resolved
    from this checkout's plan folder (the same file for both trees)."""
    path = tree / plan
    data = json.loads(path.read_text())
    mesh = (data.get("work_object") or {}).get("mesh")
    builtin = str(mesh).startswith("builtin:")
    if not mesh or builtin or Path(mesh).is_absolute() or (path.parent / mesh).exists():
        return plan
    data["work_object"]["mesh"] = str(((ROOT / plan).parent / mesh).resolve())
    copy = tmp / f"{tree.name}-{Path(plan).name}"
    copy.write_text(json.dumps(data, indent=2, sort_keys=True) + "\n")
    return str(copy)


def run_case(tree: Path, case: str, cache: Path, tmp: Path) -> dict[str, Any]:
    """One whole ``suggest`` command of ``case`` in ``tree``."""
    out_file = tmp / f"{case}-{tree.name}.json"
    out_file.unlink(missing_ok=True)
    plan, *flags = CASES[case]
    argv = ["-m", "planner", "suggest", plan_in(tree, plan, tmp), *flags, "-o", str(out_file)]
    run = run_in_tree(tree, argv, cache)
    stdout = run.pop("stdout")
    run["last_line"] = (stdout.strip().splitlines() or [""])[-1][:300]
    run.update(_answer(out_file))
    if run["exit_code"] not in (0, 1):
        raise SystemExit(f"{tree} suggest {case} failed ({run['exit_code']}): {run['stderr_last']}")
    return run


def compare(
    ours: Path, reference: Path, case: str, repeats: int, tmp: Path, warmup: bool
) -> dict[str, Any]:
    """``repeats`` pairs of one case, alternating which tree goes first."""
    cache = {ours: tmp / "cache-ours", reference: tmp / "cache-reference"}
    if warmup:  # fill both trees' caches, untimed
        run_case(reference, case, cache[reference], tmp)
        run_case(ours, case, cache[ours], tmp)

    def run(tree: Path) -> dict[str, Any]:
        return run_case(tree, case, cache[tree], tmp)

    out = interleaved(
        ours, reference, repeats, run, "points_sha256", "same_points", f"suggest {case}"
    )
    for pair in out["pairs"]:  # the whole file: recorded, not counted against the answers
        pair["same_file"] = pair["ours"]["file_sha256"] == pair["reference"]["file_sha256"]
    return {"args": CASES[case], **out}


def main(argv: list[str] | None = None) -> int:
    """Run the comparison; write ``bench/results/suggest_vs_<name>.json``."""
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--reference", type=Path, required=True, help="the reference worktree")
    ap.add_argument("--ours", type=Path, default=ROOT, help="our tree (default: this one)")
    ap.add_argument("--name", default="b68e00a", help="the reference's name in the result file")
    ap.add_argument("--cases", default="demo,plate", help=f"comma-separated of {list(CASES)}")
    ap.add_argument("--repeats", type=int, default=3, help="pairs per case")
    ap.add_argument("--no-warmup", action="store_true")
    ap.add_argument("--out", type=Path, default=None, help="result file (default by --name)")
    args = ap.parse_args(argv)
    adopt_orphans()  # a fork server's CPU counts too (bench.reference_tree.reap_orphans)
    ours, reference = args.ours.resolve(), args.reference.resolve()
    out_path = args.out or RESULTS / f"suggest_vs_{args.name}.json"
    result: dict[str, Any] = json.loads(out_path.read_text()) if out_path.exists() else {}
    result.update(run_header(ours, reference, args.name))
    result["command"] = "python3 -m planner suggest PLAN ARGS -o OUT"
    with tempfile.TemporaryDirectory(prefix="wobjcal-suggest-bench-") as tmp:
        for case in args.cases.split(","):
            result[case] = compare(
                ours, reference, case, args.repeats, Path(tmp), not args.no_warmup
            )
            write_result(out_path, result, echo=False)
    write_result(out_path, result, echo=False)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
