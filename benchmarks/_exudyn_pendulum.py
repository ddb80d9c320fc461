"""Exudyn's flexible pendulum (flexiblePendulumANCF, notes/exudyn.md) as a timed peer run.

ObjectANCFCable2D elements, hinged with gravity or free-flying; the energy is evaluated with Exudyn's
own strain measures and quadrature so that its conservation can be compared with ours.
"""
from __future__ import annotations

import numpy as np

from ancfdae._validate import choice, positive, positive_int
from ancfdae._quadrature import gauss_for_order
from ancfdae.models.shapes import hermite

from ._exudyn_base import _base_settings, _exu, _fix, _ground_marker, _ii, _require, timed_solves

__all__ = ["pendulum", "PENDULUM"]

#: flexiblePendulumANCF (notes/exudyn.md): L, rho A, EA = 2.1e10 * 0.05^2, EI = 2.1e10 * 0.05^4 / 12, g.
PENDULUM = dict(L=1.0, rhoA=10.0, EA=5.25e7, EI=10937.5, g=9.81)
_INTEGRATORS = {"trapezoidal", "generalized_alpha"}


def _cable2d_energy(q, v, le, rhoA, EA, EI, g):
    """Kinetic, strain and gravity energy of a chain of ObjectANCFCable2D elements (Exudyn's model).

    ``q`` and ``v`` are nodal (n_nodes, 4) arrays of total coordinates (x, y, x', y') and velocities.
    Strain energy int (EA eps^2 + EI K^2) / 2 with eps = |r'| - 1 and K = (r' x r'') / |r'|^2 (Exudyn's
    material curvature), on Exudyn's own Gauss rules: order 9 for the axial, order 5 for the bending
    term, so that it is the energy its equations of motion conserve. Kinetic energy exact (order 7).
    Gravity potential rhoA g int y dx (g along -y).
    """
    n_el = q.shape[0] - 1
    L = np.full(n_el, le)
    # element coordinates (n_el, 4 shapes, 2 components) in Hermite order (r_A, r'_A, r_B, r'_B)
    qe = np.stack([q[:-1, 0:2], q[:-1, 2:4], q[1:, 0:2], q[1:, 2:4]], axis=1)
    ve = np.stack([v[:-1, 0:2], v[:-1, 2:4], v[1:, 0:2], v[1:, 2:4]], axis=1)

    def field(order, which):
        s, w = gauss_for_order(order)
        shapes = hermite(s, L)
        return s, w, [np.einsum("eps,esc->epc", shapes[k], qe) for k in which], shapes

    _, w9, (d1,), _ = field(9, (1,))
    eps = np.linalg.norm(d1, axis=-1) - 1.0
    _, w5, (d1b, d2b), _ = field(5, (1, 2))
    K = (d1b[..., 0] * d2b[..., 1] - d1b[..., 1] * d2b[..., 0]) / np.sum(d1b**2, axis=-1)
    strain = 0.5 * le / 2 * (EA * np.sum(w9 * eps**2) + EI * np.sum(w5 * K**2))
    s7, w7 = gauss_for_order(7)
    N = hermite(s7, L)[0]
    rdot = np.einsum("eps,esc->epc", N, ve)
    r = np.einsum("eps,esc->epc", N, qe)
    kinetic = 0.5 * rhoA * le / 2 * np.sum(w7[None, :, None] * rdot**2)
    gravity = rhoA * g * le / 2 * np.sum(w7[None, :] * r[..., 1])
    return kinetic, strain, gravity


