"""BE3D's generalised force of a dead moment and its exact q-derivative, in NumPy (chapter Sects. 2.2, 3.6).

The virtual rotation of the cross-section frame at ``s`` is
``delta phi = e1 x delta e1 + (delta theta + g . delta r') e1`` (the bending
part and the spin of Eqs. 96-100 under a variation, ``g`` as in
:mod:`.be3d_inertia`), so a moment ``M`` does the virtual work ``M . delta phi``
with ``f_r' = (M x e1)/|r'| + g (M . e1)`` and ``f_theta = M . e1``. The
derivative comes from scalar jets over ``r'``. The compiled twin is
:func:`.be3d_moment_numba.be3d_moment`.
"""
from __future__ import annotations

import numpy as np

from ..jets import scalar as jet
from ..jets.scalar import Jet
from ..shapes import hermite, linear
from .be3d_kinematics import DOF, N_EDOF, THETA, spin_gradient
from .spatial import hermite_operator

__all__ = ["moment_load"]


def moment_load(geom: dict, q: np.ndarray, s: float, M: np.ndarray, element: int,
                tangent: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """Force (14,) and, if ``tangent``, its derivative (14, 14) of the dead moment ``M`` (3,) at ``s`` of ``element``.

    ``q``: that element's coordinates; the director at ``s`` is interpolated
    from the nodal directors of ``geom``.
    """
    L = geom["L"][[element]]
    s_ = np.array([float(s)])
    _, dN, _ = hermite(s_, L)
    N, _ = linear(s_, L)
    Sx = hermite_operator(dN, DOF, N_EDOF)[0, 0]
    Nt = np.zeros(N_EDOF)
    Nt[THETA] = N[0, 0]
    directors = geom["directors"]
    d = N[0, 0, 0] * directors[element] + N[0, 0, 1] * directors[element + 1]
    a = Sx @ q
    I = np.eye(3)
    aj = [Jet(a[i], I[i]) for i in range(3)]
    sp = jet.sqrt(aj[0] * aj[0] + aj[1] * aj[1] + aj[2] * aj[2])
    e1 = [x / sp for x in aj]
    Me1 = M[0] * e1[0] + M[1] * e1[1] + M[2] * e1[2]
    Mxe1 = [M[1] * e1[2] - M[2] * e1[1], M[2] * e1[0] - M[0] * e1[2], M[0] * e1[1] - M[1] * e1[0]]
    g, G = spin_gradient(a, d)
    gj = [Jet(g[i], G[i]) for i in range(3)]
    fa = [Mxe1[i] / sp + gj[i] * Me1 for i in range(3)]
    f = Sx.T @ np.array([x.v for x in fa]) + Nt * Me1.v
    if not tangent:
        return f, None
    dfa = np.array([x.g for x in fa])
    return f, Sx.T @ dfa @ Sx + np.outer(Nt, Me1.g @ Sx)
