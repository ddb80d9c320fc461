"""The flexible multibody benchmarks B5-B7 built from beams, rigid bodies and joints.

B5 spin-up of a flexible beam (Simo & Vu-Quoc 1986), B6 flexible slider-crank and B7 flexible spatial
pendulum with a spinning payload, as the project's benchmark definitions give them (revision 1; B7's rod
stiffness is an argument because revision 2 is proposed with E = 5e7). Each builder returns a
:class:`Benchmark`: the :class:`ancfdae.System`, its time span and the outputs of a result (functions of
``(t, q, v, lam)`` arrays), so that the study and the tests read every benchmark the same way. The joints
and the System come from :mod:`ancfdae.joints` (imported when a builder runs).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ancfdae import CircularSection, Gravity, Material, RectangularSection, RigidBody
from ancfdae.models import BE2D, SQ2D, SQ3D, Beam, Cable3D

__all__ = ["Benchmark", "hub_angle", "crank_angle", "spinup", "slider_crank", "spatial_pendulum", "BUILDERS"]

#: B7's gravity (m/s^2, along -e_z)
GRAVITY = 9.81
#: B5 data: beam length, EA, EI, rho A, spin-up time and end time (benchmarks B5).
SPINUP = dict(L=10.0, EA=2.8e7, EI=1.4e4, rhoA=1.2, T_s=15.0, t_end=30.0)


@dataclass
class Benchmark:
    """A built benchmark: the system, its time span and named outputs.

    Attributes
    ----------
    system : ancfdae.System
    t_span : tuple of float
    outputs : dict of str -> callable
        ``output(t, q, v, lam) -> ndarray`` over the output times of a result.
    bodies : dict of str -> body
        The bodies by role (``"beam"``, ``"crank"``, ``"rod"``, ``"slider"``, ``"payload"``).
    rows : dict of str -> slice
        Where named multipliers sit in ``lam`` (``"hub"``, ``"slider_normal"``, ...).
    """

    system: object
    t_span: tuple
    outputs: dict = field(default_factory=dict)
    bodies: dict = field(default_factory=dict)
    rows: dict = field(default_factory=dict)


def hub_angle(t: float, w_s: float, T_s: float = SPINUP["T_s"]) -> tuple[float, float, float]:
    """B5's hub angle, rate and acceleration: ``theta = (w_s/T_s)(t^2/2 + (T_s/2 pi)^2 (cos(2 pi t/T_s) - 1))``
    up to ``T_s``, ``w_s (t - T_s/2)`` after (the rate rises smoothly from 0 to ``w_s``)."""
    if t <= T_s:
        c = 2.0 * math.pi / T_s
        return (w_s / T_s * (0.5 * t * t + (math.cos(c * t) - 1.0) / (c * c)),
                w_s / T_s * (t - math.sin(c * t) / c), w_s / T_s * (1.0 - math.cos(c * t)))
    return w_s * (t - 0.5 * T_s), w_s, 0.0


def crank_angle(t: float, w_s: float = 100.0, T_r: float = 0.2) -> tuple[float, float, float]:
    """B6's crank angle, rate and acceleration: ``w = w_s (1 - cos(pi t/T_r))/2`` up to ``T_r``, ``w_s`` after."""
    if t <= T_r:
        c = math.pi / T_r
        return (0.5 * w_s * (t - math.sin(c * t) / c), 0.5 * w_s * (1.0 - math.cos(c * t)),
                0.5 * w_s * c * math.sin(c * t))
    return 0.5 * w_s * T_r + w_s * (t - T_r), w_s, 0.0


def _rows(system, prefix: str) -> slice:
    """The rows of ``system`` whose labels start with ``prefix`` (a joint's name), as one slice."""
    idx = [i for i, lab in enumerate(system.constraint_labels) if lab.startswith(prefix)]
    if not idx or idx != list(range(idx[0], idx[-1] + 1)):
        raise ValueError(f"no contiguous constraint rows named {prefix!r} in {system.constraint_labels}.")
    return slice(idx[0], idx[-1] + 1)