def _build_pendulum(n, free, output_period, energy_history):
    """flexiblePendulumANCF: n ObjectANCFCable2D on [0, L] along x, hinged at x = 0 with gravity,
    or free with v_y(x) = 2 sin(pi x / L) (slope velocities its x-derivative) and no gravity."""
    p = PENDULUM
    SC = _exu.SystemContainer()
    mbs = SC.AddSystem()
    le = p["L"] / n
    nodes = []
    for i in range(n + 1):
        x = i * le
        vel = [0.0, 0.0, 0.0, 0.0]
        if free:
            k = np.pi / p["L"]
            vel = [0.0, 2.0 * np.sin(k * x), 0.0, 2.0 * k * np.cos(k * x)]
        nodes.append(mbs.AddNode(_ii.NodePoint2DSlope1(referenceCoordinates=[x, 0.0, 1.0, 0.0],
                                                       initialVelocities=vel)))
    for e in range(n):
        oe = mbs.AddObject(_ii.ObjectANCFCable2D(nodeNumbers=[nodes[e], nodes[e + 1]], length=le,
                                                 massPerLength=p["rhoA"], axialStiffness=p["EA"],
                                                 bendingStiffness=p["EI"]))
        if not free:
            mm = mbs.AddMarker(_ii.MarkerBodyMass(bodyNumber=oe))
            mbs.AddLoad(_ii.LoadMassProportional(markerNumber=mm, loadVector=[0.0, -p["g"], 0.0]))
    if not free:
        _fix(mbs, _ground_marker(mbs), nodes[0], (0, 1))  # hinge: position fixed, slope free
    tip = mbs.AddSensor(_ii.SensorNode(nodeNumber=nodes[-1], storeInternal=True, writeToFile=False,
                                       outputVariableType=_exu.OutputVariableType.Position))
    state_sensors = []
    if energy_history:
        for nd in nodes:
            state_sensors.append(tuple(
                mbs.AddSensor(_ii.SensorNode(nodeNumber=nd, storeInternal=True, writeToFile=False,
                                             outputVariableType=ovt))
                for ovt in (_exu.OutputVariableType.Coordinates, _exu.OutputVariableType.Coordinates_t)))
    mbs.Assemble()
    return SC, mbs, nodes, tip, state_sensors


def _dynamic_settings(t_end, h, integrator, output_period, newton_tol=1e-6):
    """Exudyn's flexiblePendulumANCF settings: modified Newton, tolerances 1e-6, adaptive step on."""
    s = _base_settings()
    ti = s.timeIntegration
    ti.numberOfSteps = int(round(t_end / h))
    ti.endTime = t_end
    ti.newton.useModifiedNewton = True
    ti.newton.relativeTolerance = newton_tol
    ti.newton.absoluteTolerance = newton_tol
    ti.adaptiveStep = True
    ga = ti.generalizedAlpha
    if integrator == "trapezoidal":  # what DynamicSolverType.TrapezoidalIndex2 switches on
        ga.useNewmark, ga.useIndex2Constraints = True, True
        ga.newmarkBeta, ga.newmarkGamma = 0.25, 0.5
    else:
        ga.useNewmark, ga.useIndex2Constraints = False, False
        ga.spectralRadius = 0.8
    s.solution.sensors.writePeriod = output_period
    return s


def _nodal(mbs, nodes, vec):
    idx = np.array([mbs.GetNodeODE2Index(nd) for nd in nodes])[:, None] + np.arange(4)
    return np.asarray(vec)[idx]


