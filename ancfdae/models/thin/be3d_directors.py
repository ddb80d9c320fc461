"""BE3D's nodal directors (chapter Sect. 3.6): their reference values, checks, and update after a step.

The director ``d`` fixes the cross-section frame of Eqs. 96-100 together with
the torsion angle; it is interpolated linearly between the nodes and constant
between updates. The nodal directors are the element's *event state*: the
beam hands them from :meth:`~.be3d.BE3D.reference_state` to
:meth:`~.be3d.BE3D.prepare`, the driver carries them between steps
(:func:`step`, :func:`bind`), and a result keeps them in ``model_state``.

Director update
---------------
After an accepted step (chapter Sect. 3.6), per global node with slope ``a``,
angle ``theta`` and director ``d``:

* ``"projected"``: ``d <- e30`` (Eq. 99 at the node), ``theta`` unchanged;
* ``"post-rotated"``: ``d <- e3`` and ``theta <- 0``;
* ``"none"``: no update.

Either update leaves the nodal frame unchanged, and sets ``theta_dot`` to the
node's physical spin ``omega1`` (with the new director ``d . e1 = 0``, hence
``g = 0``), so nodal positions, slopes, frames and spins are unchanged, and a
second update right after the first changes nothing. Inside an element the
frame depends on the *interpolated* director, so an update changes the
interior frames, the strain and the kinetic energy: by O(h^2) (h the element
length) for a given deformed state, and not at all for motions in the plane
normal to the director. This cannot be avoided with the chapter's linear
interpolation of directors and angle.

Consequence for dynamics (chapter Sect. 5.3): between updates the equations
conserve ``T + U``; every update adds a jump. With an update after every
time step the jumps accumulate at a rate independent of the step size, and
they grow when neighbouring nodal directors drift apart (the projected
directors by the holonomy of each node's tangent path, the post-rotated ones
by the physical twist and bending between nodes), because their linear
interpolation then shrinks towards zero and the interior frames turn fast.
This is the energy blow-up of BE3D; without updates the energy stays
conserved until the axis meets the fixed director (Eq. 99 singular).
"""
from __future__ import annotations

import numpy as np

from .be3d_kinematics import director_field, frames, spin_gradient

__all__ = ["UPDATES", "reference_directors", "fallback_directors", "check_director", "director_sines",
           "update_directors", "director_geometry", "bind", "step"]

#: Values of BE3D's ``director_update`` option.
UPDATES = ("projected", "post-rotated", "none")

# Smallest admissible sine of the angle between director and axis in the reference configuration.
_PARALLEL_TOL = 1e-6
# Below this sine of the angle between director and axis, a node's frame is undefined.
_SINGULAR = 1e-12


def check_director(d, e1):
    """Raise ValueError where a director is (nearly) parallel to the axis."""
    sin = np.linalg.norm(np.cross(d, e1), axis=-1) / (np.linalg.norm(d, axis=-1) * np.linalg.norm(e1, axis=-1))
    bad = np.flatnonzero(~(sin > _PARALLEL_TOL))
    if bad.size:
        raise ValueError(f"`director` must not be parallel to the beam axis (chapter Eq. 99 would be singular); "
                         f"sine of the angle {sin[bad[0]]:.3g} at point/node {int(bad[0])}, director "
                         f"{d[bad[0]].tolist()}, axis {e1[bad[0]].tolist()}.")


def reference_directors(director, update, frames_):
    """The nodal directors of the undeformed beam and the reference angles ``theta_ref``.

    The director is ``e3`` of each node's frame (``theta_ref = 0``), or the
    given ``director`` (3,) with ``theta_ref`` the angle that turns its
    projected frame ``(e20, e30)`` into the node's ``(e2, e3)``; with the
    ``"post-rotated"`` update the reference takes ``e3`` as well.

    Parameters
    ----------
    director : ndarray (3,) or None
    update : str, one of :data:`UPDATES`
    frames_ : ndarray, shape (n_nodes, 3, 3)
        The nodes' reference frames, columns ``(e1, e2, e3)``.

    Returns
    -------
    directors : ndarray (n_nodes, 3); theta : ndarray (n_nodes,)
    """
    frames_ = np.asarray(frames_, dtype=float)
    e1, e2, e3 = frames_[:, :, 0], frames_[:, :, 1], frames_[:, :, 2]
    theta = np.zeros(len(frames_))
    if director is not None:
        directors = np.repeat(director[None, :], len(frames_), axis=0)
        check_director(directors, e1)
    if director is None or update == "post-rotated":
        directors = e3.copy()
    else:
        F, _ = frames(e1, theta, directors)
        # e3 = cos(theta) e30 - sin(theta) e20 and e2 = cos(theta) e20 + sin(theta) e30
        theta = np.arctan2(np.einsum("ni,ni->n", e2, F[:, :, 2]), np.einsum("ni,ni->n", e3, F[:, :, 2]))
    return directors, theta