def spinup(element: str = "BE2D", n_elements: int = 8, w_s: float = 4.0) -> Benchmark:
    """B5: a beam clamped to a hub at the origin whose angle is :func:`hub_angle` (no rigid body needed).

    The clamp is a :class:`~ancfdae.joints.Prescribed` joint at node 0: its position stays at the origin
    and its slope direction follows the hub (the slope's length is free, as the peer's hub clamp).
    """
    from ancfdae import System
    from ancfdae.joints import Prescribed
    L, T_s = SPINUP["L"], SPINUP["T_s"]
    side = math.sqrt(6.0e-3)            # A = 6e-3 m^2 and I = A^2/12 = 3e-6 m^4 exactly
    mat = Material(E=SPINUP["EA"] / 6.0e-3, nu=0.3, rho=SPINUP["rhoA"] / 6.0e-3)
    el = {"BE2D": BE2D, "SQ2D": SQ2D}[element](mat, RectangularSection(side))
    beam = Beam(el, n_elements, L)
    # the drives return plain numbers: the compiled steps tabulate them once per step, and a tuple of floats
    # converts several times faster than one of 1-element arrays (B6 at h = 1e-4: ~7 -> ~2 us a step)
    hub = Prescribed((beam, 0), position=lambda t: ((0.0, 0.0), (0.0, 0.0), (0.0, 0.0)),
                     angle=lambda t: hub_angle(t, w_s, T_s), name="hub")
    system = System([beam], [hub])
    s_tip = beam.s_nodes[-1]
    P = beam.point_matrix(s_tip)
    rows = {"hub_angle": _rows(system, "hub")}
    rows["hub_angle"] = slice(rows["hub_angle"].stop - 1, rows["hub_angle"].stop)

    def deflection(t, q, v, lam):
        th = np.array([hub_angle(ti, w_s, T_s)[0] for ti in t])
        full = np.repeat(beam.q_ref[None], len(t), axis=0)
        full[:, beam.free] = q
        r = (P @ full.T).T
        return -np.sin(th) * r[:, 0] + np.cos(th) * r[:, 1]

    def torque(t, q, v, lam):
        # The angle row g = r'(0) . (-sin th, cos th): its reaction on the slope is -lam n, whose moment
        # about the clamped node is -lam |r'(0)| (r' x n = |r'| e_z).
        return -lam[:, rows["hub_angle"]][:, 0] * np.array([np.hypot(*_slope0(beam, qi)) for qi in q])
    return Benchmark(system, (0.0, SPINUP["t_end"]), {"tip_deflection": deflection, "hub_torque": torque},
                     {"beam": beam}, rows)


def _slope0(beam, q):
    """The axial slope ``r'`` at node 0 (BE2D and SQ2D: the coordinates after the position)."""
    return beam.nodal(q)[0, 2:4]


