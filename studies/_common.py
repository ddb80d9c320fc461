"""Shared plumbing of the studies: output folder, progress, markdown tables, parallel sweeps."""
from __future__ import annotations

import multiprocessing
import os
import sys
import time
from concurrent.futures import Executor, ProcessPoolExecutor
from pathlib import Path

__all__ = ["output_dir", "Progress", "markdown_table", "run_cases", "command_line"]


def output_dir(name: str, out=None) -> Path:
    """The study's output folder (created): ``out`` or ``./out/<name>``."""
    path = Path(out) if out is not None else Path("out") / name
    path.mkdir(parents=True, exist_ok=True)
    return path


class Progress:
    """Prints one line per finished case with the elapsed time (to stderr; silent if disabled)."""

    def __init__(self, name: str, total: int, enabled: bool = True):
        self.name, self.total, self.enabled = name, total, enabled
        self.done = 0
        self.start = time.perf_counter()

    def __call__(self, message: str) -> None:
        self.done += 1
        if self.enabled:
            print(f"[{self.name} {self.done}/{self.total} {time.perf_counter() - self.start:7.1f}s] {message}",
                  file=sys.stderr, flush=True)


def markdown_table(headers, rows) -> str:
    """A GitHub markdown table; floats printed with 4 significant digits."""
    def fmt(x):
        if isinstance(x, float):
            return f"{x:.4g}" if 1e-3 <= abs(x) < 1e4 or x == 0 else f"{x:.3e}"
        return str(x)
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(fmt(x) for x in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def run_cases(fn, cases, executor: Executor | None = None, jobs: int | None = None, progress=None):
    """Map ``fn`` over ``cases`` through the standard executor interface.

    Parameters
    ----------
    fn : callable
        A module-level function (picklable) taking one case.
    cases : list
    executor : concurrent.futures.Executor, optional
        Any executor -- e.g. a ``ProcessPoolExecutor`` or a Dask
        ``distributed.Client().get_executor()``; it is not shut down here.
    jobs : int, optional
        Without an executor: ``1`` runs serially in this process (timings
        undisturbed); more starts a local process pool of that size.
    progress : callable, optional
        Called with a short text per finished case.

    Returns
    -------
    list
        Results in the order of ``cases``.
    """
    if executor is None and (jobs is None or jobs <= 1):
        out = []
        for case in cases:
            out.append(fn(case))
            if progress:
                progress(str(case))
        return out
    own = executor is None
    if own:
        # "spawn": forking a process that already runs threads (OpenMP, numba, SUNDIALS -- e.g. inside a
        # test session) can deadlock the children; fresh interpreters cost ~1 s each.
        executor = ProcessPoolExecutor(max_workers=jobs or os.cpu_count(),
                                       mp_context=multiprocessing.get_context("spawn"))
    try:
        futures = [executor.submit(fn, case) for case in cases]
        results = []
        for case, fut in zip(cases, futures):
            results.append(fut.result())
            if progress:
                progress(str(case))
        return results
    finally:
        if own:
            executor.shutdown()


def command_line(run, doc: str, argv=None) -> None:
    """``python -m ancfdae.studies.NAME [--quick] [--out DIR] [--jobs N]``: run a study and print its table."""
    import argparse
    p = argparse.ArgumentParser(description=doc.strip().splitlines()[0])
    p.add_argument("--quick", action="store_true", help="small, fast version (what the tests run)")
    p.add_argument("--out", default=None, help="output folder (default out/NAME)")
    p.add_argument("--jobs", type=int, default=None, help="worker processes for the sweep")
    args = p.parse_args(argv)
    res = run(quick=args.quick, out=args.out, jobs=args.jobs)
    print(res["table"])
    print(f"written to {res['path']}")
