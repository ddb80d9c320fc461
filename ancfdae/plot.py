"""Pictures of beams and results with matplotlib.

Every function draws into a given ``ax`` or, without one, into a new figure
of :mod:`matplotlib.pyplot` (so it shows in a notebook), and returns the
axes. None of them selects a backend: that stays the user's choice.
:func:`animate` renders off-screen with the Agg canvas and writes a GIF with
matplotlib's Pillow writer (no ffmpeg needed).
"""
from __future__ import annotations

import logging
import os
from pathlib import Path

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from . import _validate as validate
from ._sections import output_directors, section_outline, section_vectors
from .export import bodies_of, beam_of, joints_of
from .joint_points import joint_series

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from .bodies import RigidBody
    from .models import Beam
    from .result import Result

__all__ = ["configuration", "energy", "tip", "animate"]

logger = logging.getLogger("ancfdae")

_AXIS_SAMPLES = 8   # axis points drawn per element (the interpolation between nodes is curved)


def _new_axes(three_d: bool):
    import matplotlib.pyplot as plt      # on first use: pyplot takes 2.5-3 s to import (measured)
    fig = plt.figure()
    return fig.add_subplot(projection="3d" if three_d else None)


def _dim(body) -> int:
    return body.dim if _is_rigid(body) else body.element.dim


def _check_q(beam, q):
    q = np.asarray(q, dtype=float)
    if q.shape != (beam.n_dof,):
        raise ValueError(f"`q` must have shape ({beam.n_dof},) (the beam's free coordinates), got {q.shape}.")
    return q


