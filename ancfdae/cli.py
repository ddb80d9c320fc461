"""The ``ancfdae`` command: ``ancfdae study NAME [options]``, ``ancfdae studies``."""
from __future__ import annotations

import argparse
import importlib
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
    st = sub.add_parser("study", help="run a study (see `ancfdae study NAME --help` for its options)",
                        add_help=False)
    st.add_argument("name", help="study name (see `ancfdae studies`)")
    st.add_argument("options", nargs=argparse.REMAINDER, help="the study's options")
    sub.add_parser("studies", help="list the studies")
    args = parser.parse_args(argv)
    if args.command == "studies":
        for name in _studies():
            doc = (_load(name).__doc__ or "").strip().splitlines()
            print(f"{name:14s} {doc[0] if doc else ''}")
        return 0
    from ancfdae.studies import _cli
    return _cli.main(_load(args.name), args.options, prog=f"ancfdae study {args.name}")


if __name__ == "__main__":
    sys.exit(main())
