"""The ``ancfdae`` command: ``ancfdae study NAME [options]``, ``ancfdae studies``."""
from __future__ import annotations

import argparse
import importlib
import inspect
import pkgutil
import sys

__all__ = ["main"]


def _studies() -> list[str]:
    import ancfdae.studies as pkg
    return sorted(m.name for m in pkgutil.iter_modules(pkg.__path__) if not m.name.startswith("_"))


def _load(name: str):
    names = _studies()
    if name not in names:
        raise SystemExit(f"ancfdae: unknown study {name!r}; available: {', '.join(names)}")
    return importlib.import_module(f"ancfdae.studies.{name}")


def main(argv=None) -> int:
    """Entry point of the console script."""
    parser = argparse.ArgumentParser(prog="ancfdae", description="ANCF beam dynamics: run the studies.")
    sub = parser.add_subparsers(dest="command", required=True)
    st = sub.add_parser("study", help="run a study (writes markdown tables and PNG figures)")
    st.add_argument("name", help="study name (see `ancfdae studies`)")
    st.add_argument("--quick", action="store_true", help="small, fast version (what the tests run)")
    st.add_argument("--out", default=None, help="output folder (default out/NAME)")
    st.add_argument("--jobs", type=int, default=None, help="parallel worker processes for sweeps")
    sub.add_parser("studies", help="list the studies")
    args = parser.parse_args(argv)
    if args.command == "studies":
        for name in _studies():
            doc = (_load(name).__doc__ or "").strip().splitlines()
            print(f"{name:14s} {doc[0] if doc else ''}")
        return 0
    module = _load(args.name)
    options = {"quick": args.quick, "out": args.out}
    if args.jobs is not None:
        if "jobs" not in inspect.signature(module.run).parameters:
            raise SystemExit(f"ancfdae: study {args.name!r} runs serially; it has no --jobs option")
        if args.jobs < 1:
            raise SystemExit(f"ancfdae: --jobs must be a positive integer, got {args.jobs}")
        options["jobs"] = args.jobs
    result = module.run(**options)
    if result.get("table"):
        print(result["table"])
    if result.get("path") is not None:
        print(f"results written to {result['path']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
