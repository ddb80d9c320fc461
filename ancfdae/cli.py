"""The ``ancfdae`` command.

``ancfdae study NAME [options]`` runs a study, ``ancfdae studies`` lists them,
``ancfdae export vtk RESULT DIR`` writes ParaView files of a result file,
``ancfdae animate RESULT OUT.gif`` an animation, ``ancfdae --version``.
``python -m ancfdae`` is the same command.

The result files carry the description of their beam (element, material,
section, mesh, supports), so the export and the animation rebuild the beam from
the file alone: a user holding only ``result.nc`` gets the pictures, with no
script to find and no ``--model`` argument to get right.
"""
from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys
from pathlib import Path

from . import __version__
from . import _validate as validate
from .export import vtk
from .plot import animate
from .result import Result, ResultFileError

__all__ = ["main"]


def _studies_package():
    """``ancfdae.studies``, or a clear exit where the package was imported from a checkout not installed."""
    try:
        return importlib.import_module("ancfdae.studies")
    except ModuleNotFoundError as exc:
        if exc.name != "ancfdae.studies":
            raise
        # The studies folder becomes ancfdae.studies only by installation (pyproject's package-dir).
        raise SystemExit(f"ancfdae: the studies are not importable: ancfdae was imported from "
                         f"{Path(__file__).parent}, a source checkout that is not installed; run "
                         "`pip install -e .` in it, or run from another folder.") from None


def _studies() -> list[str]:
    pkg = _studies_package()
    return sorted(m.name for m in pkgutil.iter_modules(pkg.__path__) if not m.name.startswith("_"))


def _load(name: str):
    names = _studies()
    if name not in names:
        raise SystemExit(f"ancfdae: unknown study {name!r}; available: {', '.join(names)}")
    return importlib.import_module(f"ancfdae.studies.{name}")


def _load_result(path: str):
    try:
        return Result.load(path)
    except ResultFileError as exc:
        raise SystemExit(f"ancfdae: {exc}") from None


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {value}")
    return value


def _user_error(what: str, exc: Exception):
    """The one line for a user's error (a bad path, a result without a beam): no traceback."""
    text = str(exc) if isinstance(exc, ValueError) else f"{type(exc).__name__}: {exc}"
    return SystemExit(f"ancfdae {what}: {text}")


def _export(args) -> int:
    result = _load_result(args.result)
    try:
        pvd = vtk(result, None, args.directory, name=args.name, every=args.every)
    except (ValueError, OSError) as exc:      # the arguments are named by the message (`directory`, `name`)
        raise _user_error("export vtk", exc) from None
    print(f"ParaView time series written to {pvd}")
    return 0


def _animate(args) -> int:
    try:
        validate.output_file("path", args.output, (".gif",))    # before the (slow) load and drawing
    except ValueError as exc:
        raise _user_error("animate", exc) from None
    result = _load_result(args.result)
    try:
        out = animate(result, args.output, every=args.every, fps=args.fps)
    except (ValueError, OSError) as exc:      # `path` is the OUTPUT argument
        raise _user_error("animate", exc) from None
    print(f"animation written to {out}")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script and of ``python -m ancfdae``.

    Parameters
    ----------
    argv : list of str, optional
        Arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        Exit status: 0, or a study's (1 when one of its cases failed); a user's error exits
        through :class:`SystemExit` with a one-line message (status 1, 2 for a usage error).
    """
    parser = argparse.ArgumentParser(prog="ancfdae", description="ANCF beam dynamics: studies, result files, "
                                     "ParaView export and animations.")
    parser.add_argument("--version", action="version", version=f"ancfdae {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    st = sub.add_parser("study", help="run a study (see `ancfdae study NAME --help` for its options)",
                        add_help=False)
    st.add_argument("name", help="study name (see `ancfdae studies`)")
    st.add_argument("options", nargs=argparse.REMAINDER, help="the study's options")
    sub.add_parser("studies", help="list the studies")
    ex = sub.add_parser("export", help="export a result file (ParaView)")
    ex_sub = ex.add_subparsers(dest="format", required=True)
    vt = ex_sub.add_parser("vtk", help="write NAME.pvd + .vtu files of the beam as a solid")
    vt.add_argument("result", help="result file written by Result.save (.nc)")
    vt.add_argument("directory", help="output folder (created if missing)")
    vt.add_argument("--name", default="beam", help="base name of the files (default beam)")
    vt.add_argument("--every", type=_positive, default=1, help="write every N-th output (default 1)")
    an = sub.add_parser("animate", help="write an animated GIF of a result file")
    an.add_argument("result", help="result file written by Result.save (.nc)")
    an.add_argument("output", help="the .gif file to write (its folder must exist; an existing file is replaced)")
    an.add_argument("--every", type=_positive, default=1, help="draw every N-th output (default 1)")
    an.add_argument("--fps", type=_positive, default=20, help="frames per second (default 20)")
    args = parser.parse_args(argv)
    if args.command == "export":
        return _export(args)
    if args.command == "animate":
        return _animate(args)
    if args.command == "studies":
        for name in _studies():
            doc = (_load(name).__doc__ or "").strip().splitlines()
            print(f"{name:14s} {doc[0] if doc else ''}")
        return 0
    study = _load(args.name)
    from ancfdae.studies import _cli     # importable once _load found the study
    return _cli.main(study, args.options, prog=f"ancfdae study {args.name}")


if __name__ == "__main__":
    sys.exit(main())