def pendulum(n_elements, integrator="trapezoidal", free=False, t_end=3.0, h=1e-4, repeats=1,
             output_period=1e-3, energy_history=False, newton_tol=1e-6):
    """Exudyn's flexible pendulum (flexiblePendulumANCF, notes/exudyn.md) with ObjectANCFCable2D.

    L = 1 m, rho A = 10 kg/m, EA = 5.25e7 N, EI = 10937.5 N m^2, straight along +x at rest. Hinged
    at x = 0 (position fixed by ObjectConnectorCoordinate, slope free) under gravity 9.81 m/s^2 in -y;
    or, with ``free=True``, no hinge, no gravity and initial velocity v_y(x) = 2 sin(pi x / L).
    Constant step ``h``, modified Newton, relative and absolute tolerance 1e-6, EigenSparse, one
    thread. Only ``SolveSystem`` is timed.

    Parameters
    ----------
    n_elements : int
        Number of elements.
    integrator : {'trapezoidal', 'generalized_alpha'}
        Exudyn's TrapezoidalIndex2 (Newmark beta = 1/4, gamma = 1/2, index-2 constraints) or its
        generalized-alpha with spectral radius 0.8 (index 3).
    free : bool
        Free-flying variant instead of the hinged pendulum.
    t_end, h : float
        End time and step size in s.
    repeats : int
        Number of timed runs (fresh model each); the median wall time is reported.
    output_period : float
        Sampling period of the tip trajectory (Exudyn sensor, stored in memory).
    energy_history : bool
        Also sample all nodal coordinates and velocities to return the energy at every sample
        (adds sensor cost to the timed run; off for timing).
    newton_tol : float
        Exudyn's Newton ``relativeTolerance`` and ``absoluteTolerance`` (the example's 1e-6).

    Returns
    -------
    dict
        ``wall`` (median s), ``walls``, ``cpu`` (median process time, s), ``wall_per_simulated_second``; ``steps`` (time steps taken),
        ``newton_iterations`` (total), ``newton_iterations_per_step``, ``jacobians`` (Jacobian
        evaluations + factorisations); ``t``, ``x``, ``y``: trajectory of the last node;
        ``energy0`` and ``energy_end``: kinetic + strain + gravity energy at t = 0 and t_end
        (:func:`_cable2d_energy`), ``energy_drift`` = (energy_end - energy0) / energy scale, the scale
        being the initial kinetic energy (free) or m g L / 2 (pendulum); with ``energy_history``
        also ``energy`` (samples at ``t``) and ``energy_drift_max`` = max |energy - energy0| / scale.
    """
    n = positive_int("n_elements", n_elements)
    integrator = choice("integrator", integrator, _INTEGRATORS)
    t_end, h = positive("t_end", t_end), positive("h", h)
    repeats = positive_int("repeats", repeats)
    output_period = positive("output_period", output_period)
    _require()
    p = PENDULUM
    g = 0.0 if free else p["g"]
    le = p["L"] / n
    (SC, mbs, nodes, tip, state_sensors), solver, walls, cpus = timed_solves(
        lambda: _build_pendulum(n, free, output_period, energy_history),
        lambda: _dynamic_settings(t_end, h, integrator, output_period, newton_tol),
        _exu.MainSolverImplicitSecondOrder, repeats,
        f"Exudyn {integrator} failed for the {'free' if free else 'hinged'} beam")
    it = solver.it
    steps = int(it.currentStepIndex) - 1  # the index ends one past the last step taken
    wall = float(np.median(walls))
    ref = _nodal(mbs, nodes, mbs.systemData.GetODE2Coordinates(_exu.ConfigurationType.Reference))

    def energy(u, v):
        return sum(_cable2d_energy(ref + u, v, le, p["rhoA"], p["EA"], p["EI"], g))

    ini = _exu.ConfigurationType.Initial
    e0 = energy(_nodal(mbs, nodes, mbs.systemData.GetODE2Coordinates(ini)),
                _nodal(mbs, nodes, mbs.systemData.GetODE2Coordinates_t(ini)))
    e1 = energy(_nodal(mbs, nodes, mbs.systemData.GetODE2Coordinates()),
                _nodal(mbs, nodes, mbs.systemData.GetODE2Coordinates_t()))
    if free:  # initial kinetic energy
        scale = _cable2d_energy(ref, _nodal(mbs, nodes, mbs.systemData.GetODE2Coordinates_t(ini)),
                                le, p["rhoA"], p["EA"], p["EI"], 0.0)[0]
    else:  # m g L / 2: the potential energy the swing releases
        scale = p["rhoA"] * p["L"] * p["g"] * p["L"] / 2
    data = np.asarray(mbs.GetSensorStoredData(tip))
    out = dict(wall=wall, walls=walls, cpu=float(np.median(cpus)), wall_per_simulated_second=wall / t_end, steps=steps,
               newton_iterations=int(it.newtonStepsCount), newton_iterations_per_step=it.newtonStepsCount / steps,
               jacobians=int(it.newtonJacobiCount), t=data[:, 0], x=data[:, 1], y=data[:, 2],
               energy0=float(e0), energy_end=float(e1), energy_drift=float((e1 - e0) / scale))
    if energy_history:
        qs = [np.asarray(mbs.GetSensorStoredData(sq))[:, 1:] for sq, _ in state_sensors]
        vs = [np.asarray(mbs.GetSensorStoredData(sv))[:, 1:] for _, sv in state_sensors]
        out["energy"] = np.array([energy(np.stack([q[k] for q in qs]), np.stack([v[k] for v in vs]))
                                  for k in range(len(data))])
        out["energy_drift_max"] = float(np.max(np.abs(out["energy"] - e0)) / scale)
    return out
