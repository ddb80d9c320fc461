"""A toy study for the runner tests: each case sleeps a little (or long), then returns a tiny Result.

Its workers write their process id to ``out/pids`` so that a test can check they are gone after Ctrl-C.
Cases from ``TOY_SLOW_FROM`` (environment; not a case option, so a rerun without it reuses the stored
cases) sleep 120 s: the ones a test interrupts.
"""
import os
import time

import numpy as np

from ancfdae.result import Result
from ancfdae.studies._cli import Option
from ancfdae.studies._common import Case, output_dir, run_cases, settings
from ancfdae.studies._tables import markdown_table

NAME = "toy"
FULL = dict(n_cases=4, sleep=0.01, fail=-1)
QUICK = dict(n_cases=2)
CLI_OPTIONS = [Option("n_cases", int, "number of cases"), Option("sleep", float, "seconds each fast case sleeps"),
               Option("fail", int, "case that raises")]


def case_fn(case):
    """Sleep, then return ``{"result": Result with q = i, "square": i**2}``; case ``fail`` raises."""
    open(os.path.join(case["pids"], str(os.getpid())), "w").close()
    if case["i"] == case["fail"]:
        raise RuntimeError(f"case {case['i']} is broken")
    time.sleep(case["sleep"] if case["i"] < int(os.environ.get("TOY_SLOW_FROM", "99")) else 120.0)
    t = np.linspace(0.0, 1.0, 3)
    q = np.full((3, 2), float(case["i"]))
    return {"result": Result(t, q, q, q, stats={"steps": 3}), "square": case["i"] ** 2}


def run(n_cases=None, sleep=None, fail=None, quick=False, out=None, jobs=None, progress=True):
    """Run the toy sweep; return ``{"sweep", "table", "path"}``."""
    o = settings(FULL, QUICK, quick, dict(n_cases=n_cases, sleep=sleep, fail=fail), unchecked=("fail", "sleep"))
    path = output_dir(NAME, out, quick)
    pids = path / "pids"
    pids.mkdir(exist_ok=True)
    cases = [Case(i=i, sleep=o["sleep"], fail=o["fail"], pids=str(pids), label=f"case {i}")
             for i in range(o["n_cases"])]
    sweep = run_cases(case_fn, cases, out=path, jobs=jobs, name="toy", progress=progress)
    rows = [[str(c), "error" if r is None else r["square"]] for c, r in zip(cases, sweep.records)]
    return {"sweep": sweep, "errors": sweep.errors, "table": markdown_table(["case", "square"], rows), "path": path}
