"""Export results for ParaView: a ``.pvd`` time series of ``.vtu`` files of the beam as a solid
(and of rigid bodies as the boxes of their inertia).

The solid is drawn from the element's own kinematics at the nodes (see
:mod:`ancfdae._sections`): each node contributes its axis point and the
outline of its cross-section, consecutive nodes are joined by wedge cells.
Open the ``.pvd`` file in ParaView to play the motion.
"""
from __future__ import annotations

import logging
import os
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from typing import TYPE_CHECKING

from . import _validate as validate
from .joint_points import describe_joints, joint_series
from ._sections import output_directors, reference_points, section_outline, solid_points, wedge_cells

if TYPE_CHECKING:
    from .bodies import RigidBody
    from .models import Beam
    from .result import Result

__all__ = ["vtk", "beam_of", "bodies_of", "joints_of"]

logger = logging.getLogger("ancfdae")


def beam_of(result: Result) -> Beam:
    """The beam a result was computed with, rebuilt from the description in the result.

    Parameters
    ----------
    result : Result
        A result of :func:`ancfdae.simulate` on a :class:`~ancfdae.models.Beam`
        (or one loaded from its file).

    Returns
    -------
    Beam
        Same element, material, section, mesh and supports (no loads: the
        pictures need none).

    Raises
    ------
    ValueError
        If the result carries no beam description (e.g. a model other than
        a Beam).
    """
    from .models import Beam
    if not result.model or "element" not in result.model:
        raise ValueError("`result` carries no beam description (result.model is empty: the model was not a "
                         "Beam); pass the beam explicitly.")
    beam = Beam.from_description(result.model)
    if beam.n_dof != result.q.shape[1]:
        raise ValueError(f"the beam rebuilt from `result` has {beam.n_dof} coordinates, the result "
                         f"{result.q.shape[1]}.")
    return beam


def _strains(beam, q_full_nodal, ref_nodal):
    """Cheap strain measures at the nodes: the name and value of each."""
    el = beam.element
    dim = el.dim
    if el.name in ("SQ2D", "SQ3D"):
        out = {"section_stretch_eta": np.linalg.norm(q_full_nodal[:, dim:2 * dim], axis=1) - 1.0}
        if dim == 3:
            out["section_stretch_zeta"] = np.linalg.norm(q_full_nodal[:, 2 * dim:3 * dim], axis=1) - 1.0
        return out
    stretch = np.linalg.norm(q_full_nodal[:, dim:2 * dim], axis=1) / np.linalg.norm(ref_nodal[:, dim:2 * dim], axis=1)
    return {"axial_strain": stretch - 1.0}


def bodies_of(result: Result, beam: Beam | RigidBody | None = None) -> list[tuple[Beam | RigidBody, slice]]:
    """Every body of a result with the slice of its coordinates in ``result.q``.

    Parameters
    ----------
    result : Result
    beam : Beam, RigidBody or System, optional
        Given: that one body owns all coordinates (a System: its bodies at their ``offsets``). Otherwise the
        bodies are rebuilt from the description
        in ``result.model``: one body's (a Beam's or a RigidBody's), or a system's ``"bodies"`` list
        (under ``"system"``, with the first coordinate of each body in ``"offsets"``; without offsets
        the coordinates are stacked in the list's order).

    Returns
    -------
    list of (body, slice)

    Raises
    ------
    ValueError
        When the description names no body, or its bodies' coordinates do not add up to the result's.
    """
    if beam is not None and hasattr(beam, "bodies") and hasattr(beam, "offsets"):      # a System
        return [(b, slice(int(o), int(o) + b.n_dof)) for b, o in zip(beam.bodies, beam.offsets)]
    if beam is not None:
        return [(beam, slice(None))]
    model = result.model or {}
    system = model.get("system", model)
    if "bodies" in system:
        parts, start = [], 0
        offsets = system.get("offsets") or []
        for k, record in enumerate(system["bodies"]):
            body = _body_from_description(record, f"result.model['bodies'][{k}]")
            start = int(offsets[k]) if k < len(offsets) else start
            parts.append((body, slice(start, start + body.n_dof)))
            start += body.n_dof
        if start != result.q.shape[1]:
            raise ValueError(f"the bodies described in `result` have {start} coordinates, the result "
                             f"{result.q.shape[1]}.")
        return parts
    if model.get("body") == "RigidBody":
        body = _body_from_description(model, "result.model")
        if body.n_dof != result.q.shape[1]:
            raise ValueError(f"the body rebuilt from `result` has {body.n_dof} coordinates, the result "
                             f"{result.q.shape[1]}.")
        return [(body, slice(None))]
    return [(beam_of(result), slice(None))]


