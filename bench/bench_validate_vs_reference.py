"""``wobjcal validate`` against the same command in a reference tree, whole commands, interleaved.

Each case runs ``python3 -m planner validate PLAN --trials N --seed 1`` (the user's command: its
defaults, i.e. the check before the run, 20 vetted trials and up to 2 workers) once in this
tree and once in the reference tree (a git worktree of the reference commit, e.g.
``git worktree add --detach ../wt-b68 b68e00a``: beside this tree, so that a plan's relative
references to ``../shared/reference`` resolve there too), then again, A B A B, so that both see the
same machine load; the ratio of each pair is reference / ours (> 1: ours is faster). Each
command runs in its own tree with ``PYTHONPATH`` set to that tree, so neither picks up the
other's code (checked before the runs: ``planner.__file__`` of each environment is recorded).
The reference keeps its caches (numba kernels, distance fields, allowed-collision lists) in a
directory of its own (``$TMPDIR/wobjcal-cache-<tree name>``): numba keeps one version of the
kernels per cache directory and deletes the others, so the two trees sharing one would compile
their kernels at every turn. An untimed run of each side first fills both caches. A pair where
either side refuses the command (exit code 2: e.g. a reference tree where the plan's mesh is
not found) gives no ratio: the case is recorded as ``void`` with the refusal.

The load average is read before and after every command (``os.getloadavg``): the machine is
shared, so the pairs, not the absolute seconds, are the measurement.

    python -m bench.bench_validate_vs_reference --reference ../wt-b68
    python -m bench.bench_validate_vs_reference --reference ../wt-b68 --trials 10000 \\
        --repeats 1 --cases stator
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from bench.reference_tree import adopt_orphans, reap_orphans
from bench.result_file import write_result

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "bench" / "results"
CASES = {
    "stator": "assets/plans/stator_section_ah.json",
    "plate": "assets/plans/plate_holes_best_fit.json",
}

LOAD_KEYS = ("load_1min_before", "load_1min_after")


def _env(tree: Path) -> dict[str, str]:
    """The environment of a command run in ``tree``: its own code first on the path; another
    tree than this one gets its own cache directory (numba keeps one version of the kernels
    per cache and deletes the others: two trees sharing it would recompile at every turn)."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(tree)
    if tree.resolve() != ROOT:
        env["WOBJCAL_CACHE_DIR"] = str(Path(tempfile.gettempdir()) / f"wobjcal-cache-{tree.name}")
    return env


def planner_file(tree: Path) -> str:
    """Where ``import planner`` resolves in ``tree``'s environment (must be inside it)."""
    out = subprocess.run(
        [sys.executable, "-c", "import planner; print(planner.__file__)"],
        cwd=tree,
        env=_env(tree),
        capture_output=True,
        text=True,
        check=True,
    )
    return out.stdout.strip()


def _commit(tree: Path) -> str:
    """The commit ``tree`` is at, ``+`` when its tracked files differ from it."""
    head = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], cwd=tree, capture_output=True, text=True
    ).stdout.strip()
    dirty = subprocess.run(["git", "diff", "--quiet", "HEAD", "--", "*.py"], cwd=tree).returncode
    return head + ("+" if dirty else "")


def _last_line(text: str) -> str:
    return (text.strip().splitlines() or [""])[-1]


def _children_cpu_s() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run_command(tree: Path, plan: str, trials: int, seed: int) -> dict[str, Any]:
    """One whole ``validate`` command in ``tree``: wall and CPU seconds, load, exit code."""
    argv = [sys.executable, "-m", "planner", "validate", plan]
    argv += ["--trials", str(trials), "--seed", str(seed)]
    load0 = os.getloadavg()[0]
    cpu0, t0 = _children_cpu_s(), time.perf_counter()
    proc = subprocess.run(argv, cwd=tree, env=_env(tree), capture_output=True, text=True)
    wall = time.perf_counter() - t0
    reap_orphans()  # the fork server and its workers' CPU (adopt_orphans, in main)
    cpu = _children_cpu_s() - cpu0
    return {
        "wall_s": round(wall, 3),
        "cpu_s": round(cpu, 3),
        "load_1min_before": round(load0, 2),
        "load_1min_after": round(os.getloadavg()[0], 2),
        "exit_code": proc.returncode,
        "error": _last_line(proc.stderr)[:400] if proc.returncode == 2 else "",
        "last_line": _last_line(proc.stdout)[:200],
        "summary": next((ln for ln in proc.stdout.splitlines() if "Trials:" in ln), "")[:200],
    }


