"""Building blocks shared by the thin spatial elements Cable3D and BE3D (chapter Sects. 3.4-3.6).

Both interpolate the axis with the cubic Hermite functions of chapter Eq. 62,
``r = sum_k S_k q_k`` over the four 3-vectors ``(r_A, r'_A, r_B, r'_B)``;
they differ in where those vectors sit in the element coordinate vector
(BE3D inserts the torsion angle after each node's slope). ``dof_map[k, i]``
is the element coordinate of component ``i`` of Hermite vector ``k``.
"""
from __future__ import annotations

import numpy as np

from ..._validate import choice
from ...materials import Material
from ..._quadrature import gauss
from ..shapes import hermite

__all__ = ["hermite_operator", "PointRule", "axial_energy", "assemble", "translational_mass",
           "check_material_section", "clamp_coordinates", "AXIS_TOL"]

# A reference tangent counts as axis-aligned when its other components are below this.
AXIS_TOL = 1e-12


def hermite_operator(N: np.ndarray, dof_map: np.ndarray, n_edof: int) -> np.ndarray:
    """Interpolation operator of a Hermite field, shape (n_el, n_pts, 3, n_edof).

    ``N`` holds the four Hermite functions (or a derivative) at the points,
    shape (n_el, n_pts, 4).
    """
    B = np.zeros(N.shape[:2] + (3, n_edof))
    comp = np.arange(3)
    for k in range(4):
        B[:, :, comp, dof_map[k]] = N[:, :, k, None]
    return B


class PointRule:
    """A Gauss rule on all elements: points, weights ``w L / 2`` and Hermite operators.

    ``n_points`` is the number of Gauss points, or an array of normalised
    coordinates (then the weights are zero: for evaluating fields there).

    Attributes
    ----------
    s : (n_pts,) normalised coordinates; ``wdx`` : (n_el, n_pts) weights of ``dxi``;
    S, Ba, Bb : (n_el, n_pts, 3, n_edof) operators giving ``r``, ``r'`` and ``r''``;
    dN, ddN : (n_el, n_pts, 4) the Hermite functions' derivatives themselves (C-contiguous,
    the compiled kernels' input); dof_map : (4, 3) the element coordinate of component ``i`` of
    Hermite vector ``k`` (the compiled kernels' scatter map).
    """

    def __init__(self, n_points, lengths: np.ndarray, dof_map: np.ndarray, n_edof: int):
        if np.ndim(n_points) == 0:
            self.s, w = gauss(n_points)
        else:   # explicit points (for evaluating fields at given s), zero weights
            self.s = np.asarray(n_points, dtype=float)
            w = np.zeros_like(self.s)
        self.wdx = w[None, :] * lengths[:, None] / 2.0
        self.dof_map = dof_map
        N, dN, ddN = hermite(self.s, lengths)
        self.dN, self.ddN = np.ascontiguousarray(dN), np.ascontiguousarray(ddN)
        self.S = hermite_operator(N, dof_map, n_edof)
        self.Ba = hermite_operator(dN, dof_map, n_edof)
        self.Bb = hermite_operator(ddN, dof_map, n_edof)


def axial_energy(rule: PointRule, q: np.ndarray, slope_ref: np.ndarray, EA: float, tangent: bool):
    """Axial strain energy ``int EA/2 (|r'| - |r'_ref|)^2 dxi`` (chapter Eqs. 78/94 with Eq. 82).

    The reference slope length ``|r'_ref|`` (1 for the arc-length
    parametrised straight reference) makes the undeformed beam stress-free.

    Returns
    -------
    U : (n_el,), f : (n_el, n_edof), K : (n_el, n_edof, n_edof) or None
    """
    a = np.einsum("epin,en->epi", rule.Ba, q)
    na = np.linalg.norm(a, axis=-1)
    e = a / na[..., None]
    stretch = na - slope_ref
    U = 0.5 * EA * np.sum(rule.wdx * stretch**2, axis=1)
    ga = (EA * stretch * rule.wdx)[..., None] * e
    f = np.einsum("epin,epi->en", rule.Ba, ga)
    if not tangent:
        return U, f, None
    # d2/da2 of (|a| - j)^2 / 2 = (j/|a|) e e^T + (1 - j/|a|) I
    ratio = slope_ref / na
    H = ratio[..., None, None] * e[..., :, None] * e[..., None, :] + (1.0 - ratio)[..., None, None] * np.eye(3)
    H *= (EA * rule.wdx)[..., None, None]
    K = assemble(rule.Ba, H)
    return U, f, K


def assemble(B: np.ndarray, H: np.ndarray, B2: np.ndarray | None = None) -> np.ndarray:
    """``sum_p B_p^T H_p B2_p`` over the points: (n_el, n_pts, m, n) x (n_el, n_pts, m, m) -> (n_el, n, n)."""
    B2 = B if B2 is None else B2
    return np.sum(np.swapaxes(B, -1, -2) @ H @ B2, axis=1)


def translational_mass(lengths: np.ndarray, dof_map: np.ndarray, n_edof: int, rhoA: float) -> np.ndarray:
    """``rho A int S^T S dxi`` (chapter Eq. 27 with Eq. 62), exact with 4 Gauss points."""
    s, w = gauss(4)
    N, _, _ = hermite(s, lengths)
    m = rhoA * np.einsum("ep,epk,epl->ekl", w[None, :] * lengths[:, None] / 2.0, N, N)
    M = np.zeros((lengths.size, n_edof, n_edof))
    for i in range(3):
        M[:, dof_map[:, i][:, None], dof_map[:, i][None, :]] = m
    return M


def check_material_section(material, section, attrs):
    """Raise TypeError unless ``material`` is a Material and ``section`` has ``attrs``."""
    if not isinstance(material, Material):
        raise TypeError(f"`material` must be a Material, got {material!r}.")
    for attr in attrs:
        if not hasattr(section, attr):
            raise TypeError(f"`section` must provide {attr} (e.g. RectangularSection), got {section!r}.")


def clamp_coordinates(kind: str, frame: np.ndarray, extra: tuple[str, ...] = ()) -> tuple[str, ...]:
    """Coordinates a support fixes: position for a pin; a clamp adds the transverse slopes.

    Fixing only the slope components perpendicular to the reference tangent
    leaves the axial stretch at the clamp free (fixing it too over-constrains the axial strain there); that is
    possible by fixing coordinates when the tangent is along a global axis.
    Otherwise all three slope coordinates are fixed, which also fixes the
    axial strain at the clamped node (a slightly stiffer support).
    """
    choice("kind", kind, ("clamp", "pin"))
    pos = ("x", "y", "z")
    if kind == "pin":
        return pos
    t = np.asarray(frame, dtype=float)[:, 0]
    t = t / np.linalg.norm(t)
    slopes = ("x'", "y'", "z'")
    axis = int(np.argmax(np.abs(t)))
    others = [i for i in range(3) if i != axis]
    if np.all(np.abs(t[others]) < AXIS_TOL):
        fixed = tuple(slopes[i] for i in others)
    else:
        fixed = slopes
    return pos + fixed + tuple(extra)
