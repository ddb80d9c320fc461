"""The free flying beams of benchmarks B2 and B3 (chapter Sects. 5.2, 5.3) and their shared tools.

Both beams (the project's B2/B3 definitions, revision 2): L = 1 m, square section a = 0.05 m, E = 1e5 N/m^2,
nu = 0.3, rho = 2500 kg/m^3 (chapter Eq. 114), free-free, straight and at
rest along ``r(s) = s (0.6, 0.8[, 0])``; B is the end s = 0.

* B2 (in plane, revision 2): dead force ``f(t) (0.24, 0) N`` and moment
  ``f(t) 0.24 N m`` about +e_z at B, pulse ``f(t) = (1 - cos(2 pi t / T_p)) / 2``
  for ``t <= T_p = 2.5 s``, 0 after. (Revision 1 had 0.8 N and 0.8 N m,
  M L / EI = 15: that motion is chaotic after about 6 s, and eps_T over
  [0, 10] s then converges at order 0.5-0.8 whatever the step.)
* B3 (in space, revision 2): dead moment ``f(t) (0.1, 0.05, 0.2) N m`` at B
  with the hat ``f(t) = t/1.5`` up to 1.5 s, down to 0 at 3 s. (Revision 1
  had four times that moment: the beam spun about its axis at up to
  284 rad/s and BE3D failed within 1.2-2.3 s on every mesh.)

:func:`simulate_case` runs one case and returns a record
(the :class:`ancfdae.Result` with the tip and energy monitors, CPU time), which
the runner (:func:`studies._common.run_cases`) stores as soon as the case
finishes; :func:`unpack` turns it into the arrays the analyses use. :func:`eps_T` is the
integrated tip error of chapter Eq. 115.
"""
from __future__ import annotations

import time

import numpy as np

from ancfdae import Material, PointForce, PointMoment, RectangularSection, hat, pulse
from ancfdae import models
from ancfdae.integrators import NewtonOptions
from ancfdae.monitors import EnergyMonitor, PointSensor
from ancfdae.simulate import simulate

from ._common import Case

__all__ = ["Case", "MATERIAL", "SECTION", "LENGTH", "T_PULSE", "T_HAT", "OWN_NEWTON", "B2_FORCE", "B2_MOMENT", "B3_MOMENT", "FAMILY",
           "available", "b2_beam", "b3_beam",
           "output_times", "simulate_case", "unpack", "eps_T", "regress_order", "steady_drift"]

MATERIAL = Material(E=1e5, nu=0.3, rho=2500.0)
SECTION = RectangularSection(0.05)
LENGTH = 1.0
T_PULSE = 2.5      # B2: end of the load pulse (s)
T_HAT = 3.0        # B3: end of the moment hat (s)
#: methods whose own Newton default (driven to round-off) the studies keep unless told otherwise
OWN_NEWTON = ("energy-momentum", "energy-collocation")
B2_FORCE = 0.24    # B2: peak force (N, global x), revision 2
B2_MOMENT = 0.24   # B2: peak moment (N m, about +e_z), revision 2
B3_MOMENT = (0.1, 0.05, 0.2)   # B3: peak moment (N m, global axes), revision 2

#: element type -> family whose 128-element solution is the reference (chapter Sect. 5.2:
#: "different for thin and for shear deformable beams").
FAMILY = {"BE2D": "BE", "BE3D": "BE", "SQ2D": "SQ", "SQ3D": "SQ"}


def available(names) -> list[str]:
    """The element types of ``names`` that ancfdae.models provides."""
    return [n for n in names if hasattr(models, n)]


def _element(name, E_scale=1.0, **options):
    if not hasattr(models, name):
        raise ValueError(f"`element` must be one of {available(FAMILY)}, got {name!r}.")
    mat = MATERIAL if E_scale == 1.0 else Material(E=MATERIAL.E * E_scale, nu=MATERIAL.nu, rho=MATERIAL.rho)
    return getattr(models, name)(mat, SECTION, **options)


