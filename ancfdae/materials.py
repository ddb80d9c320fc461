"""Material law parameters and cross-section properties.

The cross-section lies in the (eta, zeta) plane of the reference
configuration (chapter Eq. 1): ``eta`` along ``e_y``, ``zeta`` along ``e_z``.
Following chapter Eq. 42, ``I2`` is the second moment about the local axis 2
(``int zeta^2 dA``, bending out of the (x, y) plane) and ``I3`` the one about
axis 3 (``int eta^2 dA``, bending in the (x, y) plane -- the planar case).
"""
from __future__ import annotations

import math
import numbers
from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from ._validate import positive

__all__ = ["Material", "Section", "RectangularSection", "CircularSection", "cowper_shear_factor"]


def cowper_shear_factor(nu: float) -> float:
    """Cowper's shear correction factor of a rectangle, chapter Eq. 112.

    Parameters
    ----------
    nu : float
        Poisson's ratio.

    Returns
    -------
    float
        ``k_s = 10 (1 + nu) / (12 + 11 nu)``; 0.8496732026143791 for nu = 0.3.
    """
    return 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu)


@dataclass(frozen=True)
class Material:
    """Linear elastic isotropic material.

    Parameters
    ----------
    E : float
        Young's modulus (> 0).
    nu : float
        Poisson's ratio, in [0, 0.5).
    rho : float
        Density (> 0).
    """

    E: float
    nu: float
    rho: float

    def __post_init__(self):
        # Stored as Python floats: numpy scalars (np.float32(0.3)) are numbers too, and a float32
        # kept as is would carry single precision into every stiffness computed from it.
        object.__setattr__(self, "E", positive("E", self.E))
        object.__setattr__(self, "rho", positive("rho", self.rho))
        nu = self.nu
        if (isinstance(nu, bool) or not isinstance(nu, numbers.Real) or not np.isfinite(nu)
                or not 0.0 <= nu < 0.5):
            raise ValueError(f"`nu` must be a number in [0, 0.5), got {nu!r}.")
        object.__setattr__(self, "nu", float(nu))

    @property
    def G(self) -> float:
        """Shear modulus ``E / (2 (1 + nu))`` (chapter Eq. 112)."""
        return self.E / (2.0 * (1.0 + self.nu))


def _saint_venant_rectangle(h: float, b: float, terms: int = 50) -> float:
    """Saint-Venant torsion constant of an h x b rectangle (series solution)."""
    long, short = max(h, b), min(h, b)
    s = sum(math.tanh(n * math.pi * long / (2 * short)) / n**5 for n in range(1, 2 * terms, 2))
    return long * short**3 / 3.0 * (1.0 - 192.0 / math.pi**5 * short / long * s)


class Section(ABC):
    """A cross-section: what every shape shares, the polar moment and the shear and torsion factors.

    A shape is a frozen dataclass subclass that declares its dimensions and
    the three factor fields ``shear_factor``, ``torsion_factor`` and
    ``shear_factors`` (each None by default), and defines the area ``A``,
    the moments ``I2``, ``I3``, ``I4`` (chapter Eq. 42, Eq. 85),
    ``_check_dimensions()`` and its default factors
    ``_default_shear_factor(nu)`` and ``_default_torsion_factor()``:
    :class:`RectangularSection` and :class:`CircularSection` are the two
    shapes of the package. The factor fields are checked here once for
    every shape (positive; a pair ``(k2, k3)`` or one ``k_s``, not both).
    """

    shear_factor: float | None
    torsion_factor: float | None
    shear_factors: tuple | None

    def __post_init__(self):
        self._check_dimensions()
        for name in ("shear_factor", "torsion_factor"):   # stored as floats (numpy scalars are numbers)
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, positive(name, value))
        pair = self.shear_factors
        if pair is None:
            return
        if self.shear_factor is not None:
            raise ValueError("give either `shear_factor` (k2 = k3) or `shear_factors` (k2, k3), not both; got "
                             f"shear_factor={self.shear_factor!r}, shear_factors={pair!r}.")
        if isinstance(pair, (str, bytes)) or not hasattr(pair, "__len__") or len(pair) != 2:
            raise ValueError(f"`shear_factors` must be a pair (k2, k3) of positive numbers, got {pair!r}.")
        object.__setattr__(self, "shear_factors",
                           (positive("shear_factors[0]", pair[0]), positive("shear_factors[1]", pair[1])))

    @property
    @abstractmethod
    def A(self) -> float:
        """Area."""

    @property
    @abstractmethod
    def I2(self) -> float:
        """``int zeta^2 dA`` (bending out of the x-y plane)."""

    @property
    @abstractmethod
    def I3(self) -> float:
        """``int eta^2 dA`` (bending in the x-y plane)."""

    @property
    @abstractmethod
    def I4(self) -> float:
        """``int eta^4 dA`` (enters the SVK bending moment, chapter Eq. 85)."""

    @abstractmethod
    def _check_dimensions(self) -> None:
        """Check (and store as floats) the shape's dimensions."""

    @abstractmethod
    def _default_shear_factor(self, nu: float) -> float:
        """``k_s`` of the shape when none is given (Cowper's for the package's shapes)."""

    @abstractmethod
    def _default_torsion_factor(self) -> float:
        """``k_t`` of the shape when none is given: its torsion constant over ``J``."""

    @property
    def J(self) -> float:
        """Polar moment ``I2 + I3``."""
        return self.I2 + self.I3

    def k_s(self, material: Material) -> float:
        """The common shear correction factor ``k2 = k3`` (the shape's default when none is given).

        Parameters
        ----------
        material : Material
            Its ``nu`` enters the default (Cowper's) factor.

        Returns
        -------
        float

        Raises
        ------
        ValueError
            If the section has two different factors ``shear_factors``; use
            :meth:`shear_factors_of` then.
        """
        if self.shear_factors is not None:
            k2, k3 = self.shear_factors
            if k2 != k3:
                raise ValueError(f"this section has two shear factors, shear_factors={self.shear_factors!r}; "
                                 "use `shear_factors_of(material)` instead of `k_s`.")
            return k2
        return self.shear_factor if self.shear_factor is not None else self._default_shear_factor(material.nu)

    def shear_factors_of(self, material: Material) -> tuple[float, float]:
        """``(k2, k3)``: the shear factors along ``eta`` and ``zeta`` (chapter Eq. 42).

        Parameters
        ----------
        material : Material

        Returns
        -------
        (float, float)
        """
        if self.shear_factors is not None:
            return self.shear_factors
        k = self.k_s(material)
        return k, k

    @property
    def k_t(self) -> float:
        """Torsion factor ``k_t``: the torsional rigidity is ``G J k_t`` (the shape's default when none is given)."""
        return self.torsion_factor if self.torsion_factor is not None else self._default_torsion_factor()


