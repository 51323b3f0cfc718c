"""Write ``tests/data/results/``: what each controller leaves after running the program of the
shipped plate 3-2-1 plan on one simulated misplaced part (one validate trial, seed 2), from this
project's interpreters of the four languages (:mod:`tests.controller_files`), and the true
frame of that part (``truth.json``). ``docs/results.md`` shows them and
``tests/planner/results/test_results_samples.py`` calibrates from each.

Run ``python3 -m tests.make_results_samples`` after a change of the plan or of the programs (the
KRL and URScript samples carry the plan's digest: a stale sample is refused by the reader).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from calib.atomic_io import write_text_atomic
from planner.export import export_files
from planner.export.job import ToolData, build_job
from tests.controller_files import fanuc_va, krl_saved_dat, ur_log
from tests.fanuc_interp import TPMachine
from tests.krl_interp import KrlMachine
from tests.planner.export.test_fanuc_program_replay import tp_text
from tests.planner.validate.test_program_trial_replay import _search_callback, _trial
from tests.rapid_interp import Machine
from tests.urscript_interp import UrMachine

ROOT = Path(__file__).resolve().parents[1]
PLAN = ROOT / "assets" / "plans" / "plate_holes_321.json"
OUT = ROOT / "tests" / "data" / "results"
SEED = 2


def make(out: Path = OUT) -> dict[str, Path]:
    """Write the samples into ``out``; ``{name: path}``."""
    out.mkdir(parents=True, exist_ok=True)
    written: dict[str, Path] = {}

    def put(name: str, text: str) -> None:
        written[name] = write_text_atomic(out / name, text)

    T_true = None
    for fmt in ("rapid", "krl", "urscript", "fanuc"):
        plan, setup, probe, T_true = _trial(PLAN, fmt, SEED)
        job = build_job(plan, setup.T_base_wobj_nominal, ToolData(T_flange_tcp=np.eye(4)))
        search = _search_callback(probe())
        if fmt == "rapid":
            m = Machine(export_files(job, "rapid")[".mod"], search)
            m.main()
            put("wobjcal_measured.json", m.files["wobjcal_measured.json"])
        elif fmt == "krl":
            files = export_files(job, "krl")
            k = KrlMachine(files, search).run()
            put("WOBJCALPLATEHOLES321.dat", krl_saved_dat(files[".dat"], k))
        elif fmt == "urscript":
            u = UrMachine(export_files(job, "urscript")[".script"], search).run()
            put("log_history.txt", ur_log(u.messages))
        else:
            _, text = tp_text(job)
            tp = TPMachine(text, search).run()
            posreg, numreg = fanuc_va(tp)
            (out / "fanuc").mkdir(exist_ok=True)
            put("fanuc/POSREG.VA", posreg)
            put("fanuc/NUMREG.VA", numreg)
    assert T_true is not None
    put(
        "truth.json",
        json.dumps(
            {
                "comment": f"the simulated part of trial seed {SEED} of {PLAN.name}: "
                "T_base_wobj (m)",
                "T_base_wobj": np.round(T_true, 12).tolist(),
            },
            indent=2,
        )
        + "\n",
    )
    return written


if __name__ == "__main__":
    for name, path in make().items():
        print(f"{name}: {path}")