def b2_beam(name: str, n_elements: int, E_scale: float = 1.0, **element_options):
    """B2, the beam flying in plane; 3D element types move in the plane z = 0.

    ``E_scale`` multiplies Young's modulus (a stiffer variant for the
    integrator study).
    """
    el = _element(name, E_scale, **element_options)
    f = pulse(T_PULSE)
    if el.dim == 2:
        kw, F, M = dict(start=(0.0, 0.0), direction=(0.6, 0.8)), (B2_FORCE, 0.0), B2_MOMENT
    else:
        kw, F, M = (dict(start=(0.0, 0.0, 0.0), direction=(0.6, 0.8, 0.0)), (B2_FORCE, 0.0, 0.0),
                    (0.0, 0.0, B2_MOMENT))
    return models.Beam(el, n_elements, LENGTH, loads=[PointForce(F, node=0, time=f), PointMoment(M, node=0, time=f)],
                       **kw)


def b3_beam(name: str, n_elements: int, t_load: float = T_HAT, scale: float = 1.0, **element_options):
    """B3, the beam flying in space (3D element types only).

    ``t_load`` (end of the hat: 3 s) and ``scale`` (of the
    moment) give the shorter, gentler variant of the quick modes.
    """
    el = _element(name, **element_options)
    if el.dim != 3:
        raise ValueError(f"`element` of B3 must be a spatial type, got {name!r}.")
    moment = scale * np.array(B3_MOMENT)
    return models.Beam(el, n_elements, LENGTH, start=(0.0, 0.0, 0.0), direction=(0.6, 0.8, 0.0),
                       loads=[PointMoment(moment, node=0, time=hat(t_load / 2))])


def output_times(t_end: float, dt_out: float) -> np.ndarray:
    """Output grid ``0, dt_out, 2 dt_out, ...`` that ends exactly at ``t_end`` and never passes it.

    ``k * dt_out`` in floating point can exceed ``t_end`` by an ulp (e.g.
    ``140 * 0.01 > 1.4``), which the integrators reject; the last sample is
    clamped to ``t_end``, and ``t_end`` is appended if it is not a multiple.
    """
    if not (t_end > 0 and dt_out > 0):
        raise ValueError(f"`t_end` and `dt_out` must be positive, got {t_end!r} and {dt_out!r}.")
    n = int(np.floor(t_end / dt_out + 1e-9))
    t = np.arange(n + 1) * dt_out
    t[-1] = min(t[-1], t_end)
    if t_end - t[-1] > 1e-9 * dt_out:
        t = np.append(t, t_end)
    return t


def simulate_case(beam, t_end: float, method: str = "lobatto3", h: float | None = 1e-3, dt_out: float = 0.01,
                  newton: dict | None = None, energy: bool = True, stop_on_blowup: bool = False,
                  monitors: tuple = (), **options) -> dict:
    """Integrate ``beam`` over ``[0, t_end]``; return the run's record.

    Parameters
    ----------
    beam : Beam
    t_end : float
    method, h, **options
        Passed to :func:`ancfdae.simulate` (``h`` must be None for IDA).
    dt_out : float
        Output interval of the tip position and the energy log (a multiple of
        ``h`` keeps the samples on the step grid, without interpolation).
    newton : dict, optional
        :class:`NewtonOptions` fields; default modified Newton, tol 1e-8
        (chapter Sect. 5.2). The energy-conserving methods (:data:`OWN_NEWTON`) keep their own
        default (round-off tolerance: what makes them conserve energy) unless ``newton`` is given.
    energy : bool
        Log the energy balance (costs a few external-power evaluations per step).
    stop_on_blowup : bool
        End the run when the energy monitor flags a blow-up (10 % drift).
    monitors : tuple of Monitor
        Logged beside the tip and the energy (e.g. :class:`ancfdae.DirectorGeometry`).

    Returns
    -------
    dict
        ``result`` (the :class:`ancfdae.Result`, monitors ``tip`` and
        ``energy``), ``cpu`` (process seconds), ``wall``, ``dof``: what the
        study's runner stores per case; :func:`unpack` gives the arrays the
        analyses use.
    """
    t_eval = output_times(t_end, dt_out)
    monitors = [PointSensor(s=0.0, name="tip"), *monitors]
    if energy:
        monitors.append(EnergyMonitor(stop_on_blowup=stop_on_blowup))
    if method != "ida" and not (method in OWN_NEWTON and newton is None):
        options["newton"] = NewtonOptions(**({"tol": 1e-8, "jacobian": "modified"} | (newton or {})))
    c0, w0 = time.process_time(), time.perf_counter()
    res = simulate(beam, (0.0, t_end), method=method, h=h, t_eval=t_eval, monitors=monitors, **options)
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    return {"result": res, "cpu": cpu, "wall": wall, "dof": int(beam.n_dof)}