def slider_crank(element: str = "BE2D", n_elements: int = 8, w_s: float = 100.0, T_r: float = 0.2,
                 slider_inertia: float = 1.0e-6) -> Benchmark:
    """B6: a driven rigid crank, a flexible connecting rod (BE2D or SQ2D) and a slider on a prismatic joint.

    The crank (0.15 m, 0.5 kg uniform bar: ``I = m l^2/12`` about its centre) is pinned to the ground at its
    reference point, the origin, and its director ``d1`` turns with :func:`crank_angle`; the rod (0.3 m,
    d = 0.01 m, E = 2e9, rho = 1200) is pinned to the crank's end and to the slider (0.02 kg, a rigid body
    whose free rotation is not coupled to anything; ``slider_inertia`` only keeps its mass matrix regular),
    which slides on the line y = 0.
    """
    from ancfdae import System
    from ancfdae.joints import Prescribed, Prismatic, Spherical
    el = {"BE2D": BE2D, "SQ2D": SQ2D}[element](Material(E=2.0e9, nu=0.3, rho=1200.0), CircularSection(0.01))
    crank = RigidBody(0.5, 0.5 * 0.15 ** 2 / 12, [0.0, 0.0], com=[0.075, 0.0], name="crank")
    rod = Beam(el, n_elements, 0.3, start=[0.15, 0.0])
    slider = RigidBody(0.02, slider_inertia, [0.45, 0.0], name="slider")
    joints = [Spherical((crank, (0.0, 0.0)), "ground", name="crank pivot"),
              Prescribed((crank, (0.0, 0.0)), angle=lambda t: crank_angle(t, w_s, T_r), name="crank drive"),
              Spherical((crank, (0.15, 0.0)), (rod, 0), name="crank pin"),
              Spherical((rod, -1), (slider, (0.0, 0.0)), name="slider pin"),
              Prismatic((slider, (0.0, 0.0)), "ground", direction=[1.0, 0.0], name="slider guide")]
    system = System([crank, rod, slider], joints)
    rows = {"crank_drive": _rows(system, "crank drive"), "slider_guide": _rows(system, "slider guide")}
    o_rod, o_sl = system.offsets[1], system.offsets[2]
    P = np.vstack([rod.point_matrix(s).toarray() for s in (0.0, 0.15, 0.3)])

    def midpoint_deflection(t, q, v, lam):
        full = np.repeat(rod.q_ref[None], len(t), axis=0)
        full[:, rod.free] = q[:, o_rod:o_rod + rod.n_dof]
        r = (P @ full.T).T.reshape(len(t), 3, 2)
        chord = r[:, 2] - r[:, 0]
        normal = np.column_stack([-chord[:, 1], chord[:, 0]]) / np.linalg.norm(chord, axis=1)[:, None]
        return np.einsum("nd,nd->n", r[:, 1] - 0.5 * (r[:, 0] + r[:, 2]), normal)

    return Benchmark(system, (0.0, 0.5), {
        "midpoint_deflection": midpoint_deflection,
        "slider_x": lambda t, q, v, lam: q[:, o_sl],
        # reactions -G^T lam: on the slider along the guide's normal, the drive's moment on the crank
        "slider_normal_force": lambda t, q, v, lam: -lam[:, rows["slider_guide"]][:, 0],
        "crank_torque": lambda t, q, v, lam: -lam[:, rows["crank_drive"]][:, 0],
    }, {"crank": crank, "rod": rod, "slider": slider}, rows)


