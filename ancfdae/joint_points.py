"""Joints as points for pictures: what a result file records of a System's joints, and their motion.

:func:`describe_joints` gives, per joint, a JSON-able record (kind, name, the sides as body index and the
``where`` handed to the body's ``attachment``, and the joint's axis: a frame vector of its first body side
or a constant direction); :meth:`ancfdae.System.describe` stores it with the bodies, so that a result file
holds enough to draw the joints without the script. :func:`joint_series` rebuilds, from such records and the
bodies, the position of every joint (its first body side's point) and its unit axis (zero for a joint
without one: Spherical, Distance, Rigid) at every output, which :func:`ancfdae.export.vtk` writes as a point
series and :func:`ancfdae.plot.animate` draws as markers.
"""
from __future__ import annotations

import numpy as np

__all__ = ["describe_joints", "joint_series"]


def _json_where(where):
    """The side's ``where`` as JSON: an int node, a float arc length, a dict, a list of body coordinates."""
    if where is None or isinstance(where, (bool, str, dict)):
        return where
    if isinstance(where, (int, np.integer)):
        return int(where)
    if isinstance(where, (float, np.floating)):
        return float(where)
    return [float(x) for x in np.asarray(where, dtype=float).ravel()]


def describe_joints(bodies, joints) -> list[dict]:
    """JSON-able records of ``joints`` between ``bodies`` (the System's lists); see the module docstring."""
    out = []
    for j in joints:
        sides = []
        for side in j.sides:
            if isinstance(side, str):
                sides.append("ground")
                continue
            body, where = side
            sides.append({"body": next(i for i, b in enumerate(bodies) if b is body), "where": _json_where(where)})
        rec = {"kind": j.kind, "name": j.name, "sides": sides}
        direction = getattr(j, "direction", None)
        if direction is not None:
            rec["direction"] = [float(x) for x in np.asarray(direction, dtype=float).ravel()]
        elif isinstance(getattr(j, "axis", None), (int, np.integer)) and j.kind in ("Revolute", "Prismatic",
                                                                                   "Prescribed"):
            rec["axis"] = int(j.axis)
        out.append(rec)
    return out


def joint_series(records: list[dict], parts, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Positions and unit axes of the described joints at every output.

    Parameters
    ----------
    records : list of dict
        From :func:`describe_joints` (a result's ``model["system"]["joints"]``).
    parts : list of (body, slice)
        The bodies and their coordinate columns (:func:`ancfdae.export.bodies_of`).
    q : ndarray, shape (n_out, n_dof)

    Returns
    -------
    points, axes : ndarray, shape (n_out, n_joints, 3)
        In 3D coordinates (a planar system at z = 0); an axis is zero where the joint has none.

    Raises
    ------
    ValueError
        When a record names a body that ``parts`` do not have.
    """
    n_out = q.shape[0]
    P, A = np.zeros((n_out, len(records), 3)), np.zeros((n_out, len(records), 3))
    for k, rec in enumerate(records):
        side = next((s for s in rec["sides"] if s != "ground"), None)
        if side is None:
            continue
        i = side["body"]
        if not 0 <= i < len(parts):
            raise ValueError(f"joint {k} ({rec.get('name') or rec['kind']}) names body {i}, the result has "
                             f"{len(parts)} bodies.")
        body, cols = parts[i]
        att = body.attachment(side["where"])
        qb = q[:, cols]
        x = np.asarray(att.position @ qb.T).T + np.asarray(att.offset, dtype=float)
        P[:, k, :x.shape[1]] = x
        if "direction" in rec:
            d = np.asarray(rec["direction"], dtype=float)
            A[:, k, :d.size] = d / np.linalg.norm(d)
        elif "axis" in rec and rec["axis"] < len(att.axes):
            d = np.asarray(att.axes[rec["axis"]] @ qb.T).T + np.asarray(att.axes_offset[rec["axis"]], dtype=float)
            A[:, k, :d.shape[1]] = d / np.maximum(np.linalg.norm(d, axis=1), 1e-300)[:, None]
    return P, A