def unpack(record: dict) -> dict:
    """The analysis view of a stored record: the other entries plus ``t``, ``tip``, ``energy``, ``stats``,
    ``status``, ``message``, ``t_fail`` from its Result (the coordinate history is dropped)."""
    res = record["result"]
    out = {k: v for k, v in record.items() if k != "result"}
    en = None
    if "energy" in res.monitors:
        log = res.monitors["energy"]
        en = {k: np.asarray(log[k]) for k in ("kinetic", "strain", "work", "total", "balance")}
        t_blow = log.get("t_blow_up")
        # None when no blow-up; a file format without null may give NaN back
        en["t_blow_up"] = None if t_blow is None or not np.isfinite(t_blow) else float(t_blow)
    out.update(t=res.t, tip=np.asarray(res.monitors["tip"]["position"]).reshape(res.t.size, -1), energy=en,
               stats=dict(res.stats), status=res.status, message=res.message, t_fail=res.t_fail,
               options=dict(res.options),
               monitors={k: v for k, v in res.monitors.items() if k not in ("tip", "energy")})
    return out


def eps_T(t, tip, t_ref, tip_ref) -> float:
    """Integrated tip error of chapter Eq. 115, ``(int_0^T |u_ref - u|^2 dt)^(1/2)``.

    The displacements share their initial position, so ``u_ref - u`` is the
    difference of positions. The run's samples are matched to the reference's
    by time (both on the same output grid); the integral is the trapezoidal
    rule over the samples up to the end of the shorter of the two histories
    (a failed run or reference ends early: compare ``t[-1]``). Only the first
    two components are compared (3D types moving in the plane against a
    planar reference lose nothing: their z stays 0).
    """
    t, t_ref = np.asarray(t), np.asarray(t_ref)
    keep = t <= t_ref[-1] + 1e-9
    t, tip = t[keep], np.asarray(tip)[keep]
    idx = np.searchsorted(t_ref, t - 1e-9)
    if t.size < 2 or np.any(np.abs(t_ref[np.minimum(idx, t_ref.size - 1)] - t) > 1e-9):
        raise ValueError("`t` must be a subset of the reference's output times.")
    d = tip[:, :2] - np.asarray(tip_ref)[idx, :2]
    e2 = np.sum(d * d, axis=1)
    return float(np.sqrt(np.sum(0.5 * (e2[1:] + e2[:-1]) * np.diff(t))))


def regress_order(x, y) -> float:
    """Observed order ``p`` of ``y ~ C x^-p`` by a least-squares line on log-log data."""
    return float(-np.polyfit(np.log(np.asarray(x, float)), np.log(np.asarray(y, float)), 1)[0])


def steady_drift(t, balance, t_from: float) -> dict:
    """Energy drift after the load ends: max |E - E(t_from)| and the fitted rate dE/dt (per s)."""
    t, balance = np.asarray(t), np.asarray(balance)
    m = (t >= t_from - 1e-9) & np.isfinite(balance)
    if m.sum() < 2:
        return {"max": float("nan"), "rate": float("nan"), "final": float("nan")}
    tb, eb = t[m], balance[m]
    return {"max": float(np.max(np.abs(eb - eb[0]))), "rate": float(np.polyfit(tb, eb, 1)[0]),
            "final": float(eb[-1] - eb[0])}
