"""Exudyn as the peer in our benchmarks: the same problems, solved by Exudyn, timed the same way.

Exudyn (C++ core, Python interface, ``pip install exudyn``) is the closest peer of ancfdae; its
author's earlier code HOTINT produced the chapter's results. Each runner builds an Exudyn model
outside the timed part, times only the solver call (``MainSolver*.SolveSystem``) with
``time.perf_counter``, single thread, EigenSparse, and returns plain numbers so that a benchmark can
print the ratio to ancfdae. Run ``python -m benchmarks._exudyn_peer`` for a table of all runners.

Runners
-------
cantilever_be2d
    B1 (chapter Sect. 5.1, benchmarks.md) with ``ObjectANCFCable2D`` (the BE2D of chapter Sect. 3).
cantilever_beam3d
    B1 with ``ObjectANCFBeam`` (shear deformable, linear, the nearest Exudyn has to SQ3D).
pendulum
    Exudyn's ``flexiblePendulumANCF`` example (hinged, gravity) or its free-flying variant
    (implemented in ``_exudyn_pendulum``, re-exported here).

Newton tolerance of the static runs
-----------------------------------
Our solver stops when max|R| / max|R_0| < 1e-8 with R_0 the first residual of the load step, which
for B1 is the load increment F/10 at the tip. Exudyn measures ||R||_2 of its whole residual (ODE2
part including the reactions C_q^T lambda, plus the constraint equations) and stops when
||R||_2 / R_ref <= ``relativeTolerance`` or ||R||_2 <= ``absoluteTolerance``. Its R_ref is the
residual with the Lagrange multipliers reset to zero (so it contains the previous step's reaction)
and, by default (``adaptInitialResidual``), is replaced by the first iterate's residual when that is
larger (2.3e7 N against F/10 = 1.3e5 N in the first step at 64 elements): ``relativeTolerance =
1e-8`` is up to ~200 times looser than our test (44 instead of 49 Newton iterations for B1).
The equivalent used here is ``absoluteTolerance = 1e-8 F / n_steps`` with ``relativeTolerance =
1e-14`` (off) and ``adaptInitialResidual = False``: at convergence the
reactions balance, so ||R||_2 <= 1e-8 max|R_0| implies our criterion (and is stricter by at most
the 2-norm/max-norm factor).
"""
from __future__ import annotations

import numpy as np

from ancfdae._validate import positive_int

from ._exudyn_base import (_base_settings, _exu, _fix, _ground_marker, _ii, _require, available, module_variant,
                           square_section, timed_solves)
from ._exudyn_pendulum import PENDULUM, pendulum

__all__ = ["available", "module_variant", "cantilever_be2d", "cantilever_beam3d", "cantilever_ge3d",
           "cantilever_ge2d", "pendulum", "B1", "B1_REF_BE",
           "B1_REF_SQ", "PENDULUM"]

#: B1 data (benchmarks.md): L, side a of the square section, E, nu, rho, and the tip force 3EI/L^2.
B1 = dict(L=2.0, a=0.1, E=2.07e11, nu=0.3, rho=7800.0, F=3 * 2.07e11 * 0.1**4 / 12 / 2.0**2)
#: Reference tip displacements of B1 (chapter Eq. 113): Bernoulli-Euler and shear deformable.
B1_REF_BE = (-0.50853730436, 1.20723985455)
B1_REF_SQ = (-0.50946471774, 1.20882282955)
_B1_LOAD_STEPS = 10
_B1_TOL = 1e-8
_K_TORSION = 0.8436  # Saint-Venant factor of a square, benchmarks.md "Common definitions"


