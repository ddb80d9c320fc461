"""Shared plumbing of the studies: options, output folder, and the case runner that keeps every finished case.

A study is a sweep of independent cases (one simulation each). :func:`run_cases`
runs them serially or through an executor, writes each finished case to the
output folder as soon as it finishes (:class:`CaseStore`), reuses the cases a
previous run with the same options left there, records a case that raises as
that case's failure and goes on, and on Ctrl-C cancels the rest, stops its own
worker processes and raises :class:`Interrupted` (the command line prints one
line and exits 130).

Every study's ``run``
---------------------
Besides its own options, every study's ``run`` takes the sweep options

``quick``
    the test-suite mode: the study's ``QUICK`` defaults over its ``FULL`` ones;
``out``
    the output folder (default ``out/NAME``, ``out/NAME-quick`` with ``quick``),
    checked before any work; each case is stored there when it finishes and a
    rerun reuses the stored cases;
``jobs``, ``executor``
    worker processes, or any ``concurrent.futures.Executor`` (e.g. a Dask
    ``Client().get_executor()``, which overrides ``jobs``), see :func:`run_cases`;
``plots``
    write the markdown table and the figures (PNG and SVG); with
    ``plots=False`` and no ``out`` nothing is written;
``progress``
    a progress bar on stderr;

and returns a dict with the study's own results (``rows``, ...) and the keys
``errors`` (``{case label: error text}`` of the cases that raised),
``reused`` (cases taken from ``out``), ``figures`` (``{file stem: Figure}``),
``table`` (markdown, :mod:`ancfdae.studies._tables`) and ``path`` (the output
folder or None). The command line (:mod:`ancfdae.studies._cli`) maps
``ancfdae study NAME`` onto ``run``.
"""
from __future__ import annotations

import math
import multiprocessing
import numbers
import os
import signal
import sys
import time
import traceback
from concurrent.futures import FIRST_COMPLETED, Executor, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

from ._store import CaseStore

__all__ = ["Case", "OptionError", "output_dir", "CaseStore", "Sweep", "Interrupted", "run_cases", "progress_bar",
           "settings"]


class OptionError(ValueError):
    """A study option is invalid (found before any work; the command line reports it as a usage error)."""


def output_dir(name: str, out=None, quick: bool = False) -> Path:
    """The study's output folder, checked and created before any work.

    Parameters
    ----------
    name : str
        Study name.
    out : path, optional
        The folder; default ``out/NAME`` (``out/NAME-quick`` in quick mode,
        so that a quick run never overwrites a full run's results).
    quick : bool

    Raises
    ------
    ValueError
        If ``out`` is an existing file or cannot be created as a folder.
    """
    path = Path(out) if out is not None else Path("out") / (f"{name}-quick" if quick else name)
    if path.exists() and not path.is_dir():
        raise OptionError(f"`out` must be a folder, got {str(path)!r}, which is an existing file.")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OptionError(f"`out` must be a folder that can be created, got {str(path)!r}: {exc}") from None
    if not os.access(path, os.W_OK):
        raise OptionError(f"`out` must be a writable folder, got {str(path)!r}.")
    return path