def joints_of(result: Result, beam: Beam | RigidBody | None = None) -> list[dict]:
    """The joint records of a System's result (:func:`ancfdae.joint_points.describe_joints`).

    Parameters
    ----------
    result : Result
        A run's result; its ``model`` description holds a System's joints.
    beam : System, Beam or RigidBody, optional
        When it is the System of the run, its joints are described directly.

    Returns
    -------
    list of dict
        One record per joint; empty without joints.
    """
    if beam is not None and hasattr(beam, "joints") and hasattr(beam, "bodies"):
        return describe_joints(beam.bodies, beam.joints)
    model = result.model or {}
    return list(model.get("system", {}).get("joints", []) or [])


def _joint_frames(result: Result, parts, records):
    """``frame(i) -> meshio.Mesh`` of the joints as vertices with their unit ``axis`` and index ``joint``."""
    import meshio
    P, A = joint_series(records, parts, result.q)
    cells = [("vertex", np.arange(len(records))[:, None])]
    index = np.arange(len(records), dtype=float)

    def frame(i):
        return meshio.Mesh(P[i], cells, point_data={"axis": A[i], "joint": index})
    return frame


def _body_from_description(record: dict, where: str):
    from .bodies import RigidBody
    from .models import Beam
    if isinstance(record, dict) and record.get("body") == "RigidBody":
        return RigidBody.from_description(record)
    if isinstance(record, dict) and "element" in record:
        return Beam.from_description(record)
    raise ValueError(f"`{where}` describes neither a beam nor a rigid body, got keys "
                     f"{sorted(record) if isinstance(record, dict) else type(record).__name__}.")


def _beam_frames(result: Result, beam: Beam, cols: slice, single: bool):
    """``frame(i) -> meshio.Mesh`` of the beam as a solid at output ``i`` (see :func:`vtk`)."""
    import meshio
    outline = section_outline(beam.element.section)
    cells = [("wedge", wedge_cells(beam.n_nodes, len(outline)))]
    per_node = 1 + len(outline)
    directors = output_directors(result, beam) if single else None
    X0 = reference_points(beam, outline)
    ref_nodal = beam.q_ref.reshape(beam.n_nodes, -1)

    def frame(i):
        q, v = result.q[i, cols], result.v[i, cols]
        d = None if directors is None else directors[i]
        X = solid_points(beam, q, outline, d)
        scale = max(float(np.max(np.abs(v))), 1e-300)
        eps = 1e-6 * max(float(np.max(np.abs(q))), 1.0) / scale
        V = (solid_points(beam, q + eps * v, outline, d) - solid_points(beam, q - eps * v, outline, d)) / (2 * eps)
        point_data = {"displacement": X - X0, "velocity": V}
        for key, value in _strains(beam, beam.nodal(q), ref_nodal).items():
            point_data[key] = np.repeat(value, per_node)
        return meshio.Mesh(X, cells, point_data=point_data)
    return frame


def _rigid_frames(result: Result, body, cols: slice):
    """``frame(i) -> meshio.Mesh`` of a rigid body's box (exact velocities: the corners are linear in q)."""
    import meshio
    from .bodies.picture import BOX_CELL, box_points

    def embed(x):
        return x if body.dim == 3 else np.column_stack([x, np.zeros(len(x))])
    cells = [(BOX_CELL[body.dim], np.arange(2 ** body.dim)[None, :])]
    X0 = embed(box_points(body, body.q_ref))

    def frame(i):
        X = embed(box_points(body, result.q[i, cols]))
        V = embed(box_points(body, result.v[i, cols]))
        return meshio.Mesh(X, cells, point_data={"displacement": X - X0, "velocity": V})
    return frame


