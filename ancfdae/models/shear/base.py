"""Common base of the shear- and cross-section-deformable elements SQ2D and SQ3D (chapter Sect. 4).

The two elements differ only in their dimension, their frame (chapter Eq. 7 or
its planar analogue) and their moment load; the mesh handling, the quadrature
options, the mass matrix and the preparation of both strain-energy
formulations live here, the kernels in :mod:`.kernels` (NumPy) and
:mod:`.kernels_numba` (compiled).
"""
from __future__ import annotations

import numbers

import numpy as np
from numpy.typing import ArrayLike

from ..._quadrature import gauss
from ..._validate import choice
from ...materials import CircularSection, Material, RectangularSection
from ..element import Element, Kernel
from .continuum import voigt
from .kernels import SQReference
from .points import local_variables, rule, shapes
from .structural import structural_kernel

__all__ = ["SQElement", "shear_factors"]

_STRUCTURAL_TERMS = ("axial", "shear", "bending", "cross_section")
_CONTINUUM_TERMS = ("axial", "section")


def shear_factors(section, material) -> tuple[float, float]:
    """``(k2, k3)`` of a section: ``shear_factors_of`` where the section has it, else ``k_s`` twice."""
    if hasattr(section, "shear_factors_of"):
        return section.shear_factors_of(material)
    k = section.k_s(material)
    return k, k


def _compiled(element: SQElement) -> Kernel:
    """The compiled kernel object; its module, and numba's loops with it, is imported when selected."""
    from .sq_kernel import SQCompiled
    return SQCompiled(element)