def _static_settings(criterion="ours"):
    """B1 load stepping and the Newton stopping rule: ours (module docstring) or Exudyn's default.

    ``criterion="exudyn"`` keeps Exudyn's own relative test (``relativeTolerance = 1e-8`` with
    ``adaptInitialResidual``): up to ~200 times looser than ours, but the strict absolute form
    cannot be met beyond ~128 elements, where the residual's round-off floor exceeds it. A float
    criterion is Exudyn's own test with that ``relativeTolerance`` (looser still).
    """
    if isinstance(criterion, float):
        s = _static_settings("exudyn")
        s.staticSolver.newton.relativeTolerance = criterion
        return s
    if criterion not in ("ours", "exudyn"):
        raise ValueError(f"`criterion` must be 'ours', 'exudyn' or a float, got {criterion!r}.")
    s = _base_settings()
    st = s.staticSolver
    st.numberOfLoadSteps = _B1_LOAD_STEPS
    st.adaptiveStep = False  # exactly 10 uniform steps; a failed step is an error, not a refinement
    st.newton.useModifiedNewton = False  # full Newton
    st.newton.maxIterations = 25
    if criterion == "exudyn":
        st.newton.relativeTolerance = _B1_TOL
        return s
    st.newton.relativeTolerance = 1e-14
    st.newton.absoluteTolerance = _B1_TOL * B1["F"] / _B1_LOAD_STEPS
    st.newton.adaptInitialResidual = False
    return s

def _b1_tip_load(mbs, node):
    m = mbs.AddMarker(_ii.MarkerNodePosition(nodeNumber=node))
    mbs.AddLoad(_ii.LoadForceVector(markerNumber=m, loadVector=[0.0, B1["F"], 0.0]))


def _build_b1_be2d(n):
    """B1 with ObjectANCFCable2D: clamp x, y, y' of node 0 (not x'), dead tip force on the last node."""
    a, E = B1["a"], B1["E"]
    SC = _exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = _ground_marker(mbs)
    le = B1["L"] / n
    nodes = [mbs.AddNode(_ii.NodePoint2DSlope1(referenceCoordinates=[i * le, 0.0, 1.0, 0.0])) for i in range(n + 1)]
    for e in range(n):
        mbs.AddObject(_ii.ObjectANCFCable2D(nodeNumbers=[nodes[e], nodes[e + 1]], length=le,
                                            massPerLength=B1["rho"] * a**2, axialStiffness=E * a**2,
                                            bendingStiffness=E * a**4 / 12))
    _fix(mbs, ground, nodes[0], (0, 1, 3))  # x, y, r'_y (benchmarks.md B1 clamp of BE2D)
    _b1_tip_load(mbs, nodes[-1])
    mbs.Assemble()
    return SC, mbs, nodes[-1]


def _build_b1_beam3d(n):
    """B1 with ObjectANCFBeam (NodePointSlope23: r, r_y, r_z): clamp all 9 coordinates of node 0.

    Section stiffness diag(EA, k_s GA, k_s GA, k_t G J, E I2, E I3) with Cowper's k_s (chapter Eq. 112),
    J = I2 + I3 and k_t = 0.8436 (benchmarks.md); the cross-section penalty factors are Exudyn's
    defaults (1, 1, 1).
    """
    sec = _section_b1()
    SC = _exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = _ground_marker(mbs)
    le = B1["L"] / n
    nodes = [mbs.AddNode(_ii.NodePointSlope23(referenceCoordinates=[i * le, 0, 0, 0, 1, 0, 0, 0, 1]))
             for i in range(n + 1)]
    for e in range(n):
        mbs.AddObject(_ii.ObjectANCFBeam(nodeNumbers=[nodes[e], nodes[e + 1]], length=le, sectionData=sec))
    _fix(mbs, ground, nodes[0], range(9))  # position and both cross-section slopes
    _b1_tip_load(mbs, nodes[-1])
    mbs.Assemble()
    return SC, mbs, nodes[-1]


def _section_b1():
    """B1's section for Exudyn's 3D beams: diag(EA, k_s GA, k_s GA, k_t G J, E I2, E I3) (chapter Eq. 112)."""
    return square_section(B1["E"], B1["nu"], B1["rho"], B1["a"], _K_TORSION)


def _build_b1_ge3d(n):
    """B1 with ObjectBeamGeometricallyExact (Simo-Reissner, rotation-vector nodes): clamp node 0 (6 coordinates)."""
    sec = _section_b1()
    SC = _exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = _ground_marker(mbs)
    le = B1["L"] / n
    nodes = [mbs.AddNode(_ii.NodeRigidBodyRotVecLG(referenceCoordinates=[i * le, 0, 0, 0, 0, 0]))
             for i in range(n + 1)]
    for e in range(n):
        mbs.AddObject(_ii.ObjectBeamGeometricallyExact(nodeNumbers=[nodes[e], nodes[e + 1]], length=le,
                                                       sectionData=sec))
    _fix(mbs, ground, nodes[0], range(6))
    _b1_tip_load(mbs, nodes[-1])
    mbs.Assemble()
    return SC, mbs, nodes[-1]


