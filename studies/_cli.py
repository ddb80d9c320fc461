"""Command line of one study: ``ancfdae study NAME [--quick] [--out DIR] [--jobs N] [study options]``.

Each study module lists its command-line options in ``CLI_OPTIONS`` (a list
of :class:`Option`) and its defaults in ``FULL`` and ``QUICK`` (dicts keyed by
the ``run`` parameter); ``--help`` shows both. An option given on the command
line overrides the mode's default.
"""
from __future__ import annotations

import argparse
import inspect
import signal
import sys
import threading
from dataclasses import dataclass

from ._common import Interrupted, OptionError

__all__ = ["Option", "parser", "main"]


@dataclass(frozen=True)
class Option:
    """One study option: ``run`` parameter ``name``, value type, ``nargs`` ("+" for a list) and help text."""

    name: str
    type: type
    help: str
    nargs: str | None = None
    choices: tuple | None = None


def _fmt(value) -> str:
    if isinstance(value, (list, tuple)):
        return " ".join(_fmt(v) for v in value) if value else "(none)"
    if value is None:
        return "(none)"
    return f"{value:g}" if isinstance(value, float) else str(value)


def _study_name(module) -> str:
    """``NAME`` of a study module, else the last part of its module name, also when it runs as ``__main__``."""
    spec = getattr(module, "__spec__", None)      # `python -m ancfdae.studies.X`: __name__ is "__main__"
    return getattr(module, "NAME", (spec.name if spec is not None else module.__name__).rsplit(".", 1)[-1])


def parser(module, prog: str | None = None) -> argparse.ArgumentParser:
    """The argument parser of a study module (its options, with the full and the quick defaults)."""
    name = _study_name(module)
    doc = (module.__doc__ or name).strip().splitlines()[0]
    p = argparse.ArgumentParser(prog=prog or f"ancfdae study {name}", description=doc)
    p.add_argument("--quick", action="store_true", help="small, fast version (what the tests run)")
    p.add_argument("--out", default=None,
                   help=f"output folder; a rerun with the same folder reuses its finished cases "
                        f"(default: out/{name}, with --quick out/{name}-quick)")
    if _takes_jobs(module):
        p.add_argument("--jobs", type=int, default=None,
                       help="worker processes for the sweep (default: 1, serial, timings undisturbed)")
    else:       # accepted as 1 so that the common synopsis holds; more is refused with the reason
        p.add_argument("--jobs", type=int, default=None,
                       help="only 1: this study runs its cases serially (its CPU times are its result)")
    full, quick = getattr(module, "FULL", {}), getattr(module, "QUICK", {})
    for opt in getattr(module, "CLI_OPTIONS", ()):
        default = f"default: {_fmt(full.get(opt.name))}"
        if opt.name in quick and quick[opt.name] != full.get(opt.name):
            default += f"; with --quick: {_fmt(quick[opt.name])}"
        p.add_argument("--" + opt.name.replace("_", "-"), dest=opt.name, type=opt.type, nargs=opt.nargs,
                       choices=opt.choices, default=None, help=f"{opt.help} ({default})")
    return p


def _takes_jobs(module) -> bool:
    return "jobs" in inspect.signature(module.run).parameters


def _terminate(signum, frame):
    raise KeyboardInterrupt


def main(module, argv=None, prog: str | None = None) -> int:
    """Parse ``argv``, run the study, print its table; return the exit status.

    0 when every case finished, 1 when a case failed (the others are kept and shown), 2 for a bad
    option (said before any work), 130 after Ctrl-C.
    """
    p = parser(module, prog)
    args = vars(p.parse_args(argv))
    if args.get("jobs") is not None and args["jobs"] < 1:
        p.error(f"--jobs must be a positive integer, got {args['jobs']}")
    if not _takes_jobs(module):
        if args.get("jobs") not in (None, 1):
            p.error(f"--jobs must be 1 for this study, got {args['jobs']}: it runs its cases serially because their "
                    "CPU times are its result (the other studies take --jobs N)")
        args.pop("jobs", None)
    options = {k: v for k, v in args.items() if v is not None and k not in ("quick",)}
    previous = None
    if threading.current_thread() is threading.main_thread():
        # `kill PID` (SIGTERM) stops a study like Ctrl-C: finished cases kept, workers stopped, exit 130
        previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        result = module.run(quick=args["quick"], **options)
    except Interrupted as exc:
        print(exc, file=sys.stderr)
        return 130
    except KeyboardInterrupt:
        print(f"{p.prog} interrupted.", file=sys.stderr)
        return 130
    except OptionError as exc:          # bad options (e.g. --out an existing file): said at once, before any work
        print(f"{p.prog}: error: {exc}", file=sys.stderr)     # one line (`--help` shows the options)
        return 2
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)
    if result.get("table"):
        print(result["table"])
    if result.get("path") is not None:
        print(f"results written to {result['path']}")
    errors = result.get("errors") or {}
    if errors:        # the finished cases are kept and shown; the command still says it did not all work
        print(f"{p.prog}: {len(errors)} case(s) failed: {', '.join(errors)} (the reasons are in the table's notes); "
              "exit status 1", file=sys.stderr)
        return 1
    return 0
