"""The geometry of BE3D's nodal directors along a run (:class:`DirectorGeometry`, chapter Eq. 99)."""
from __future__ import annotations

from typing import Any

import numpy as np

from ancfdae import _validate as validate
from ancfdae.models.thin.be3d_directors import director_geometry
from ancfdae.models.thin.be3d_kinematics import TorsionRule
from ancfdae.monitors.base import Monitor

__all__ = ["DirectorGeometry"]


class DirectorGeometry(Monitor):
    """The geometry of BE3D's nodal directors at the output times (chapter Sect. 3.6, Eq. 99).

    BE3D interpolates the director linearly inside an element. When the two nodal directors drift apart the
    interpolated one shrinks, the projection of Eq. 99 degenerates inside the element and the interior
    frames turn fast: the energy of a director update grows with it. Logged per output time:
    ``max_angle`` (degrees), the largest angle between the nodal directors of an element, and
    ``min_projection``, the smallest length of Eq. 99's unnormalised projection ``|d - (d.e1) e1|`` over
    ``points`` equidistant points of every element (1 for a director normal to the axis, 0 where the frame
    is undefined), with the elements where they occur (``max_angle_element``, ``min_projection_element``).

    Parameters
    ----------
    points : int
        Points per element, ends included (>= 2; default 9, the midpoint among them).
    name : str
        Key in ``Result.monitors``.
    """

    def __init__(self, points: int = 9, name: str = "directors") -> None:
        self.points = validate.positive_int("points", points)
        if self.points < 2:
            raise ValueError(f"`points` must be at least 2 (the element's ends), got {points!r}.")
        self.name = str(name)
        self._rows = []         # (a failed start still logs: nothing)

    def start(self, model: Any, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        geom = getattr(model, "geom", None)
        if not isinstance(geom, dict) or "directors" not in geom:
            raise TypeError(f"DirectorGeometry needs a beam of BE3D-type elements (model.geom['directors']); "
                            f"{type(model).__name__} has none.")
        self.model = model
        self._rule = TorsionRule(np.linspace(-1.0, 1.0, self.points), geom["L"])
        self._rows = []

    def sample(self, t: float, q: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        m = self.model
        angle, proj = director_geometry(m.geom["directors"], m.expand(q)[m.edofs], self._rule)
        i, j = int(np.argmax(angle)), int(np.argmin(proj))
        self._rows.append((np.degrees(angle[i]), i, proj[j], j))

    def log(self) -> dict:
        rows = np.array(self._rows, dtype=float).reshape(-1, 4)
        return {"max_angle": rows[:, 0], "max_angle_element": rows[:, 1].astype(int),
                "min_projection": rows[:, 2], "min_projection_element": rows[:, 3].astype(int)}