def _build_b1_ge2d(n):
    """B1 with ObjectBeamGeometricallyExact2D (planar Simo-Reissner, nodes x, y, phi): clamp node 0."""
    a, E, nu, rho = B1["a"], B1["E"], B1["nu"], B1["rho"]
    G = E / (2 * (1 + nu))
    ks = 10 * (1 + nu) / (12 + 11 * nu)
    SC = _exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = _ground_marker(mbs)
    le = B1["L"] / n
    nodes = [mbs.AddNode(_ii.NodeRigidBody2D(referenceCoordinates=[i * le, 0, 0])) for i in range(n + 1)]
    for e in range(n):
        mbs.AddObject(_ii.ObjectBeamGeometricallyExact2D(
            nodeNumbers=[nodes[e], nodes[e + 1]], length=le, massPerLength=rho * a**2,
            crossSectionInertia=rho * a**4 / 12, bendingStiffness=E * a**4 / 12, axialStiffness=E * a**2,
            shearStiffness=ks * G * a**2))
    _fix(mbs, ground, nodes[0], range(3))
    _b1_tip_load(mbs, nodes[-1])
    mbs.Assemble()
    return SC, mbs, nodes[-1]


def cantilever_ge3d(n_elements, repeats=3, criterion="ours"):
    """B1 with Exudyn's ObjectBeamGeometricallyExact, its strongest 3D beam (shear deformable).

    Same load stepping, tolerance and timing as :func:`cantilever_be2d`; nodes NodeRigidBodyRotVecLG
    (position, rotation vector), node 0 clamped, section stiffness of :func:`_section_b1`, error
    against the shear-deformable reference of chapter Eq. 113. Returns the keys of
    :func:`cantilever_be2d`.
    """
    return _cantilever(_build_b1_ge3d, n_elements, repeats, B1_REF_SQ, criterion)


def cantilever_ge2d(n_elements, repeats=3, criterion="ours"):
    """B1 with Exudyn's ObjectBeamGeometricallyExact2D (planar Simo-Reissner beam, k_s G A shear stiffness).

    Same as :func:`cantilever_ge3d` in the plane (nodes NodeRigidBody2D).
    """
    return _cantilever(_build_b1_ge2d, n_elements, repeats, B1_REF_SQ, criterion)


def _cantilever(build, n_elements, repeats, reference, criterion="ours"):
    n = positive_int("n_elements", n_elements)
    repeats = positive_int("repeats", repeats)
    _require()
    (SC, mbs, tip), solver, walls, cpus = timed_solves(
        lambda: build(n), lambda: _static_settings(criterion), _exu.MainSolverStatic, repeats,
        f"Exudyn static solver failed for B1 with {n} elements")
    u = np.asarray(mbs.GetNodeOutput(tip, _exu.OutputVariableType.Displacement))[:2]
    ref = np.asarray(reference)
    err = float(np.linalg.norm(u - ref))
    return dict(tip=(float(u[0]), float(u[1])), error=err, rel_error=err / float(np.linalg.norm(ref)),
                wall_median=float(np.median(walls)), walls=walls, cpu_median=float(np.median(cpus)),
                newton_iterations=solver.it.newtonStepsCount, jacobians=solver.it.newtonJacobiCount,
                n_dof=int(mbs.systemData.ODE2Size()))


def cantilever_be2d(n_elements, repeats=3, criterion="ours"):
    """Benchmark B1 (chapter Sect. 5.1) with Exudyn's ObjectANCFCable2D (BE2D).

    ``n_elements`` ObjectANCFCable2D elements with NodePoint2DSlope1 nodes (x, y, x', y'); node 0
    clamped on x, y and y' by ObjectConnectorCoordinate (x' free, as benchmarks.md and Exudyn's
    ANCFcantileverTest); dead tip force 3EI/L^2 in +y via LoadForceVector on a MarkerNodePosition of
    the last node; static solver, 10 uniform load steps, full Newton with the stopping rule of the
    module docstring, EigenSparse, one thread.

    Parameters
    ----------
    n_elements : int
        Number of elements (>= 1).
    repeats : int
        Number of timed solves (each on a freshly built model); the median is reported.
    criterion : {"ours", "exudyn"} or float
        Newton stopping rule: the equivalent of ours, or Exudyn's default (see ``_static_settings``).

    Returns
    -------
    dict
        ``tip`` (ux, uy) in m; ``error`` |u - u_ref| in m and ``rel_error`` = error / |u_ref| against
        chapter Eq. 113 (BE); ``wall_median`` and ``walls`` in s (solve call only);
        ``newton_iterations`` and ``jacobians`` (totals over the 10 load steps of the last solve);
        ``n_dof`` (Exudyn's ODE2 coordinates, the clamped ones included).
    """
    return _cantilever(_build_b1_be2d, n_elements, repeats, B1_REF_BE, criterion)


