"""The store of a study's finished cases: keyed on what defines a case, written atomically, verified on reuse.

A stored case is reused only when its *key* matches: the SHA-256 of the case's options, the
definition of the computation (the source of the case function's module and of the modules of its
package that it uses) and the package version. Its record (JSON) carries a digest of itself and the
SHA-256 of its Result file, whose name contains the key (a run with other options never writes over
it); the Result file carries its own checksums (:mod:`ancfdae._filecheck`). Anything that does not
match -- other options, changed code, another version, a damaged record or file, a file computed by
an interrupted run with other options -- makes the case run again, and :attr:`CaseStore.notes` says
why (the runner prints it).
"""
from __future__ import annotations

import hashlib
import inspect
import json
import os
import re
import sys
from pathlib import Path

from ancfdae import __version__
from ancfdae.result import Result, ResultFileError

__all__ = ["CaseStore", "definition_hash", "jsonable"]


def jsonable(obj):
    """Plain Python (lists, floats, ...) of ``obj`` for JSON; numpy scalars and arrays converted."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if hasattr(obj, "tolist"):
        return obj.tolist()
    return obj


def _stem(label: str) -> str:
    """A file name from a case label ("BE2D 8 el (reference)" -> "BE2D_8_el_reference")."""
    return re.sub(r"[^A-Za-z0-9.+-]+", "_", label).strip("_")


def _sha(text) -> str:
    return hashlib.sha256(text if isinstance(text, bytes) else text.encode()).hexdigest()


def definition_hash(fn) -> str:
    """SHA-256 of the source of ``fn``'s module and of the modules of its package it uses.

    The case function's module defines the benchmark (model, loads, integrator settings); its
    package's helper modules that it imports (e.g. the flying beams' shared definitions) too.
    """
    module = sys.modules.get(getattr(fn, "__module__", ""), None)
    if module is None:
        return _sha(repr(fn))
    package = module.__name__.rpartition(".")[0] or module.__name__
    used = {module.__name__}
    for obj in vars(module).values():
        name = obj.__name__ if inspect.ismodule(obj) else getattr(obj, "__module__", None)
        if isinstance(name, str) and name.startswith(package + ".") and name in sys.modules:
            used.add(name)
    texts = []
    for name in sorted(used):
        try:
            texts.append(name + "\n" + inspect.getsource(sys.modules[name]))
        except (OSError, TypeError):
            texts.append(name)
    return _sha("\n".join(texts))


class CaseStore:
    """The finished cases of a study in ``folder/cases``.

    Per case two files: the simulation's :class:`ancfdae.Result` (``STEM-KEY.nc``, written by
    :meth:`Result.save`) and ``STEM.json``: the case's options, its key, its scalars (CPU time,
    counters, ...), the Result file's name and SHA-256, and a digest of the record. Both are
    written to a temporary name and renamed, the JSON last, so a case counts as finished only
    once both files are complete. A case whose function raised is kept as ``STEM.json`` with
    ``"error"``; it is run again on the next run.

    Parameters
    ----------
    folder : path
        The study's output folder.
    fn : callable, optional
        The case function, whose definition (:func:`definition_hash`) enters the key.
    """

    def __init__(self, folder, fn=None):
        self.folder = Path(folder) / "cases"
        self.folder.mkdir(parents=True, exist_ok=True)
        self.definition = definition_hash(fn) if fn is not None else ""
        #: why stored cases were not reused (one line per case), for the runner to print
        self.notes: list[str] = []

    def key(self, case) -> str:
        """SHA-256 of the case's options, the computation's definition and the package version."""
        return _sha(json.dumps({"case": jsonable(dict(case)), "definition": self.definition,
                                "version": __version__}, sort_keys=True, allow_nan=True))

    def _json(self, case) -> Path:
        return self.folder / (_stem(str(case)) + ".json")

    def _stale(self, case, why: str) -> None:
        self.notes.append(f"case {str(case)!r}: {why}; computing it again")
        return None

    def load(self, case):
        """The stored record of ``case`` (a dict with ``"result"``), or None if absent, failed or not matching."""
        path = self._json(case)
        if not path.is_file():
            return None
        try:
            meta = json.loads(path.read_text())
            body = {k: v for k, v in meta.items() if k != "digest"}
            intact = meta.get("digest") == _sha(json.dumps(body, sort_keys=True, allow_nan=True))
        except (OSError, ValueError, AttributeError) as exc:
            return self._stale(case, f"its stored record {path.name} is unreadable ({exc})")
        if not intact:
            return self._stale(case, f"its stored record {path.name} does not match its digest (damaged or edited)")
        if "error" in meta:
            return None        # a failure: run it again
        if meta.get("key") != self.key(case):
            return self._stale(case, "it was stored with other options, another definition of the computation "
                                     "or another package version")
        file = self.folder / str(meta.get("file"))
        try:
            data = file.read_bytes()
        except OSError as exc:
            return self._stale(case, f"its Result file cannot be read ({exc})")
        if _sha(data) != meta.get("file_sha256"):
            return self._stale(case, f"its Result file {file.name} is not the one its record was written with")
        try:
            result = Result.load(file)
        except ResultFileError as exc:
            return self._stale(case, str(exc))
        return dict(meta["record"], result=result)

    def save(self, case, record: dict) -> Path:
        """Write ``record`` (``"result"``: a Result; other entries JSON-able scalars) of ``case``."""
        key = self.key(case)
        file = Path(record["result"].save(self.folder / f"{_stem(str(case))}-{key[:16]}.nc"))
        scalars = {k: v for k, v in record.items() if k != "result"}
        return self._write(case, {"case": jsonable(dict(case)), "key": key, "file": file.name,
                                  "file_sha256": _sha(file.read_bytes()), "record": jsonable(scalars)})

    def save_error(self, case, error: str) -> Path:
        """Record that ``case`` raised (``error``: the exception's text)."""
        return self._write(case, {"case": jsonable(dict(case)), "key": self.key(case), "error": error})

    def _write(self, case, meta) -> Path:
        meta = dict(meta, digest=_sha(json.dumps(meta, sort_keys=True, allow_nan=True)))
        path = self._json(case)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps(meta, indent=1, allow_nan=True))
        os.replace(tmp, path)
        return path
