"""What every joint shares: its sides, their frames in the system's coordinates, and the base class.

A side is ``"ground"`` or ``(body, where)``: ``body`` one of the :class:`~ancfdae.System`'s bodies (the object
itself) and ``where`` what the body's ``attachment(where)`` takes (a beam: a node index, an arc length as a
float or ``{"s": float}``). :class:`Frame` is a side resolved by the system: its point and frame vectors as
:class:`~ancfdae.joints.rows.Affine` maps of the system's coordinates. A joint turns its frames into
constraint rows (:meth:`Joint.rows`); joints to the ground take the ground's point (and vectors) from the other
side in the initial configuration unless given.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ancfdae.joints.rows import Affine, Rows

__all__ = ["Joint", "Frame", "GROUND", "check_side"]

GROUND = "ground"


def check_side(arg: str, side) -> object:
    """``side`` checked for its form: ``"ground"`` or a pair ``(body, where)``."""
    if isinstance(side, str):
        if side != GROUND:
            raise ValueError(f"`{arg}` must be 'ground' or a pair (body, where), got {side!r}.")
        return side
    if not isinstance(side, tuple) or len(side) != 2:
        raise ValueError(f"`{arg}` must be 'ground' or a pair (body, where) such as (beam, 0) or "
                         f"(beam, {{'s': 0.5}}), got {side!r:.200}.")
    return side


@dataclass(frozen=True)
class Frame:
    """A side of a joint in the system's coordinates.

    Attributes
    ----------
    point : Affine or None
        The point (None for the ground).
    axes : tuple of Affine
        The frame vectors (empty for the ground).
    label : str
        ``"body 0 node 3"`` or ``"ground"``.
    dim : int or None
        Spatial dimension (None for the ground).
    """

    point: Affine | None
    axes: tuple
    label: str
    dim: int | None

    @property
    def ground(self) -> bool:
        """True for the ground."""
        return self.point is None


class Joint(ABC):
    """Base of the joints: two sides (or one), a name, and the rows they contribute.

    Subclasses implement :meth:`rows`. ``name`` labels the rows (``"name[k]"``) in redundancy reports,
    ``Result.constraint_labels`` and the drift monitor.
    """

    #: dimensions the joint applies to
    dims: tuple[int, ...] = (2, 3)
    kind = "joint"

    def __init__(self, sides: tuple, name: str | None = None) -> None:
        self.sides = tuple(check_side(arg, s) for arg, s in sides)
        self.side_args = tuple(arg for arg, _ in sides)
        if name is not None and not isinstance(name, str):
            raise ValueError(f"`name` must be a string, got {name!r}.")
        self.name = name

    def label(self, frames: tuple[Frame, ...]) -> str:
        """The joint's name, or ``"Kind(side a, side b)"``."""
        return self.name or f"{self.kind}({', '.join(f.label for f in frames)})"

    def check_dim(self, frames: tuple[Frame, ...]) -> int:
        """The joint's dimension: the bodies' (equal), one this joint applies to."""
        dims = {f.dim for f in frames if not f.ground}
        if not dims:
            raise ValueError(f"{self.kind} joint {self.name or ''}: at least one side must be a body, "
                             "got 'ground' on every side.")
        if len(dims) > 1:
            raise ValueError(f"{self.label(frames)} joins a {min(dims)}D and a {max(dims)}D body: the sides of a "
                             "joint must have the same dimension.")
        dim = dims.pop()
        if dim not in self.dims:
            raise ValueError(f"{self.label(frames)}: a {self.kind} joint applies to "
                             f"{' and '.join(f'{d}D' for d in self.dims)} bodies, got a {dim}D body.")
        return dim

    @abstractmethod
    def rows(self, frames: tuple[Frame, ...], q0: np.ndarray, n: int) -> Rows:
        """The joint's constraint rows in the system's ``n`` coordinates.

        Parameters
        ----------
        frames : tuple of Frame
            The sides, resolved by the system, in the order given to the constructor.
        q0 : ndarray, shape (n,)
            The system's initial coordinates (the ground's point and vectors default to the other side's).
        n : int
            Number of coordinates.
        """


def vector(arg: str, value, dim: int, *, unit: bool = False) -> np.ndarray:
    """A finite vector of ``dim`` components (normalised when ``unit``), or a clear error."""
    try:
        x = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise ValueError(f"`{arg}` must be a vector of {dim} numbers, got {value!r}.") from None
    if x.shape != (dim,) or not np.all(np.isfinite(x)):
        raise ValueError(f"`{arg}` must be a finite vector of {dim} numbers for a {dim}D joint, got {value!r}.")
    if unit:
        norm = np.linalg.norm(x)
        if norm == 0:
            raise ValueError(f"`{arg}` must be a non-zero vector, got {value!r}.")
        x = x / norm
    return x


def constant(x: np.ndarray, n: int) -> Affine:
    """The constant vector ``x`` as an Affine map (the ground's points and vectors)."""
    return Affine(sp.csr_matrix((x.size, n)), np.asarray(x, dtype=float))


def normals(u: np.ndarray) -> np.ndarray:
    """An orthonormal basis of the plane normal to the unit vector ``u`` (rows), shape (dim - 1, dim)."""
    if u.size == 2:
        return np.array([[-u[1], u[0]]])
    a = np.eye(3)[int(np.argmin(np.abs(u)))]
    n1 = np.cross(u, a)
    n1 /= np.linalg.norm(n1)
    return np.array([n1, np.cross(u, n1)])


def axis(frame: Frame, arg: str, index) -> Affine:
    """The frame vector ``index`` of a body side, with a clear error."""
    if isinstance(index, (bool, np.bool_)) or not isinstance(index, (int, np.integer)) \
            or not 0 <= index < len(frame.axes):
        raise ValueError(f"`{arg}` must index a frame vector of {frame.label} (0 to {len(frame.axes) - 1}), "
                         f"got {index!r}.")
    return frame.axes[int(index)]