def configuration(beam: Beam | RigidBody, q: ArrayLike, ax: Axes | None = None, *,
                  directors: np.ndarray | None = None, sections: bool = True, color: Any = None) -> Axes:
    """Draw a configuration of a beam (its axis and the outline of the solid) or of a rigid body (the edges
    of the box of its inertia, :func:`ancfdae.bodies.picture.box_corners`).

    Parameters
    ----------
    beam : Beam or RigidBody
    q : array_like, shape (n_dof,)
        Free coordinates, e.g. ``result.q[i]``.
    ax : matplotlib Axes, optional
        2D axes for planar elements, 3D axes (``projection="3d"``) for
        spatial ones; default a new figure.
    directors : ndarray, shape (n_nodes, 3), optional
        BE3D: the directors belonging to ``q`` (``result.model_state["directors"][i]``).
    sections : bool
        Also draw the cross-sections at the nodes (from the element's own
        kinematics) and the edges of the solid between them.
    color : optional
        Matplotlib color of every line.

    Returns
    -------
    matplotlib Axes
        The first line drawn is the axis, sampled at ``8`` points per element.
    """
    q = _check_q(beam, q)
    if _is_rigid(beam):
        return _rigid_configuration(beam, q, ax, color)
    dim = beam.element.dim
    if ax is None:
        ax = _new_axes(dim == 3)
    elif (dim == 3) != hasattr(ax, "zaxis"):
        raise ValueError(f"`ax` must be {'a 3D' if dim == 3 else 'a 2D'} axes for {beam.element.name}, "
                         f"got {type(ax).__name__}.")
    s = np.linspace(0.0, beam.s_nodes[-1], _AXIS_SAMPLES * beam.n_elements + 1)
    r = beam.position(q, s)
    (axis_line,) = ax.plot(*r.T, color=color, lw=1.5, label="axis")
    color = axis_line.get_color()
    if sections:
        outline = section_outline(beam.element.section)
        rn, a_eta, a_zeta = section_vectors(beam, q, directors)
        ring = (rn[:, None, :] + outline[None, :, 0, None] * a_eta[:, None, :]
                + outline[None, :, 1, None] * a_zeta[:, None, :])          # (n_nodes, n_outline, 3)
        if dim == 2:
            # In the plane the solid is the band between the two faces eta = +-h/2.
            top = rn + outline[:, 0].max() * a_eta
            bottom = rn + outline[:, 0].min() * a_eta
            for face in (top, bottom):
                ax.plot(face[:, 0], face[:, 1], color=color, lw=0.8)
            for k in range(beam.n_nodes):
                ax.plot([bottom[k, 0], top[k, 0]], [bottom[k, 1], top[k, 1]], color=color, lw=0.8)
        else:
            for k in range(beam.n_nodes):
                closed = np.vstack([ring[k], ring[k, :1]])
                ax.plot(*closed.T, color=color, lw=0.8)
            step = max(1, ring.shape[1] // 4)
            for j in range(0, ring.shape[1], step):
                ax.plot(*ring[:, j].T, color=color, lw=0.5)
    if dim == 2:
        ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    if dim == 3:
        ax.set_zlabel("z")
    return ax


def _is_rigid(body) -> bool:
    from .bodies import RigidBody
    return isinstance(body, RigidBody)


def _rigid_configuration(body: RigidBody, q: np.ndarray, ax: Axes | None, color: Any) -> Axes:
    """A rigid body as the edges of the box of its inertia, the first line drawn from the centre of mass."""
    from .bodies.picture import box_edges, box_points
    if ax is None:
        ax = _new_axes(body.dim == 3)
    elif (body.dim == 3) != hasattr(ax, "zaxis"):
        raise ValueError(f"`ax` must be {'a 3D' if body.dim == 3 else 'a 2D'} axes for a {body.dim}D rigid body, "
                         f"got {type(ax).__name__}.")
    corners = box_points(body, q)
    (line,) = ax.plot(*np.array([body.centre_of_mass(q)] * 2).T, "o", color=color, ms=3, label="centre of mass")
    for a, b in box_edges(body.dim):
        ax.plot(*corners[[a, b]].T, color=line.get_color(), lw=1.2)
    if body.dim == 2:
        ax.set_aspect("equal", adjustable="datalim")
    return ax


def energy(result: Result, ax: Axes | None = None, *, monitor: str = "energy") -> Axes:
    """Plot the energies of an :class:`~ancfdae.EnergyMonitor` log over time.

    Parameters
    ----------
    result : Result
    ax : matplotlib Axes, optional
    monitor : str
        Name of the energy monitor in ``result.monitors``.

    Returns
    -------
    matplotlib Axes
        One line per energy: kinetic, strain, potential, total (in this order).
    """
    if monitor not in result.monitors:
        raise ValueError(f"`result` has no monitor {monitor!r} (run with monitors=[EnergyMonitor()]); "
                         f"it has {sorted(result.monitors)}.")
    log = result.monitors[monitor]
    if ax is None:
        ax = _new_axes(False)
    for key in ("kinetic", "strain", "potential", "total"):
        ax.plot(result.t, log[key], label=key, lw=2.0 if key == "total" else 1.0)
    ax.set_xlabel("t")
    ax.set_ylabel("energy")
    ax.legend()
    return ax


def tip(result: Result, ax: Axes | None = None, *, beam: Beam | None = None, s: float | None = None) -> Axes:
    """Plot the displacement components of a point of the axis (default the beam's end) over time.

    Parameters
    ----------
    result : Result
    ax : matplotlib Axes, optional
    beam : Beam, optional
        Default: rebuilt from the description in ``result``.
    s : float, optional
        Reference arc length of the point (default the end of the beam).

    Returns
    -------
    matplotlib Axes
        One line per component ``u_x, u_y(, u_z)``.
    """
    if beam is None:
        beam = beam_of(result)
    s = beam.s_nodes[-1] if s is None else float(s)
    r0 = beam.position(beam.q_ref[beam.free], s)
    P = beam.point_matrix(s)   # r(s) = P expand(q), affine in q: one sparse product for all outputs
    full = np.repeat(beam.q_ref[None], result.t.size, axis=0)
    full[:, beam.free] = result.q
    u = (P @ full.T).T - r0
    if ax is None:
        ax = _new_axes(False)
    for k, name in enumerate("xyz"[:beam.element.dim]):
        ax.plot(result.t, u[:, k], label=f"u_{name}")
    ax.set_xlabel("t")
    ax.set_ylabel(f"displacement at s = {s:g}")
    ax.legend()
    return ax


def animate(result: Result, path: str | os.PathLike, *, beam: Beam | RigidBody | None = None, every: int = 1,
            fps: int = 20, dpi: int = 80) -> Path:
    """Write an animated GIF of the motion of a beam, a rigid body or a system of bodies.

    Parameters
    ----------
    result : Result
    path : str or path-like
        The ``.gif`` file to write.
    beam : Beam or RigidBody, optional
        Default: rebuilt from the description in ``result`` (a system's bodies too, as
        :func:`ancfdae.export.vtk` reads them).
    every : int
        Draw every ``every``-th output.
    fps : int
        Frames per second of the GIF.
    dpi : int
        Resolution of the frames.

    Returns
    -------
    pathlib.Path
        The file written. Frames share fixed axis limits (those of the whole motion). A System's joints
        (recorded in its result) are drawn as black dots.
    """
    path = validate.output_file("path", path, (".gif",))     # checked first: a bad path fails at once
    fps = validate.positive_int("fps", fps)
    dpi = validate.positive_int("dpi", dpi)
    from matplotlib.animation import PillowWriter       # matplotlib on first use, as in _new_axes
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if isinstance(every, bool) or not isinstance(every, int) or every < 1:
        raise ValueError(f"`every` must be a positive integer, got {every!r}.")
    if result.t.size == 0:
        raise ValueError("`result` has no outputs to animate.")
    parts = bodies_of(result, beam)
    frames = range(0, result.t.size, every)
    joints = joints_of(result, beam)
    joint_points = joint_series(joints, parts, result.q)[0] if joints else None
    fig = Figure(figsize=(6, 4))
    FigureCanvasAgg(fig)     # off-screen rendering, whatever backend pyplot uses
    three_d = _dim(parts[0][0]) == 3
    ax = fig.add_subplot(projection="3d" if three_d else None)
    directors = [output_directors(result, b) if len(parts) == 1 and not _is_rigid(b) else None for b, _ in parts]
    # Fixed limits: the extent of the drawn bodies over all frames.
    pts, pad = [], 0.0
    for (body, cols), d in zip(parts, directors):
        if _is_rigid(body):
            from .bodies.picture import box_points
            pts.append(box_points(body, result.q[list(frames)][:, cols]).reshape(-1, body.dim))
            continue
        pts += [section_vectors(body, result.q[i, cols], None if d is None else d[i])[0][:, :_dim(body)]
                for i in frames]
        sec = body.element.section
        pad = max(pad, 0.6 * max(getattr(sec, "h", 0.0), getattr(sec, "d", 0.0), np.sqrt(sec.A)))
    pts = np.concatenate(pts)
    lo, hi = pts.min(axis=0) - pad, pts.max(axis=0) + pad
    writer = PillowWriter(fps=fps)
    with writer.saving(fig, str(path), dpi=dpi):
        for i in frames:
            ax.clear()
            for (body, cols), d in zip(parts, directors):
                configuration(body, result.q[i, cols], ax, directors=None if d is None else d[i])
            if joint_points is not None:           # the joints as black dots
                ax.scatter(*joint_points[i, :, :3 if three_d else 2].T, color="k", s=12, zorder=5)
            if not three_d:
                ax.set_aspect("equal", adjustable="box")
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
            if three_d:
                ax.set_zlim(lo[2], hi[2])
            ax.set_title(f"t = {result.t[i]:.4g}")
            writer.grab_frame()
    logger.info("wrote %d frames to %s", len(frames), path)
    return path