class Case(dict):
    """A sweep case: a dict of options whose ``str`` is its ``label`` (progress line, stored file names)."""

    def __str__(self):
        return str(self.get("label", dict.__repr__(self)))


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during a sweep: the finished cases are kept; ``str()`` says how many and where."""


@dataclass
class Sweep:
    """What :func:`run_cases` returns.

    Attributes
    ----------
    records : list
        Per case in the order of the cases: its record (after ``reduce``), or
        None if it raised.
    errors : dict
        ``{label: error text}`` of the cases that raised.
    reused : int
        Cases taken from the output folder instead of being run.
    """

    records: list
    errors: dict = field(default_factory=dict)
    reused: int = 0

    def finished(self) -> list:
        """The records of the cases that did not raise."""
        return [r for r in self.records if r is not None]


def progress_bar(name: str, total: float, initial: float = 0, enabled: bool = True):
    """A tqdm bar on stderr: share of the work done, elapsed time, estimated time left, cases done and the last."""
    from tqdm import tqdm
    return tqdm(total=total, initial=initial, desc=name, file=sys.stderr, disable=not enabled, dynamic_ncols=True,
                bar_format="{desc} {percentage:3.0f}% [{elapsed}<{remaining}] {postfix}")


def _ignore_sigint():
    # Worker processes leave Ctrl-C to the parent, which cancels the sweep and stops them:
    # no traceback from every worker, and no worker dying half-way through writing a pipe.
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _error_text(exc: BaseException) -> str:
    """``Type: message (at file:line in function)`` -- where the innermost frame of the case raised."""
    text = "".join(traceback.format_exception_only(type(exc), exc)).strip()
    frames = traceback.extract_tb(exc.__traceback__) if exc.__traceback__ is not None else []
    remote = getattr(exc.__cause__, "tb", None)            # a worker's traceback, as text
    if frames and not remote:
        f = frames[-1]
        text += f" (at {Path(f.filename).name}:{f.lineno} in {f.name})"
    elif remote:
        lines = [ln.strip() for ln in str(remote).splitlines() if ln.strip().startswith("File ")]
        if lines:
            text += f" (at {lines[-1]})"
    return text


def run_cases(fn, cases, out=None, executor: Executor | None = None, jobs: int | None = None, reduce=None,
              name: str = "study", progress: bool = True, cost=None) -> Sweep:
    """Run ``fn`` over ``cases``, keeping each finished case in ``out``.

    Parameters
    ----------
    fn : callable
        A module-level function (picklable) taking one case and returning a
        record: a dict with ``"result"`` (an :class:`ancfdae.Result`) and
        JSON-able scalars.
    cases : list of dict
        Each case's ``str`` is its label (unique within the sweep; it names
        the stored files).
    out : path, optional
        Output folder: finished cases are written to ``out/cases`` as they
        finish, and cases stored there by an earlier run with the same
        options are reused. None: nothing is written.
    executor : concurrent.futures.Executor, optional
        Any executor -- e.g. a Dask ``distributed.Client().get_executor()``;
        it is not shut down here (on Ctrl-C its pending futures are cancelled).
    jobs : int, optional
        Without an executor: ``1`` (default) runs serially in this process
        (timings undisturbed); more starts a local process pool of that size,
        whose workers are stopped on Ctrl-C.
    reduce : callable, optional
        Applied to each record once stored (e.g. to drop the full coordinate
        history and keep what the analysis needs).
    name : str
        Shown by the progress bar.
    progress : bool
        Show a progress bar with elapsed time and the estimated time left,
        advancing in completion order.
    cost : callable, optional
        Relative cost of a case (``cost(case) -> float``); the progress bar
        advances by it, so that its estimate of the time left holds when the
        cases differ in cost (default: equal), and an executor gets the cases
        longest first (the workers then end together; the records keep the
        order of ``cases``).

    Returns
    -------
    Sweep

    Raises
    ------
    Interrupted
        On Ctrl-C, after the pending cases are cancelled and the own workers
        stopped; finished cases are kept in ``out``.
    """
    cases = list(cases)
    labels = [str(c) for c in cases]
    if len(set(labels)) != len(labels):
        raise ValueError(f"`cases` must have unique labels, got duplicates in {labels}.")
    store = CaseStore(out, fn) if out is not None else None
    reduce = reduce or (lambda r: r)
    records = [None] * len(cases)
    todo = []
    for i, case in enumerate(cases):
        rec = store.load(case) if store is not None else None
        if rec is None:
            todo.append(i)
        else:
            records[i] = reduce(rec)
    sweep = Sweep(records, reused=len(cases) - len(todo))
    for note in store.notes if store is not None else ():
        print(f"{name}: {note}", file=sys.stderr, flush=True)
    if sweep.reused and progress:
        print(f"{name}: reusing {sweep.reused} of {len(cases)} finished cases from {store.folder}",
              file=sys.stderr, flush=True)
    weight = [float(cost(c)) if cost is not None else 1.0 for c in cases]
    bar = progress_bar(name, sum(weight), sum(w for w, r in zip(weight, records) if r is not None), progress)
    count = [sweep.reused]

    def finish(i, record=None, exc=None):
        if exc is not None:
            sweep.errors[labels[i]] = _error_text(exc)
            if store is not None:
                store.save_error(cases[i], sweep.errors[labels[i]])
            bar.write(f"{name}: case {labels[i]!r} raised {sweep.errors[labels[i]]}; the others go on",
                      file=sys.stderr)
        else:
            if store is not None:
                store.save(cases[i], record)
            records[i] = reduce(record)
        count[0] += 1
        bar.set_postfix_str(f"{count[0]}/{len(cases)} cases, last: {labels[i]}", refresh=False)
        bar.update(weight[i])

    pool = None
    try:
        if executor is None and (jobs is None or jobs <= 1):
            for i in todo:
                try:
                    record = fn(cases[i])
                except Exception as exc:        # one case's failure, recorded; KeyboardInterrupt passes
                    finish(i, exc=exc)
                else:
                    finish(i, record)
        elif todo:
            if executor is None:
                # "spawn": forking a process that already runs threads (OpenMP, numba, SUNDIALS -- e.g.
                # inside a test session) can deadlock the children; fresh interpreters cost ~1 s each.
                pool = executor = ProcessPoolExecutor(max_workers=jobs, initializer=_ignore_sigint,
                                                      mp_context=multiprocessing.get_context("spawn"))
            # longest first (by ``cost``): the last case to start is a short one, so the workers end together
            order = sorted(todo, key=lambda i: -weight[i]) if cost is not None else todo
            pending = {executor.submit(fn, cases[i]): i for i in order}
            try:
                while pending:
                    done, _ = wait(pending, return_when=FIRST_COMPLETED)
                    for fut in done:
                        i = pending.pop(fut)
                        exc = fut.exception()
                        if exc is not None:
                            finish(i, exc=exc)
                        else:
                            finish(i, fut.result())
            except BaseException:
                for fut in pending:
                    fut.cancel()
                raise
    except KeyboardInterrupt:
        _stop(pool)
        pool = None
        bar.close()
        n_done = sum(r is not None for r in records)
        where = f" in {store.folder}" if store is not None else " (no output folder: not kept)"
        raise Interrupted(f"{name} interrupted: {n_done} of {len(cases)} cases finished and kept{where}; "
                          "run the same command again to continue.") from None
    finally:
        if pool is not None:
            pool.shutdown()
    bar.close()
    return sweep


def _stop(pool) -> None:
    """Stop an own process pool now: cancel what is queued, terminate the workers."""
    if pool is None:
        return
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        if p.is_alive():
            p.terminate()
    deadline = time.monotonic() + 5.0
    for p in procs:
        p.join(timeout=max(0.0, deadline - time.monotonic()))


def _numbers(value):
    """The numbers in an option value (a number, or a list/tuple of them); text and None give none."""
    if isinstance(value, (list, tuple)):
        return [x for v in value for x in _numbers(v)]
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        return []
    return [value]


def settings(full: dict, quick_defaults: dict, quick: bool, given: dict, zero_allowed=(), unchecked=()) -> dict:
    """A study's options: the full (or, with ``quick``, the quick) defaults overridden by ``given``.

    ``given`` holds the ``run`` arguments; None means "the mode's default". Every number of the
    result (also inside lists) must be finite and positive -- sizes, times, steps, tolerances --,
    or zero for the options in ``zero_allowed`` ("0: none"); options in ``unchecked`` are not
    checked. Checked here, before any work, so that a bad option is one clear error.

    Raises
    ------
    OptionError
        Naming the option, the rule and the value.
    """
    base = dict(full, **quick_defaults) if quick else dict(full)
    unknown = [k for k in given if k not in base]
    if unknown:
        raise TypeError(f"unknown study options {unknown}; known: {sorted(base)}")
    out = {k: (given[k] if given.get(k) is not None else v) for k, v in base.items()}
    for k, value in out.items():
        if k in unchecked:
            continue
        for x in _numbers(value):
            if not math.isfinite(x) or x < 0 or (x == 0 and k not in zero_allowed):
                rule = "non-negative (0: none)" if k in zero_allowed else "positive"
                raise OptionError(f"`{k}` (--{k.replace('_', '-')}) must be {rule} and finite, got {value!r}.")
    return out