@dataclass(frozen=True)
class RectangularSection(Section):
    """Rectangular cross-section, ``h`` along ``eta`` (e_y) and ``b`` along ``zeta`` (e_z).

    ``J``, ``k_s``, ``shear_factors_of`` and ``k_t`` are those of every
    :class:`Section`.

    Parameters
    ----------
    h, b : float
        Side lengths (> 0); ``b`` defaults to ``h`` (square).
    shear_factor : float, optional
        One shear correction factor ``k_s`` for both transverse shears
        (``k2 = k3 = k_s``); None selects Cowper's value of chapter Eq. 112 for
        the material's ``nu``.
    torsion_factor : float, optional
        ``k_t`` such that the torsional rigidity is ``G J k_t`` with
        ``J = I2 + I3``; None selects the Saint-Venant value (0.8436 for a
        square). Nachbagauer et al. (2013) call it ``k1`` (0.5768 for their
        0.2 x 0.4 section).
    shear_factors : (float, float), optional
        ``(k2, k3)``: separate factors for the shear along ``eta`` (``Gamma_2``,
        stiffness ``k2 G A``) and along ``zeta`` (``Gamma_3``, ``k3 G A``),
        chapter Eq. 42; e.g. ``(0.8331, 0.7961)`` in Nachbagauer et al. (2013).
        Not together with ``shear_factor``. The planar elements use ``k2``.
    """

    h: float
    b: float | None = None
    shear_factor: float | None = None
    torsion_factor: float | None = None
    shear_factors: tuple | None = None

    def _check_dimensions(self) -> None:
        object.__setattr__(self, "h", positive("h", self.h))
        if self.b is None:
            object.__setattr__(self, "b", self.h)
        object.__setattr__(self, "b", positive("b", self.b))

    @property
    def A(self) -> float:
        """Area."""
        return self.h * self.b

    @property
    def I2(self) -> float:
        """``int zeta^2 dA = h b^3 / 12`` (bending out of the x-y plane)."""
        return self.h * self.b**3 / 12.0

    @property
    def I3(self) -> float:
        """``int eta^2 dA = b h^3 / 12`` (bending in the x-y plane)."""
        return self.b * self.h**3 / 12.0

    @property
    def I4(self) -> float:
        """``int eta^4 dA = b h^5 / 80`` (enters the SVK bending moment, chapter Eq. 85)."""
        return self.b * self.h**5 / 80.0

    def _default_shear_factor(self, nu: float) -> float:
        return cowper_shear_factor(nu)

    def _default_torsion_factor(self) -> float:
        return _saint_venant_rectangle(self.h, self.b) / self.J


@dataclass(frozen=True)
class CircularSection(Section):
    """Solid circular cross-section.

    ``k_t = 1`` (the polar moment is the torsion constant); the default shear
    factor is ``6 (1 + nu) / (7 + 6 nu)`` (Cowper, solid circle). ``J``,
    ``k_s``, ``shear_factors_of`` and ``k_t`` are those of every :class:`Section`.

    Parameters
    ----------
    d : float
        Diameter (> 0).
    shear_factor : float, optional
        Shear correction factor ``k_s`` (k2 = k3); None selects Cowper's.
    torsion_factor : float, optional
        ``k_t``; None selects 1.
    shear_factors : (float, float), optional
        ``(k2, k3)`` along ``eta`` and ``zeta`` instead of one ``shear_factor``
        (as for :class:`RectangularSection`).
    """

    d: float
    shear_factor: float | None = None
    torsion_factor: float | None = None
    shear_factors: tuple | None = None

    def _check_dimensions(self) -> None:
        object.__setattr__(self, "d", positive("d", self.d))

    @property
    def A(self) -> float:
        """Area ``pi d^2 / 4``."""
        return math.pi * self.d**2 / 4.0

    @property
    def I2(self) -> float:
        """``int zeta^2 dA = pi d^4 / 64``."""
        return math.pi * self.d**4 / 64.0

    @property
    def I3(self) -> float:
        """``int eta^2 dA``, equal to ``I2``."""
        return self.I2

    @property
    def I4(self) -> float:
        """``int eta^4 dA = pi d^6 / 512``."""
        return math.pi * self.d**6 / 512.0

    def _default_shear_factor(self, nu: float) -> float:
        return 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)      # Cowper, solid circle

    def _default_torsion_factor(self) -> float:
        return 1.0      # the polar moment is the torsion constant of a solid circle
