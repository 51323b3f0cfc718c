"""Plot the UI latency runs of ``bench/results/ui_latency_runs/`` (issue 22, item 8).

Each JSON there is one ``bench_ui_latency --demo-browser`` run, named ``<tree>_run<k>.json``
(``ours`` or the reference commit). The plot shows, per measure, the median and the p90 of
every run side by side, with the 300 ms target:

    python -m bench.plot_ui_latency                       # -> docs/img/ui_latency.png
    python -m bench.plot_ui_latency --out /tmp/lat.png
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

HERE = Path(__file__).resolve().parent
RUNS = HERE / "results" / "ui_latency_runs"
OUT = HERE.parent / "docs" / "img" / "ui_latency.png"

#: (result key, label) of the measures shown.
MEASURES = (
    ("click_to_row_in_dom", "click → row\nin the DOM"),
    ("click_to_row_on_page", "click → row\n(locator)"),
    ("undo_to_row_out_of_dom", "undo → row gone\nfrom the DOM"),
    ("undo_click_to_row_gone", "undo → row gone\n(locator)"),
)
TARGET_MS = 300.0


def load_runs(folder: Path = RUNS) -> dict[str, dict[str, object]]:
    """Every run in ``folder`` by file stem (e.g. ``ours_run1``), sorted by name."""
    runs = {p.stem: json.loads(p.read_text()) for p in sorted(folder.glob("*.json"))}
    if not runs:
        raise SystemExit(f"no runs in {folder}: run bench.bench_ui_latency --demo-browser first")
    return runs


def plot(runs: dict[str, dict[str, object]], out: Path) -> None:
    """Grouped bars: a group per measure, a bar per run (median, whisker to the p90), ms."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = sorted(runs, key=lambda n: (not n.startswith("ours"), n))
    width = 0.8 / len(names)
    fig, ax = plt.subplots(figsize=(9, 4.2), dpi=110)
    for k, name in enumerate(names):
        run = runs[name]
        med, p90 = [], []
        for key, _ in MEASURES:
            stats = run[key]
            assert isinstance(stats, dict)
            med.append(float(stats["median_ms"]))
            p90.append(float(stats["p90_ms"]))
        xs = [i + (k - (len(names) - 1) / 2) * width for i in range(len(MEASURES))]
        load = run.get("load_average_start", [float("nan")])
        assert isinstance(load, list)
        colour = "tab:green" if name.startswith("ours") else "tab:grey"
        ax.bar(
            xs,
            med,
            width * 0.9,
            color=colour,
            alpha=0.55 + 0.2 * (k % 2),
            label=f"{name} (load {float(load[0]):.1f})",
        )
        ax.errorbar(
            xs,
            med,
            yerr=[[0.0] * len(med), [p - m for p, m in zip(p90, med, strict=True)]],
            fmt="none",
            ecolor="black",
            capsize=2,
            lw=0.8,
        )
    ax.axhline(TARGET_MS, color="tab:red", ls="--", lw=1, label="target 300 ms (median)")
    ax.set_xticks(range(len(MEASURES)), [label for _, label in MEASURES])
    ax.set_ylabel("ms after the click (bar: median, whisker: p90)")
    ax.set_title("Demo cell in headless Chromium: status row after a click and an undo")
    ax.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, default=RUNS)
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args(argv)
    plot(load_runs(args.runs), args.out)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
