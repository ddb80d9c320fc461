"""Export results for ParaView: a ``.pvd`` time series of ``.vtu`` files of the beam as a solid.

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
from ._sections import output_directors, reference_points, section_outline, solid_points, wedge_cells

if TYPE_CHECKING:
    from .models import Beam
    from .result import Result

__all__ = ["vtk", "beam_of"]

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


def vtk(result: Result, beam: Beam | None = None, directory: str | os.PathLike = ".", name: str = "beam",
        every: int = 1) -> Path:
    """Write the motion of a beam as ParaView files.

    Parameters
    ----------
    result : Result
        Output of :func:`ancfdae.simulate` (or :meth:`Result.load`).
    beam : Beam, optional
        The beam of the run; default: rebuilt from ``result.model``
        (:func:`beam_of`).
    directory : str or path-like
        Created if missing; receives ``NAME.pvd`` and ``NAME_000000.vtu``, ...
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
    Point data of every point: ``displacement`` (from the reference
    configuration), ``velocity`` (exact for SQ elements, whose section points
    are linear in the coordinates; a central difference of the point map
    along ``v`` otherwise, relative error about 1e-9), and per node (repeated
    on its section) ``axial_strain`` (``|r'| / |r'_ref| - 1``; BE2D, Cable3D,
    BE3D) or ``section_stretch_eta``/``_zeta`` (``|r_eta| - 1``; SQ).
    """
    import meshio       # on first use: 0.2-0.5 s to import (measured), and only the export needs it
    if beam is None:
        beam = beam_of(result)
    if beam.n_dof != result.q.shape[1]:
        raise ValueError(f"`beam` has {beam.n_dof} coordinates, `result` {result.q.shape[1]}.")
    if isinstance(every, bool) or not isinstance(every, int) or every < 1:
        raise ValueError(f"`every` must be a positive integer, got {every!r}.")
    directory = validate.output_folder("directory", directory)
    name = validate.file_stem("name", name)
    outline = section_outline(beam.element.section)
    cells = [("wedge", wedge_cells(beam.n_nodes, len(outline)))]
    per_node = 1 + len(outline)
    directors = output_directors(result, beam)
    X0 = reference_points(beam, outline)
    ref_nodal = beam.q_ref.reshape(beam.n_nodes, -1)
    entries = []
    for i in range(0, result.t.size, every):
        q, v = result.q[i], result.v[i]
        d = None if directors is None else directors[i]
        X = solid_points(beam, q, outline, d)
        scale = max(float(np.max(np.abs(v))), 1e-300)
        eps = 1e-6 * max(float(np.max(np.abs(q))), 1.0) / scale
        V = (solid_points(beam, q + eps * v, outline, d) - solid_points(beam, q - eps * v, outline, d)) / (2 * eps)
        point_data = {"displacement": X - X0, "velocity": V}
        for key, value in _strains(beam, beam.nodal(q), ref_nodal).items():
            point_data[key] = np.repeat(value, per_node)
        fname = f"{name}_{i:06d}.vtu"
        meshio.write(directory / fname, meshio.Mesh(X, cells, point_data=point_data), file_format="vtu")
        entries.append((float(result.t[i]), fname))
    pvd = directory / f"{name}.pvd"
    lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    lines += [f'    <DataSet timestep="{t!r}" group="" part="0" file={quoteattr(f)}/>' for t, f in entries]
    lines += ["  </Collection>", "</VTKFile>", ""]
    pvd.write_text("\n".join(lines))
    logger.info("wrote %d ParaView frames to %s", len(entries), pvd)
    return pvd
