"""Exudyn import, availability and the settings and constraints every peer run shares.

Kept apart so that the peer's runners (``_exudyn_peer``, ``_exudyn_pendulum``) import one place that
decides which compiled Exudyn module is loaded.
"""
from __future__ import annotations

import sys

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

__all__ = ["available", "module_variant"]


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
