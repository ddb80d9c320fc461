"""Input checks shared by the package: each raises with the argument, the rule and the value."""
from __future__ import annotations

import functools
import inspect
import numbers
import os
from pathlib import Path

import numpy as np


def positive(name: str, value) -> float:
    """Return ``value`` as float; raise ValueError unless it is finite and > 0."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not np.isfinite(value) or value <= 0:
        raise ValueError(f"`{name}` must be a positive finite number, got {value!r}.")
    return float(value)


def nonnegative(name: str, value) -> float:
    """Return ``value`` as float; raise ValueError unless it is finite and >= 0."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or not np.isfinite(value) or value < 0:
        raise ValueError(f"`{name}` must be a non-negative finite number, got {value!r}.")
    return float(value)


def positive_int(name: str, value) -> int:
    """Return ``value`` as int; raise ValueError unless it is an integer >= 1."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or value < 1:
        raise ValueError(f"`{name}` must be a positive integer, got {value!r}.")
    return int(value)


def flag(name: str, value) -> bool:
    """Return ``value`` if it is True or False (numpy's bool too); raise ValueError otherwise."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"`{name}` must be True or False, got {value!r}.")
    return bool(value)


def finite_vector(name: str, value, size: int | None = None) -> np.ndarray:
    """Return ``value`` as a 1-D float array of finite entries (of length ``size`` if given)."""
    if isinstance(value, (str, bytes)) or np.asarray(value).dtype.kind in "USO" and any(
            isinstance(x, (str, bytes)) for x in np.asarray(value, dtype=object).ravel()):
        raise ValueError(f"`{name}` must be an array of numbers, got text: {value!r:.200}.")
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"`{name}` must be an array of numbers, got {value!r:.200}.") from None
    if arr.ndim != 1 or (size is not None and arr.shape[0] != size):
        want = f"shape ({size},)" if size is not None else "a 1-D array"
        raise ValueError(f"`{name}` must have {want}, got shape {arr.shape}.")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"`{name}` must be finite (no NaN or inf), got {arr.tolist()}.")
    return arr


def output_folder(name: str, value) -> Path:
    """Return ``value`` as a Path of a writable folder, created if missing; raise ValueError naming ``name``."""
    path = Path(value)
    if path.exists() and not path.is_dir():
        raise ValueError(f"`{name}` must be a folder, got {str(path)!r}, which is an existing file.")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"`{name}` must be a folder that can be created, got {str(path)!r} "
                         f"({exc.strerror or exc}).") from None
    if not os.access(path, os.W_OK):
        raise ValueError(f"`{name}` must be a writable folder, got {str(path)!r}.")
    return path


def output_file(name: str, value, suffixes: tuple = ()) -> Path:
    """Return ``value`` as a Path of a file that can be written (in an existing, writable folder; ending in
    one of ``suffixes`` when given); raise ValueError naming ``name`` otherwise. An existing file is replaced."""
    path = Path(value)
    if suffixes and path.suffix.lower() not in suffixes:
        raise ValueError(f"`{name}` must end in {' or '.join(suffixes)}, got {str(path)!r}.")
    if path.is_dir():
        raise ValueError(f"`{name}` must name a file, got {str(path)!r}, which is a folder.")
    folder = path.parent
    if not folder.is_dir():
        raise ValueError(f"`{name}` must be in an existing folder, got {str(path)!r}: the folder {str(folder)!r} "
                         + ("is a file." if folder.exists() else "does not exist."))
    if not os.access(folder, os.W_OK):
        raise ValueError(f"`{name}` must be in a writable folder, got {str(path)!r}.")
    return path


def file_stem(name: str, value) -> str:
    """Return ``value`` if it is a plain, non-empty file name (no folder part); raise ValueError otherwise."""
    if not isinstance(value, str) or not value or value in (".", "..") or Path(value).name != value \
            or "/" in value or os.sep in value:
        raise ValueError(f"`{name}` must be a plain file name (no folder part, not empty), got {value!r}.")
    return value


def choice(name: str, value, options) -> str:
    """Return ``value`` if it is one of ``options``; raise ValueError naming them otherwise."""
    if value not in options:
        raise ValueError(f"`{name}` must be one of {sorted(options)}, got {value!r}.")
    return value


def check_shape(name: str, value, shape: tuple, what: str = "") -> None:
    """Raise ValueError unless ``np.shape(value) == shape`` (a shape comparison, no copy).

    ``what`` says where the expected shape comes from, e.g. ``"n_dof = 16"``.
    """
    got = np.shape(value)
    if got != shape:
        why = f" ({what})" if what else ""
        raise ValueError(f"`{name}` must have shape {shape}{why}, got {got}.")


def renamed(old: str, new: str, why: str):
    """Decorator: a call with the keyword ``old`` raises a TypeError naming ``new`` and ``why``.

    On a class it wraps ``__init__`` (put it above ``@dataclass``). The signature shown to users is
    the new one; the old keyword only gets the explanation instead of Python's bare "unexpected
    keyword argument".
    """
    def wrap(obj):
        func = obj.__init__ if inspect.isclass(obj) else obj

        @functools.wraps(func)
        def call(*args, **kwargs):
            if old in kwargs:
                raise TypeError(f"`{old}` was renamed `{new}` ({why}); got {old}={kwargs[old]!r}.")
            return func(*args, **kwargs)
        if inspect.isclass(obj):
            obj.__init__ = call
            return obj
        return call
    return wrap