def vtk(result: Result, beam: Beam | RigidBody | None = None, directory: str | os.PathLike = ".",
        name: str = "beam", every: int = 1) -> Path:
    """Write the motion of a beam, a rigid body or a system of bodies as ParaView files.

    Parameters
    ----------
    result : Result
        Output of :func:`ancfdae.simulate` (or :meth:`Result.load`).
    beam : Beam, RigidBody or System, optional
        The body (or system) of the run; default: rebuilt from ``result.model`` (a beam's or a rigid body's
        description, or a system's list ``"bodies"`` whose coordinates are stacked in its order).
    directory : str or path-like
        Created if missing; receives ``NAME.pvd`` and ``NAME_000000.vtu``, ... (a system:
        ``NAME_K_000000.vtu`` for its body K, one part each in the ``.pvd``).
    name : str
        Base name of the files.
    every : int
        Write every ``every``-th output (1: all).

    Returns
    -------
    pathlib.Path
        The ``.pvd`` file.

    Notes
    -----
    A beam is drawn as a solid; point data of every point: ``displacement`` (from the reference
    configuration), ``velocity`` (exact for SQ elements, whose section points are linear in the
    coordinates; a central difference of the point map along ``v`` otherwise, relative error about
    1e-9), and per node (repeated on its section) ``axial_strain`` (``|r'| / |r'_ref| - 1``; BE2D,
    Cable3D, BE3D) or ``section_stretch_eta``/``_zeta`` (``|r_eta| - 1``; SQ). A rigid body is drawn as
    the homogeneous box of its mass and inertia (a quad in the plane) with ``displacement`` and the
    exact ``velocity`` of its corners. A System's joints (recorded in its result, :mod:`ancfdae.joint_points`)
    are the last part: one vertex per joint at its first body side's point, with point data ``axis`` (the
    unit axis of a revolute, prismatic or prescribed joint, zero otherwise) and ``joint`` (its index; the
    ``.pvd`` names them in a comment).
    """
    import meshio       # on first use: 0.2-0.5 s to import (measured), and only the export needs it
    parts = bodies_of(result, beam)
    if beam is not None and beam.n_dof != result.q.shape[1]:
        raise ValueError(f"`beam` has {beam.n_dof} coordinates, `result` {result.q.shape[1]}.")
    if isinstance(every, bool) or not isinstance(every, int) or every < 1:
        raise ValueError(f"`every` must be a positive integer, got {every!r}.")
    directory = validate.output_folder("directory", directory)
    name = validate.file_stem("name", name)
    from .bodies import RigidBody
    single = len(parts) == 1
    writers = [_rigid_frames(result, body, cols) if isinstance(body, RigidBody) else
               _beam_frames(result, body, cols, single) for body, cols in parts]
    joints = joints_of(result, beam)
    if joints:                       # the last part: the joints as points (index k = number of bodies)
        writers.append(_joint_frames(result, parts, joints))
        single = False
    entries = []
    for i in range(0, result.t.size, every):
        for k, frame in enumerate(writers):
            fname = f"{name}_{i:06d}.vtu" if single else f"{name}_{k}_{i:06d}.vtu"
            meshio.write(directory / fname, frame(i), file_format="vtu")
            entries.append((float(result.t[i]), k, fname))
    pvd = directory / f"{name}.pvd"
    lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    if joints:
        names = ", ".join(f"{k}: {j.get('name') or j['kind']}" for k, j in enumerate(joints)).replace("--", "- -")
        lines.append(f"    <!-- part {len(parts)}: the joints {names} -->")
    lines += [f'    <DataSet timestep="{t!r}" group="" part="{k}" file={quoteattr(f)}/>' for t, k, f in entries]
    lines += ["  </Collection>", "</VTKFile>", ""]
    pvd.write_text("\n".join(lines))
    logger.info("wrote %d ParaView frames to %s", len(entries), pvd)
    return pvd