def cantilever_beam3d(n_elements, repeats=3, criterion="ours"):
    """Benchmark B1 with Exudyn's ObjectANCFBeam (shear deformable, linear, finite-difference Jacobian).

    Same load stepping, tolerance and timing as :func:`cantilever_be2d`; nodes NodePointSlope23
    (r, r_y, r_z), all 9 coordinates of node 0 fixed, the error measured against the
    shear-deformable reference of chapter Eq. 113 (SQ2D/SQ3D).

    Parameters
    ----------
    n_elements : int
        Number of elements (>= 1).
    repeats : int
        Number of timed solves; the median is reported.

    Returns
    -------
    dict
        Same keys as :func:`cantilever_be2d`.
    """
    return _cantilever(_build_b1_beam3d, n_elements, repeats, B1_REF_SQ, criterion)

def main(argv=None):
    """Print the peer's numbers: B1 with both elements, then the pendulum runs (median of repeats)."""
    import argparse

    ap = argparse.ArgumentParser(prog="python -m benchmarks._exudyn_peer", description=main.__doc__)
    ap.add_argument("--repeats", type=int, default=3, help="timed runs per case (median printed)")
    args = ap.parse_args(argv)
    if not available():
        print("exudyn is not installed; nothing to measure.")
        return 1
    print(f"Exudyn {_exu.__version__} ({module_variant()} module), 1 thread, EigenSparse, "
          f"median of {args.repeats}, solve call only")
    print(f"\nB1 cantilever, 10 load steps, full Newton, ||R||_2 <= 1e-8 F/10")
    print(f"{'element':<20}{'n_el':>5}{'dof':>6}{'ux':>16}{'uy':>16}{'|u-u_ref|':>11}{'rel':>10}"
          f"{'Newton':>8}{'wall ms':>10}")
    for name, runner in (("ANCFCable2D (BE)", cantilever_be2d), ("ANCFBeam (SQ ref)", cantilever_beam3d)):
        meshes, errors = (8, 16, 32, 64), []
        for n in meshes:
            r = runner(n, repeats=args.repeats)
            errors.append(r["error"])
            print(f"{name:<20}{n:>5}{r['n_dof']:>6}{r['tip'][0]:>16.11f}{r['tip'][1]:>16.11f}{r['error']:>11.3e}"
                  f"{r['rel_error']:>10.2e}{r['newton_iterations']:>8}{1e3 * r['wall_median']:>10.2f}")
        order = -np.polyfit(np.log(meshes), np.log(errors), 1)[0]
        print(f"{name:<20} convergence order (least-squares fit of log error on log n_el): {order:.2f}")
    print("\nflexiblePendulumANCF, ObjectANCFCable2D, 3 s, h = 1e-4, modified Newton, tol 1e-6")
    print(f"{'run':<12}{'n_el':>5}{'integrator':>19}{'wall s/s':>10}{'it/step':>9}{'Jacobians':>10}"
          f"{'tip x(3 s)':>12}{'tip y(3 s)':>12}{'dE/E_ref':>11}")
    for free, n, integ in ((False, 25, "trapezoidal"), (False, 25, "generalized_alpha"),
                           (True, 25, "trapezoidal"), (False, 100, "trapezoidal")):
        r = pendulum(n, integrator=integ, free=free, repeats=args.repeats)
        print(f"{'free' if free else 'pendulum':<12}{n:>5}{integ:>19}{r['wall_per_simulated_second']:>10.3f}"
              f"{r['newton_iterations_per_step']:>9.2f}{r['jacobians']:>10}{r['x'][-1]:>12.6f}{r['y'][-1]:>12.6f}"
              f"{r['energy_drift']:>11.2e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