def compare(
    ours: Path, reference: Path, plan: str, trials: int, repeats: int, seed: int
) -> dict[str, Any]:
    """``repeats`` interleaved pairs (ours, then the reference) of one case."""
    pairs = []
    for k in range(repeats):
        a = run_command(ours, plan, trials, seed)
        if a["exit_code"] == 2:  # bad input (e.g. over the run-size budget): nothing to time
            return {"plan": plan, "trials": trials, "refused": a["error"]}
        b = run_command(reference, plan, trials, seed)
        if b["exit_code"] == 2:  # the reference did not run the plan: no ratio
            print(f"{plan}: no ratio, the reference refused it: {b['error']}", flush=True)
            return {
                "plan": plan,
                "trials": trials,
                "void": b["error"],
                "pairs": [*pairs, {"ours": a, "reference": b}],
            }
        pairs.append({"ours": a, "reference": b, "ratio": round(b["wall_s"] / a["wall_s"], 3)})
        print(
            f"{plan} x{trials} #{k + 1}: ours {a['wall_s']:.1f} s, reference {b['wall_s']:.1f} s,"
            f" ratio {pairs[-1]['ratio']:.2f} (load {a['load_1min_before']:.1f}-"
            f"{b['load_1min_after']:.1f})",
            flush=True,
        )
    ours_w = [p["ours"]["wall_s"] for p in pairs]
    ref_w = [p["reference"]["wall_s"] for p in pairs]
    ratios = [p["ratio"] for p in pairs]
    loads = [p[side][k] for p in pairs for side in ("ours", "reference") for k in LOAD_KEYS]
    return {
        "plan": plan,
        "trials": trials,
        "pairs": pairs,
        "ours_median_wall_s": statistics.median(ours_w),
        "reference_median_wall_s": statistics.median(ref_w),
        "ratio_median": statistics.median(ratios),
        "ratio_range": [min(ratios), max(ratios)],
        "ours_median_cpu_s": statistics.median(p["ours"]["cpu_s"] for p in pairs),
        "reference_median_cpu_s": statistics.median(p["reference"]["cpu_s"] for p in pairs),
        "load_range": [min(loads), max(loads)],
    }


def main(argv: list[str] | None = None) -> int:
    """Run the comparison; write ``bench/results/validate_vs_<name>.json``."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reference", type=Path, required=True, help="the reference worktree")
    ap.add_argument("--name", default="b68e00a", help="the reference's name in the result file")
    ap.add_argument("--cases", default="stator,plate", help=f"comma-separated of {list(CASES)}")
    ap.add_argument("--trials", type=int, default=400)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--no-warmup", action="store_true")
    args = ap.parse_args(argv)
    adopt_orphans()  # a fork server's CPU counts too (bench.reference_tree.reap_orphans)
    reference = args.reference.resolve()
    where = {"ours": planner_file(ROOT), "reference": planner_file(reference)}
    if not where["ours"].startswith(str(ROOT)) or not where["reference"].startswith(str(reference)):
        raise SystemExit(f"a tree imports the other's code: {where}")
    out_path = RESULTS / f"validate_vs_{args.name}.json"
    result: dict[str, Any] = json.loads(out_path.read_text()) if out_path.exists() else {}
    result.update(
        {
            "reference": args.name,
            "planner_imported_from": where,
            "cpu_count": os.cpu_count(),
            "command": "python3 -m planner validate PLAN --trials N --seed 1 (defaults otherwise)",
        }
    )
    ours_commit = _commit(ROOT)
    for case in args.cases.split(","):
        plan = CASES[case]
        if not args.no_warmup:  # numba kernels into the caches of both trees
            run_command(ROOT, plan, 50, args.seed)
            run_command(reference, plan, 50, args.seed)
        result[f"{case}_{args.trials}"] = {
            "ours_commit": ours_commit,
            **compare(ROOT, reference, plan, args.trials, args.repeats, args.seed),
        }
        write_result(out_path, result, echo=False)  # after every case: a long run keeps its part
    write_result(out_path, result)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