class SQElement(Element):
    """Shared implementation; see :class:`~ancfdae.models.SQ2D` and :class:`~ancfdae.models.SQ3D`."""

    formulations = ("structural", "continuum", "continuum-locking")
    kernel_twins = {"numpy": SQReference, "numba": _compiled}
    node_params = (-1.0, 1.0, 0.0)    # class default (quadratic); instances set their own
    #: term of each structural strain component, in the order returned by ``_strains``
    _terms: tuple[str, ...] = ()

    def __init__(self, material: Material, section: RectangularSection | CircularSection,
                 formulation: str = "structural", nodes: int = 3, quadrature: dict | None = None,
                 kernel: str = "auto") -> None:
        if not isinstance(material, Material):
            raise TypeError(f"`material` must be an ancfdae Material, got {material!r}.")
        self.formulation = choice("formulation", formulation, self.formulations)
        if self.formulation == "structural":
            needed = ("A", "I2", "I3", "J", "k_s", "k_t")
            missing = [a for a in needed if not hasattr(section, a)]
            if missing:
                raise TypeError(f"`section` must provide {', '.join(needed)} (e.g. RectangularSection); "
                                f"{section!r} lacks {', '.join(missing)}.")
        elif not isinstance(section, (RectangularSection, CircularSection)):
            raise TypeError("`section` must be a RectangularSection or CircularSection for the continuum "
                            f"formulation (its points integrate the cross-section), got {section!r}.")
        if isinstance(nodes, bool) or nodes not in (2, 3):
            raise ValueError(f"`nodes` must be 3 (quadratic, Eqs. 105/107) or 2 (linear, Eqs. 104/106), got {nodes!r}.")
        self.material, self.section, self.nodes = material, section, int(nodes)
        # Per instance: the node layout depends on `nodes` (the class default is the quadratic element).
        self.node_params = (-1.0, 1.0, 0.0) if nodes == 3 else (-1.0, 1.0)
        self.quadrature = self._parse_quadrature(quadrature)
        self.kernel = kernel

    def __repr__(self):
        return (f"{self.name}(formulation={self.formulation!r}, nodes={self.nodes}, "
                f"quadrature={self.quadrature!r}, kernel={self._kernel!r})")

    @property
    def energy_degree(self) -> int | None:
        """4 for the continuum formulations (St. Venant-Kirchhoff energy of the Green strain, which is
        quadratic in q, Eqs. 13, 28-33); None for the structural one (|r'| and the frame of Eq. 7)."""
        return None if self.formulation == "structural" else 4

    # -- options ----------------------------------------------------------------------------
    def default_quadrature(self) -> dict:
        """Default rules, ``term -> (kind, n_points)``.

        Structural: reduced Gauss integration (one point fewer than the nodes,
        after Simo and Vu-Quoc, Sect. 4.2.2) of the axial, shear and bending
        terms -- full integration locks in shear -- and the end-point
        (Lobatto) rule with one point per node for the cross-section terms,
        which penalises the thickness strain at the nodes and so leaves no
        zero-energy mode. These rules reproduce the chapter's Table 2 to 4
        digits; no other combination of 1-5 point rules does (tests).
        Continuum: the same reduced Gauss rule along the axis (full
        integration locks in shear here too: 3 points make one quadratic
        element 5 % too stiff in bending), 3 x 3 Gauss points over a
        rectangular section (exact for the quartic St. Venant-Kirchhoff
        energy); ``{"axial": 3}`` is Project Chrono's full integration.
        """
        n = self.nodes
        if self.formulation == "structural":
            return {"axial": ("gauss", n - 1), "shear": ("gauss", n - 1), "bending": ("gauss", n - 1),
                    "cross_section": ("lobatto", n)}
        return {"axial": ("gauss", n - 1), "section": ("gauss", 3)}

    def _parse_quadrature(self, spec):
        rules = self.default_quadrature()
        if spec is None:
            return rules
        if not isinstance(spec, dict):
            raise TypeError(f"`quadrature` must be a dict term -> rule, got {spec!r}.")
        for term, value in spec.items():
            if term not in rules:
                raise ValueError(f"`quadrature` term must be one of {sorted(rules)} for formulation "
                                 f"{self.formulation!r}, got {term!r}.")
            if isinstance(value, numbers.Integral) and not isinstance(value, bool):
                value = ("gauss", value)
            ok = (isinstance(value, (tuple, list)) and len(value) == 2 and value[0] in ("gauss", "lobatto")
                  and isinstance(value[1], numbers.Integral) and not isinstance(value[1], bool)
                  and value[1] >= (2 if value[0] == "lobatto" else 1))
            if not ok or (term == "section" and value[0] != "gauss"):
                raise ValueError(f"`quadrature[{term!r}]` must be a number of Gauss points >= 1 or "
                                 f"('gauss'|'lobatto', n) with n >= 1 (Lobatto: n >= 2; section: Gauss only), "
                                 f"got {value!r}.")
            rules[term] = (value[0], int(value[1]))
        return rules

    # -- mesh -------------------------------------------------------------------------------
    @property
    def _nvec(self) -> int:
        return self.dim           # vectors per node: r and the dim-1 cross-section slopes

    def reference_coordinates(self, points: np.ndarray, frames: np.ndarray) -> np.ndarray:
        """``[r, e_2(, e_3)]`` per node: unit cross-section slopes along the reference frame."""
        return np.concatenate([points] + [frames[:, :, k] for k in range(1, self.dim)], axis=1)

    def support_coordinates(self, kind: str, frame: np.ndarray) -> tuple[str, ...]:
        """Clamp: position and every cross-section slope coordinate; pin: position."""
        if kind == "pin":
            return self.node_coordinates[:self.dim]
        return self.node_coordinates

    # -- preparation ------------------------------------------------------------------------
    def prepare(self, q_ref: np.ndarray, lengths: np.ndarray) -> dict:
        lengths = np.asarray(lengths, dtype=float)
        geom = {"L": lengths, "M": self._mass(lengths, q_ref)}
        if self.formulation == "structural":
            self._prepare_structural(geom, q_ref, lengths)
        else:
            self._prepare_continuum(geom, q_ref, lengths)
        return geom

    def _stiffness(self) -> np.ndarray:
        """Cross-section stiffness of each structural strain (Eqs. 42, 48, 109-111)."""
        raise NotImplementedError

    def _prepare_structural(self, geom, q_ref, lengths):
        # One group of points per distinct rule, each evaluating only the strains of its terms
        # (the frame of Eq. 7 is not computed at points that carry the cross-section terms only).
        groups = []
        for r in sorted(set(self.quadrature[t] for t in _STRUCTURAL_TERMS)):
            which = [k for k, t in enumerate(self._terms) if self.quadrature[t] == r]
            s, w = rule(*r)
            N, dN = shapes(self.nodes, s, lengths)
            E, P = N.shape[:2]
            v = local_variables(N, dN, q_ref, self.dim).reshape(E * P, -1)
            npv = self.dim * (self.dim - 1)
            jac = np.linalg.norm(v[:, npv:npv + self.dim], axis=1)      # |r_ref'| = dS/dxi (Eq. 15)
            zeros = np.zeros((E * P, len(which)))
            _, _, _, raw = structural_kernel(self._strains, which, v, self.dim, zeros, zeros, 0)
            # Strains per unit arc length S (Eqs. 16, 19) integrated over dS; cross-section strains over dS.
            cs = np.array([self._terms[k] == "cross_section" for k in which])
            scale = np.where(cs[None, :], jac[:, None], 1.0 / jac[:, None])
            wq = (w[None, :] * lengths[:, None] / 2).reshape(-1)
            Dw = self._stiffness()[which][None, :] * wq[:, None] * scale
            groups.append({"which": which, "ref": raw, "Dw": Dw, "N": N, "dN": dN})
        geom["groups"] = groups

    def _section_points(self):
        """Cross-section points ``(S, dim-1)`` and area weights for the continuum energy."""
        n = self.quadrature["section"][1]
        sec = self.section
        if isinstance(sec, RectangularSection):
            s, w = gauss(n)
            eta, weta = s * sec.h / 2, w * sec.h / 2
            zeta, wzeta = s * sec.b / 2, w * sec.b / 2
            if self.dim == 2:
                return eta[:, None], weta * sec.b
            E_, Z_ = np.meshgrid(eta, zeta, indexing="ij")
            return np.stack([E_.ravel(), Z_.ravel()], axis=1), np.outer(weta, wzeta).ravel()
        # Solid circle: Gauss in the radius (weight r dr) times 2n equally spaced angles.
        R = sec.d / 2
        s, w = gauss(n)
        r, wr = R * (s + 1) / 2, w * R / 2 * (R * (s + 1) / 2)
        th = np.arange(2 * n) * np.pi / n
        pts = np.stack([np.outer(r, np.cos(th)).ravel(), np.outer(r, np.sin(th)).ravel()], axis=1)
        wt = np.outer(wr, np.full(th.size, np.pi / n)).ravel()
        return (pts[:, :1], wt) if self.dim == 2 else (pts, wt)

    def _elasticity(self):
        """Full elasticity matrix and its split D0 + Dnu (Eqs. 34, 108); 2D: plane stress."""
        mat = self.material
        k2, k3 = shear_factors(self.section, mat)
        E, nu, G = mat.E, mat.nu, mat.G
        if self.dim == 3:
            lam = E * nu / ((1 + nu) * (1 - 2 * nu))
            normal = lam * np.ones((3, 3)) + 2 * G * np.eye(3)          # Eq. 34 as the standard isotropic law (the chapter's text lost its factors)
            # gamma_23 (in the section, no correction), gamma_13 (along zeta: k3), gamma_12 (along eta: k2)
            shear = np.diag([G, k3 * G, k2 * G])
        else:
            Ep = E / (1 - nu**2)
            normal = Ep * np.array([[1.0, nu], [nu, 1.0]])
            shear = np.array([[k2 * G]])
        n = normal.shape[0]
        D = np.zeros((n + shear.shape[0],) * 2)
        D[:n, :n], D[n:, n:] = normal, shear
        D0 = np.diag(np.concatenate([np.full(n, E), np.diag(shear)]))
        return D, D0, D - D0

    def _prepare_continuum(self, geom, q_ref, lengths):
        s, w = rule(*self.quadrature["axial"])
        N, dN = shapes(self.nodes, s, lengths)
        E, P = N.shape[:2]
        pts, ws = self._section_points()
        D, D0, Dnu = self._elasticity()
        if self.formulation == "continuum":
            # Eq. 108: the Poisson part only on the axis, with the area (one point at eta = zeta = 0).
            pts = np.vstack([pts, np.zeros((1, self.dim - 1))])
            ws = np.concatenate([ws, [self.section.A]])
            Ds = np.concatenate([np.repeat(D0[None], len(pts) - 1, axis=0), Dnu[None]])
        else:
            Ds = np.repeat(D[None], len(pts), axis=0)
        nb = 2 * self.dim - 1
        Pc = np.zeros((len(pts), self.dim, nb))
        Pc[:, 0, self.dim - 1] = 1.0                                    # x_xi = r' + eta a2' + zeta a3'
        for k in range(1, self.dim):
            Pc[:, 0, self.dim - 1 + k] = pts[:, k - 1]
            Pc[:, k, k - 1] = 1.0                                       # x_eta = a2, x_zeta = a3
        v = local_variables(N, dN, q_ref, self.dim).reshape(E * P, -1)
        X = np.einsum("scb,pbi->psic", Pc, v.reshape(E * P, nb, self.dim))
        C = np.einsum("psic,psid->pscd", X, X)
        if np.abs(C - np.eye(self.dim)).max() > 1e-10:
            raise ValueError(f"formulation={self.formulation!r} needs a straight reference configuration with "
                             "orthonormal cross-section slopes (chapter Eq. 13); the given nodes deviate by "
                             f"{np.abs(C - np.eye(self.dim)).max():.3g} in the metric.")
        _, T = voigt(self.dim)
        ref = 0.5 * np.einsum("acd,pscd->psa", T, C)
        wax = (w[None, :] * lengths[:, None] / 2).reshape(-1)
        geom["groups"] = [{"Pc": Pc, "ws": ws, "Ds": Ds, "ref": ref, "wax": wax, "N": N, "dN": dN}]

    def _mass(self, lengths, q_ref):
        """``rho int S^T S dV`` (Eq. 27): ``rho int N_i N_j dS`` times diag(A, I3, I2) per node vector."""
        s, w = gauss(4)                  # quadratic x quadratic (times |r'| of a curved reference)
        N, dN = shapes(self.nodes, s, lengths)
        nn = N.shape[-1]
        r1 = np.einsum("epi,eic->epc", dN, q_ref.reshape(len(lengths), nn, -1)[:, :, :self.dim])
        jac = np.linalg.norm(r1, axis=-1)
        m = np.einsum("ep,epi,epj->eij", w[None, :] * lengths[:, None] / 2 * jac, N, N)
        sec = self.section
        c = self.material.rho * np.array([sec.A, sec.I3, sec.I2])[:self._nvec]
        # M[e, (i, a, c), (j, b, d)] = m[e, i, j] c[a] delta_ab delta_cd, written block by block.
        nv, d = self._nvec, self.dim
        M = np.zeros((len(lengths), nn, nv, d, nn, nv, d))
        for a in range(nv):
            mc = m * c[a]
            for k in range(d):
                M[:, :, a, k, :, a, k] = mc
        n = nn * nv * d
        return M.reshape(len(lengths), n, n)

    # -- kernels ----------------------------------------------------------------------------
    def mass_matrix(self, geom: dict) -> np.ndarray:
        return geom["M"]

    def shape_matrix(self, s: ArrayLike, lengths: ArrayLike) -> np.ndarray:
        N, _ = shapes(self.nodes, np.asarray(s, dtype=float), np.asarray(lengths, dtype=float))
        E, P, nn = N.shape
        S = np.zeros((E, P, self.dim, nn, self._nvec, self.dim))
        for c in range(self.dim):
            S[:, :, c, :, 0, c] = N
        return S.reshape(E, P, self.dim, -1)