def fallback_directors(director, q_ref):
    """Directors for a geometry prepared without a reference state (e.g. of stacked copies of a mesh).

    The given ``director`` if any, else per node the global axis least
    aligned with the reference slope.
    """
    slopes = np.concatenate([q_ref[:, 3:6], q_ref[-1:, 10:13]])
    if director is not None:
        return np.repeat(director[None, :], len(slopes), axis=0)
    return np.eye(3)[np.argmin(np.abs(slopes), axis=1)]


def director_sines(directors, Q):
    """Sine of the angle between each nodal director and the axis ``r'`` (1 = normal, 0 = parallel)."""
    a = Q[:, 3:6]
    return (np.linalg.norm(np.cross(directors, a), axis=-1)
            / (np.linalg.norm(directors, axis=-1) * np.linalg.norm(a, axis=-1)))


def update_directors(directors, Q, V, variant):
    """The director update; return the new ``(Q, V, directors)`` (the arguments are not changed).

    ``directors``: nodal directors, shape (n_nodes, 3); ``Q``, ``V``: nodal coordinates and velocities,
    shape (n_nodes, 7), per node ``(x, y, z, x', y', z', theta)``.
    """
    if variant == "none":
        return Q, V, directors
    a = Q[:, 3:6]
    with np.errstate(invalid="ignore", divide="ignore"):   # a singular node is reported below
        F, n = frames(a, Q[:, 6], directors)
    bad = np.flatnonzero(~(n > _SINGULAR))
    if bad.size:
        raise FloatingPointError(
            f"BE3D director update: the director is parallel to the beam axis at node(s) {bad.tolist()} "
            "(the projection of chapter Eq. 99 is singular); use smaller steps so the update follows the axis.")
    g, _ = spin_gradient(a, directors)
    omega1 = V[:, 6] + np.einsum("ni,ni->n", g, V[:, 3:6])
    Q, V = Q.copy(), V.copy()
    if variant == "projected":
        # e30 (Eq. 99): turn e3 back by theta, since e3 = c e30 - s e20 and e2 = c e20 + s e30.
        c, s = np.cos(Q[:, 6])[:, None], np.sin(Q[:, 6])[:, None]
        new = c * F[:, :, 2] + s * F[:, :, 1]
    else:
        new = F[:, :, 2].copy()
        Q[:, 6] = 0.0
    V[:, 6] = omega1
    new.setflags(write=False)
    return Q, V, new


def director_geometry(directors, q, rule):
    """How far an element's linearly interpolated director is from degenerating (Sect. 3.6, Eq. 99).

    Parameters
    ----------
    directors : ndarray (n_el + 1, 3)
        The nodal directors (unit vectors after an update).
    q : ndarray (n_el, 14)
        Element coordinates.
    rule : TorsionRule
        The points at which the interior is examined.

    Returns
    -------
    angle : ndarray (n_el,)
        The angle between the element's two nodal directors (rad).
    projection : ndarray (n_el,)
        The smallest length over the points of Eq. 99's unnormalised projection ``|d - (d.e1) e1|`` of the
        interpolated director ``d = S5 d_A + S6 d_B``: the sine of the director-axis angle at a node, and
        ``cos(angle / 2)`` at most at the midpoint. The frame is undefined where it reaches zero.
    """
    dA, dB = directors[:-1], directors[1:]
    cos = np.einsum("ei,ei->e", dA, dB) / (np.linalg.norm(dA, axis=-1) * np.linalg.norm(dB, axis=-1))
    angle = np.arccos(np.clip(cos, -1.0, 1.0))
    d, _ = director_field(directors, rule)
    a = np.einsum("epin,en->epi", rule.Ba, q)
    e1 = a / np.linalg.norm(a, axis=-1, keepdims=True)
    e30 = d - np.einsum("epi,epi->ep", d, e1)[..., None] * e1
    return angle, np.min(np.linalg.norm(e30, axis=-1), axis=1)


def bind(geom: dict, state: dict) -> dict:
    """``geom`` with the nodal directors of ``state`` (read-only; ``geom`` itself is unchanged)."""
    directors = np.array(state["directors"], dtype=float)
    if directors.shape != geom["directors"].shape:
        raise ValueError(f"`state['directors']` must have shape {geom['directors'].shape}, got {directors.shape}.")
    directors.setflags(write=False)
    return dict(geom, directors=directors)


def step(geom: dict, Q: np.ndarray, V: np.ndarray, variant: str, update_below: float | None) -> tuple | None:
    """The director update after an accepted step: ``(Q, V, {"directors": ...})``, or None when not done.

    ``variant`` is the ``director_update`` option; with ``update_below`` the
    update waits until the sine of the angle between director and axis falls
    below it at some node (see :class:`~.be3d.BE3D`).
    """
    if variant == "none":
        return None
    directors = geom["directors"]
    Q = np.asarray(Q, dtype=float)
    if update_below is not None and np.min(director_sines(directors, Q)) >= update_below:
        return None
    Q2, V2, new = update_directors(directors, Q, np.asarray(V, dtype=float), variant)
    return Q2, V2, {"directors": new}