def angular_momentum_z(system, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``L_z = int (r x r_dot)_z dm`` of a spatial system whose coordinates are 3-vectors that rotate alike
    (every ANCF node vector and a rigid body's point and directors): with ``M = Ms (x) I_3``,
    ``L = sum_ab Ms_ab q_a x v_b``."""
    Ms = system.mass().toarray()[0::3, 0::3]
    Q, V = q.reshape(len(q), -1, 3), v.reshape(len(v), -1, 3)
    return (np.einsum("na,ab,nb->n", Q[..., 0], Ms, V[..., 1]) - np.einsum("na,ab,nb->n", Q[..., 1], Ms, V[..., 0]))


def spatial_pendulum(element: str = "SQ3D", n_elements: int = 4, E: float = 5.0e9, t_end: float = 5.0,
                     spin: float = 2.0, thickness: float = 0.01) -> Benchmark:
    """B7: a rod (SQ3D or Cable3D) on a spherical joint at the origin, a rigid disk welded to its lower end.

    Rod: 1 m, d = 0.02 m, ``E`` (5e9 in revision 1), rho = 1000, tilted 30 degrees from -e_z towards +e_x;
    disk: 1 kg, radius 0.1 m, centre at the rod's end, axis (its director ``d3``) along the rod; gravity
    9.81 along -e_z; the whole assembly turns rigidly about e_z at ``spin`` rad/s at t = 0. The weld is a
    :class:`~ancfdae.joints.Rigid` joint with the disk as side ``a`` (the rod end's frame vectors are
    combinations of the disk's directors).

    ``thickness`` (default 1 cm; revision 1 has a thin disk) adds ``m h^2/12`` to the diametral moments: a
    thin disk is a lamina whose mass matrix is singular along its axis director, which the energy-momentum
    integrator's factorisation of ``M`` alone does not accept; 1 cm changes the diametral moment by 0.33 %.
    """
    from ancfdae import System
    from ancfdae.joints import Rigid, Spherical
    el = {"SQ3D": SQ3D, "Cable3D": Cable3D}[element](Material(E=E, nu=0.3, rho=1000.0), CircularSection(0.02))
    a = math.radians(30.0)
    axis = np.array([math.sin(a), 0.0, -math.cos(a)])
    w = np.array([0.0, 0.0, spin])
    g = Gravity([0.0, 0.0, -GRAVITY])
    # A rigid rotation turns every nodal vector (position and slopes) alike: v = w x vector.
    nodal = Beam(el, n_elements, 1.0, direction=axis).q_ref.reshape(n_elements * (el.n_nodes - 1) + 1, -1, 3)
    rod = Beam(el, n_elements, 1.0, direction=axis, loads=[g],
               initial_velocity=np.cross(w, nodal).reshape(nodal.shape[0], -1))
    e1 = np.array([math.cos(a), 0.0, math.sin(a)])
    R = np.column_stack([e1, np.cross(axis, e1), axis])          # d3 along the rod
    m, r = 1.0, 0.1
    i_d = m * r * r / 4 + m * thickness ** 2 / 12
    disk = RigidBody(m, [i_d, i_d, m * r * r / 2], axis, R, velocity=np.cross(w, axis),
                     angular_velocity=w, loads=[g], name="payload")
    system = System([rod, disk], [Spherical((rod, 0), "ground", name="pivot"),
                                  Rigid((disk, (0.0, 0.0, 0.0)), (rod, -1), name="weld")])
    o, pivot = system.offsets[1], _rows(system, "pivot")
    # the coordinates of a unit rigid translation along e_z: every node's position and the payload's point
    lift = np.zeros(system.n_dof)
    lift[system.offsets[0]:system.offsets[0] + rod.n_dof] = (
        Beam(el, n_elements, 1.0, direction=axis, start=(0.0, 0.0, 1.0)).q_ref - rod.q_ref)[rod.free]
    lift[o + 2] = 1.0
    momentum = system.mass() @ lift          # P_z = lift^T M v (M constant: Cable3D and natural coordinates)

    def pivot_force_mean_z(t, q, v, lam):
        # The pivot's vertical reaction on the rod averaged over each output interval, from the vertical
        # momentum balance dP_z/dt = F_z - m g of the whole pendulum: (P_z(t_k) - P_z(t_k-1)) / dt + m g at
        # t_k, the point value -lam_z at t_0. Not the point value at every t_k: that carries the rod's axial
        # modes up to 5.6e3 rad/s, excited by the release of the unstretched rod, which no affordable step
        # resolves (docs/studies.md, "B7: the pivot force").
        P = v @ momentum
        mean = np.diff(P) / np.diff(t) + (lift @ momentum) * GRAVITY
        return np.r_[-lam[:1, pivot][:, 2], mean]

    return Benchmark(system, (0.0, t_end), {
        "payload": lambda t, q, v, lam: q[:, o:o + 3],
        "pivot_force_mean_z": pivot_force_mean_z,
        "energy": lambda t, q, v, lam: np.array([system.energy(ti, qi, vi).total for ti, qi, vi in zip(t, q, v)]),
        "angular_momentum_z": lambda t, q, v, lam: angular_momentum_z(system, q, v),
    }, {"rod": rod, "payload": disk}, {"pivot": pivot, "weld": _rows(system, "weld")})


#: The builders by benchmark name.
BUILDERS: dict[str, Callable[..., Benchmark]] = {"B5": spinup, "B6": slider_crank, "B7": spatial_pendulum}
