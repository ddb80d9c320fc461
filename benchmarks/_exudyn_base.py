"""Exudyn import, availability, and what every peer run shares: settings, constraints, section, timing.

Kept apart so that the peer's runners (``_exudyn_peer``, ``_exudyn_pendulum``, ``sq3d_dynamics``)
import one place that decides which compiled Exudyn module is loaded and how a solve is timed.
"""
from __future__ import annotations

import sys
import time

import numpy as np

# Exudyn's own speed mode (exudynCPPfast: no range checks, AVX2), as its flexiblePendulumANCF example
# uses; 25-30 % faster for ObjectANCFBeam. Only chosen here if nobody imported or configured exudyn
# before; Exudyn falls back to the standard module on CPUs without AVX2. See :func:`module_variant`.
if "exudyn" not in sys.modules and not hasattr(sys, "exudynFast"):
    sys.exudynFast = True

try:  # Exudyn is an optional dependency (the `benchmark` extra)
    import exudyn as _exu
    from exudyn import itemInterface as _ii
except ImportError:  # pragma: no cover - exercised only where exudyn is missing
    _exu = None
    _ii = None

__all__ = ["available", "module_variant", "square_section", "timed_solves"]


def available() -> bool:
    """True if Exudyn can be imported (the peer runners need it)."""
    return _exu is not None


def module_variant() -> str:
    """Which compiled Exudyn module is loaded: 'fast' (exudynCPPfast), 'standard' or 'missing'."""
    if _exu is None:
        return "missing"
    return "fast" if "exudyn.exudynCPPfast" in sys.modules else "standard"


def _require():
    if _exu is None:
        raise ImportError("exudyn is not installed; `pip install exudyn` (the `benchmark` extra).")


def _base_settings():
    """Settings common to every run: sparse LU, one thread, no files, no console output."""
    s = _exu.SimulationSettings()
    s.linearSolver.solverType = _exu.LinearSolverType.EigenSparse
    s.parallel.numberOfThreads = 1
    s.solution.file.write = False
    s.show.statistics = False
    s.show.computationTime = False
    s.staticSolver.verboseMode = 0
    s.timeIntegration.verboseMode = 0
    return s


def _ground_marker(mbs):
    """A coordinate marker on a ground node: the fixed side of ObjectConnectorCoordinate."""
    ng = mbs.AddNode(_ii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
    return mbs.AddMarker(_ii.MarkerNodeCoordinate(nodeNumber=ng, coordinate=0))


def _fix(mbs, ground, node, coordinates):
    """Fix the given coordinates of ``node`` to their reference values (as ANCFcantileverTest)."""
    for c in coordinates:
        m = mbs.AddMarker(_ii.MarkerNodeCoordinate(nodeNumber=node, coordinate=c))
        mbs.AddObject(_ii.ObjectConnectorCoordinate(markerNumbers=[ground, m]))


def square_section(E: float, nu: float, rho: float, a: float, k_t: float):
    """Exudyn's BeamSection of a square of side ``a`` for its 3D beams.

    Stiffness diag(EA, k_s GA, k_s GA, k_t G J, E I2, E I3) with Cowper's k_s (chapter Eq. 112) and
    J = I2 + I3; mass rho A per length; inertia rho diag(J, I2, I3).
    """
    G = E / (2 * (1 + nu))
    ks = 10 * (1 + nu) / (12 + 11 * nu)
    A, I = a**2, a**4 / 12
    sec = _exu.BeamSection()
    sec.stiffnessMatrix = np.diag([E * A, ks * G * A, ks * G * A, k_t * G * 2 * I, E * I, E * I])
    sec.massPerLength = rho * A
    sec.inertia = rho * np.diag([2 * I, I, I])
    return sec


def timed_solves(build, settings, solver_type, repeats: int, failure: str):
    """Solve ``repeats`` fresh models, timing only ``SolveSystem``, one thread as configured.

    Parameters
    ----------
    build : callable
        ``build() -> (SC, mbs, ...)``, called untimed before each solve (``SC`` owns ``mbs``: the
        tuple keeps it alive).
    settings : callable
        ``settings() -> SimulationSettings`` of each solve.
    solver_type : type
        E.g. ``exudyn.MainSolverStatic`` or ``exudyn.MainSolverImplicitSecondOrder``.
    repeats : int
    failure : str
        The message of the RuntimeError raised when a solve fails.

    Returns
    -------
    model : tuple
        What the last ``build()`` returned, solved.
    solver
        The last solver (its ``it`` holds the iteration counts).
    walls, cpus : list of float
        Wall-clock and process time of each solve, s.
    """
    walls, cpus = [], []
    for _ in range(repeats):
        model = build()
        solver = solver_type()
        s = settings()
        c0, t0 = time.process_time(), time.perf_counter()
        ok = solver.SolveSystem(model[1], s)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
        if not ok:
            raise RuntimeError(failure)
    return model, solver, walls, cpus
