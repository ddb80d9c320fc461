"""Dynamics benchmark: Exudyn's flexible pendulum (flexiblePendulumANCF) with every ancfdae integrator.

``python -m benchmarks.dynamics [--elements 25 100] [--t-end 3.0] [--h 1e-4] [--repeats 3] [--tol 1e-8]``

Problem (notes/exudyn.md): L = 1 m, rho A = 10 kg/m, EA = 5.25e7 N, EI = 10937.5 N m^2, BE2D
elements, hinged at x = 0 (position fixed, slope free), gravity 9.81 m/s^2 in -y, released
horizontally from rest; and a free-flying variant (no hinge, no gravity, v_y(x) = 2 sin(pi x / L)).
Fixed step h for the fixed-step integrators, rtol for IDA.

Printed per case and integrator: median wall seconds per simulated second (model built outside the
timed part, output every 10 ms, no monitors), Newton iterations per step, factorisations, relative
energy drift max|E - E0| / scale (scale: m g L / 2 hinged, initial kinetic energy free; evaluated
after the run from the output states), the tip position at t_end, and -- with Exudyn importable,
run in the same process, interleaved with ours -- Exudyn's figures and the ratio ancfdae / Exudyn
(< 1: ancfdae faster). ``--profile`` adds where our time goes (model residual, model Jacobian,
LU factorisation and solves, the rest) per Newton iteration.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import Gravity, Material, RectangularSection, simulate
from ancfdae.models import BE2D, Beam

try:
    from . import _exudyn_peer as peer
except ImportError:  # pragma: no cover
    peer = None

#: flexiblePendulumANCF: a 0.05 m square section with E = 2.1e10 and rho = 4000 gives the peer's
#: rho A = 10 kg/m, EA = 5.25e7 N, EI = 10937.5 N m^2.
MATERIAL = dict(E=2.1e10, nu=0.3, rho=4000.0)
SIDE = 0.05
G = 9.81

#: our integrators and the Exudyn integrator each is compared with
METHODS = {
    "lobatto3": ({}, "trapezoidal"),
    "lobatto2": ({}, "trapezoidal"),
    "newmark": ({}, "trapezoidal"),
    "generalized-alpha": ({"rho_inf": 0.8}, "generalized_alpha"),
    # IDA's cost hinges on the velocity atol. Measured (25 elements, 3 s): default atol: 75.7 (hinged) and
    # 38.4 (free) s per simulated s, energy drift 3.2e-4 / 5.5e-5; atol=(1e-6, 1e-2): 0.23 / 1.6 s per s
    # but drift 1.8e-2 / 0.17 and tip 2 cm off at 3 s (BDF2 damping with large steps).
    "ida": ({"rtol": 1e-6}, None),
}


#: BE2D kernel option ("auto": numba when importable); set by --kernel
KERNEL = "auto"


def pendulum(n_elements: int, free: bool = False) -> Beam:
    """The flexible pendulum (hinged, gravity) or its free-flying variant as a Beam of BE2D."""
    el = BE2D(Material(**MATERIAL), RectangularSection(SIDE), kernel=KERNEL)
    if free:
        return Beam(el, n_elements=n_elements, length=1.0,
                    initial_velocity=lambda p: np.column_stack([0 * p[:, 0], 2 * np.sin(np.pi * p[:, 0])]))
    return Beam(el, n_elements=n_elements, length=1.0, supports={0: ("x", "y")}, loads=[Gravity((0.0, -G))])


def _scale(beam, free):
    q0, v0 = beam.initial_state()
    return beam.energy(0.0, q0, v0).kinetic if free else 10.0 * 1.0 * G * 0.5


class _Timed:
    """Wraps a model; accumulates wall time of residual and Jacobian calls (for --profile)."""

    def __init__(self, model):
        self.m, self.t_res, self.t_jac = model, 0.0, 0.0
        self.n_dof, self.mass_is_constant = model.n_dof, model.mass_is_constant

    def __getattr__(self, name):
        return getattr(self.m, name)

    def residual(self, *args):
        t0 = time.perf_counter()
        r = self.m.residual(*args)
        self.t_res += time.perf_counter() - t0
        return r

    def residual_stages(self, *args):
        t0 = time.perf_counter()
        r = self.m.residual_stages(*args)
        self.t_res += time.perf_counter() - t0
        return r

    def jacobian(self, *args):
        t0 = time.perf_counter()
        j = self.m.jacobian(*args)
        self.t_jac += time.perf_counter() - t0
        return j


def ours(method, n_elements, free, t_end, h, tol, profile=False):
    """One timed run of ours; returns figures."""
    opts, _ = METHODS[method]
    beam = pendulum(n_elements, free)
    model = _Timed(beam) if profile else beam
    kw = dict(opts)
    if method != "ida":
        kw.update(h=h, newton={"tol": tol})
    t_eval = np.linspace(0.0, t_end, int(round(t_end / 0.01)) + 1)
    lu = {"t": 0.0}
    if profile and method != "ida":
        import ancfdae.integrators._newton as nw
        orig_f, orig_s = nw._Factor.__init__, nw._Factor.solve

        def f_init(self, m):
            t0 = time.perf_counter()
            orig_f(self, m)
            lu["t"] += time.perf_counter() - t0

        def f_solve(self, r):
            t0 = time.perf_counter()
            x = orig_s(self, r)
            lu["t"] += time.perf_counter() - t0
            return x
        nw._Factor.__init__, nw._Factor.solve = f_init, f_solve
    t0 = time.perf_counter()
    try:
        res = simulate(model, (0.0, t_end), method, t_eval=t_eval, **kw)
    finally:
        if profile and method != "ida":
            nw._Factor.__init__, nw._Factor.solve = orig_f, orig_s
    wall = time.perf_counter() - t0
    E = np.array([beam.energy(t, q, v).total for t, q, v in zip(res.t, res.q, res.v)])
    st = res.stats
    out = dict(wall=wall, status=res.status, steps=st["steps"], iterations=st["newton_iterations"],
               factorizations=st["factorizations"], drift=float(np.max(np.abs(E - E[0])) / _scale(beam, free)),
               tip=beam.position(res.q[-1], 1.0), message=res.message)
    if profile:
        it = max(st["newton_iterations"], 1)
        out["profile_us"] = dict(residual=model.t_res / it * 1e6, jacobian=model.t_jac / it * 1e6,
                                 lu=lu["t"] / it * 1e6,
                                 rest=(wall - model.t_res - model.t_jac - lu["t"]) / it * 1e6,
                                 residual_calls_per_it=st["residual_evals"] / it)
    return out


def exudyn(integrator, n_elements, free, t_end, h):
    """One timed Exudyn run (None when Exudyn is missing)."""
    if peer is None or not peer.available():
        return None
    r = peer.pendulum(n_elements, integrator=integrator, free=free, t_end=t_end, h=h, repeats=1)
    return dict(wall=r["wall"], iterations=r["newton_iterations"], steps=r["steps"], jacobians=r["jacobians"],
                drift=abs(r["energy_drift"]), tip=np.array([r["x"][-1], r["y"][-1]]))


def run_case(n_elements, free, methods, t_end, h, tol, repeats, profile):
    label = f"{'free-flying' if free else 'hinged pendulum'}, {n_elements} BE2D elements"
    beam = pendulum(n_elements, free)
    print(f"\n== {label} ({beam.n_dof} coordinates), t_end = {t_end} s, h = {h} s, Newton tol {tol}")
    hdr = (f"{'integrator':<20}{'s/sim-s':>9}{'it/step':>8}{'LU':>6}{'drift':>10}"
           f"{'tip x':>10}{'tip y':>10}{'exudyn s/s':>11}{'ex it/st':>9}{'ex drift':>10}{'ratio':>7}")
    print(hdr)
    peers: dict = {}
    for method in methods:
        ex_name = METHODS[method][1]
        walls, ex_walls, ratios, last, ex_last = [], [], [], None, None
        for _ in range(repeats):  # interleave ours and the peer so both see the same machine load
            last = ours(method, n_elements, free, t_end, h, tol)
            walls.append(last["wall"])
            if ex_name is not None:
                if ex_name not in peers or len(peers[ex_name]) < repeats:
                    ex = exudyn(ex_name, n_elements, free, t_end, h)
                    if ex is not None:
                        peers.setdefault(ex_name, []).append(ex)
                lst = peers.get(ex_name, [])
                if lst:
                    ex_last = lst[min(len(walls), len(lst)) - 1]
                    ratios.append(last["wall"] / ex_last["wall"])
        w = float(np.median(walls)) / t_end
        line = (f"{method:<20}{w:9.3f}{last['iterations'] / max(last['steps'], 1):8.2f}{last['factorizations']:6d}"
                f"{last['drift']:10.2e}{last['tip'][0]:10.5f}{last['tip'][1]:10.5f}")
        if ex_last is not None:
            exw = float(np.median([p["wall"] for p in peers[ex_name]])) / t_end
            line += (f"{exw:11.3f}{ex_last['iterations'] / ex_last['steps']:9.2f}{ex_last['drift']:10.2e}"
                     f"{float(np.median(ratios)):7.2f}")
        print(line + ("" if last["status"] == "success" else f"   FAILED: {last['message']}"), flush=True)
        if profile:
            p = ours(method, n_elements, free, t_end, h, tol, profile=True)["profile_us"]
            print(f"{'':<20}per Newton iteration: residual {p['residual']:.1f} us "
                  f"({p['residual_calls_per_it']:.2f} calls), Jacobian {p['jacobian']:.1f} us, "
                  f"LU {p['lu']:.1f} us, rest {p['rest']:.1f} us", flush=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, nargs="+", default=[25, 100])
    ap.add_argument("--t-end", type=float, default=3.0)
    ap.add_argument("--h", type=float, default=1e-4)
    ap.add_argument("--tol", type=float, default=1e-8, help="Newton relative tolerance (chapter: 1e-8)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--methods", nargs="+", default=list(METHODS), choices=list(METHODS))
    ap.add_argument("--no-free", action="store_true", help="skip the free-flying variant")
    ap.add_argument("--kernel", default="auto", choices=["auto", "numpy", "numba"], help="BE2D kernel option")
    ap.add_argument("--profile", action="store_true", help="one extra run per integrator, timing its parts")
    a = ap.parse_args(argv)
    if peer is None or not peer.available():
        print("exudyn not importable: printing ancfdae only (pip install '.[benchmark]')")
    else:
        print(f"exudyn module: {peer.module_variant()}")
    global KERNEL
    KERNEL = a.kernel
    print(f"BE2D kernel: {a.kernel} -> {pendulum(1).element.kernel_in_use}")
    for n in a.elements:
        run_case(n, False, a.methods, a.t_end, a.h, a.tol, a.repeats, a.profile)
    if not a.no_free:
        run_case(a.elements[0], True, a.methods, a.t_end, a.h, a.tol, a.repeats, a.profile)


if __name__ == "__main__":
    main()
