"""Dynamics at equal accuracy: work-precision of ancfdae's integrators against Exudyn's (same process).

``python -m benchmarks.work_precision [--elements 25 100] [--t-end 0.5] [--repeats 3] [--tol 1e-6]``

Problem: Exudyn's flexible pendulum example (flexiblePendulumANCF): L = 1 m, rho A = 10 kg/m,
EA = 5.25e7 N, EI = 10937.5 N m^2, hinged at x = 0 (position fixed, slope free), gravity 9.81 m/s^2
in -y, released horizontally from rest; BE2D elements on our side, ObjectANCFCable2D on Exudyn's:
the same semi-discrete model (same strain measures, same Gauss rules 5/3 points), so one reference
serves both.

Error: max over the output times (every 10 ms) of the distance of the free end to that of a
converged reference (ours, Lobatto IIIA-3 at ``--h-ref`` with Newton tolerance 1e-10; its own error
is estimated against the same method at twice the step and printed). Cost: process (CPU) time of
the solve call, model built untimed; medians of ``--repeats`` runs with every configuration of both
codes run once per round (interleaved, so both see the same machine load).

IDA (``--methods ida``): x is rtol; atol = (rtol, 100 rtol) for (q, v) and BDF order <= 2, so each
run ends in about a second (see ``OURS``); its Newton iteration is SUNDIALS' own (its nonlinear
tolerance is tied to rtol, ``--tol`` does not apply).

Newton: the same tolerance ``--tol`` on both sides: Exudyn's relative and absolute tolerance
(modified Newton, its example's settings, adaptive step on as in the example) and ours' relative
tolerance (max-norm of the residual over that of the step's first residual; modified Newton).
The definitions differ (Exudyn: 2-norm, reference residual adapted): say so when reading ratios.

Printed: every run (method, step or rtol, CPU s, error, Newton iterations per step, factorisations),
then at each accuracy level reached by an Exudyn run the cheapest run of each side at least as
accurate and the ratio ours / Exudyn's best (< 1: ours faster), then for every run of ours the
cheapest Exudyn run at least as accurate and the ratio (the per-method figure, e.g. for IDA); how
these ratios are formed: :mod:`benchmarks._equal_accuracy`. The per-run table is the full picture.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import simulate

from . import _equal_accuracy as equal
from .dynamics import pendulum as build_pendulum

try:
    from . import _exudyn_peer as peer
except ImportError:  # pragma: no cover
    peer = None

#: our configurations: method -> (options, list of step sizes or rtols)
OURS = {
    "lobatto3": ({}, [4e-3, 2e-3, 1e-3, 5e-4, 2.5e-4]),
    "generalized-alpha": ({"rho_inf": 0.8}, [4e-4, 2e-4, 1e-4, 5e-5]),
    # IDA: BDF capped at order 2 (A-stable) and atol per group (q: rtol m, v: 100 rtol m/s). Measured
    # (25 elements, [0, 0.5] s, shared 2-core machine): with order <= 5 and this atol, rtol 1e-6 and 1e-7
    # did not finish within 60 s (orders 3-5 are not A-stable: the undamped axial modes, EA = 5.25e7 N,
    # hold the step); the default atol (2 rtol on v) resolves those modes and did not finish in 25 min.
    # With order <= 2: 249 / 373 / 4,108 / 7,538 steps at rtol 1e-4 / 1e-5 / 1e-6 / 1e-7, each < 1 s CPU.
    "ida": ({"max_order": 2}, [1e-4, 1e-5, 1e-6, 1e-7, 1e-8]),
}
#: IDA's atol per coordinate group, as multiples of rtol: (positions and slopes, velocities)
IDA_ATOL = (1.0, 100.0)
#: Exudyn's integrators and their step sizes
PEER = {"trapezoidal": [4e-4, 2e-4, 1e-4, 5e-5], "generalized_alpha": [4e-4, 2e-4, 1e-4, 5e-5]}
DT_OUT = 0.01


def _tip_history(beam, res):
    full = np.tile(beam.q_ref, (len(res.t), 1))
    full[:, beam.free] = res.q
    return (beam.point_matrix(1.0) @ full.T).T     # (n_t, 2)


def run_ours(n, method, x, t_end, tol):
    """One timed run; x is the step (fixed-step methods) or rtol (IDA)."""
    opts = dict(OURS[method][0])
    if method == "ida":
        opts.update(rtol=x, atol=(IDA_ATOL[0] * x, IDA_ATOL[1] * x))
    else:
        opts.update(h=x, newton={"tol": tol})
    beam = build_pendulum(n)
    t_eval = np.linspace(0.0, t_end, int(round(t_end / DT_OUT)) + 1)
    c0 = time.process_time()
    res = simulate(beam, (0.0, t_end), method, t_eval=t_eval, **opts)
    cpu = time.process_time() - c0
    st = res.stats
    steps = max(int(st.get("steps", 0)), 1)
    return dict(cpu=cpu, tip=_tip_history(beam, res), t=np.asarray(res.t), ok=res.status == "success",
                it_per_step=st.get("newton_iterations", 0) / steps, lu=st.get("factorizations", -1),
                message=res.message)


def run_peer(n, integrator, h, t_end, tol):
    r = peer.pendulum(n, integrator=integrator, t_end=t_end, h=h, repeats=1, output_period=DT_OUT, newton_tol=tol)
    tip = np.column_stack([r["x"], r["y"]])
    return dict(cpu=r["cpu"], tip=tip, t=np.asarray(r["t"]), ok=True, it_per_step=r["newton_iterations_per_step"],
                lu=r["jacobians"], message="")


def reference(n, t_end, h_ref):
    """Reference tip history (Lobatto IIIA-3, h_ref, Newton tol 1e-10) and its estimated error."""
    fine = run_ours(n, "lobatto3", h_ref, t_end, 1e-10)
    coarse = run_ours(n, "lobatto3", 2 * h_ref, t_end, 1e-10)
    est = equal.tip_error(coarse, fine["t"], fine["tip"]) / 15.0   # order 4: e(h) ~ e(2h) / 16
    return fine["t"], fine["tip"], est


def case(n, t_end, repeats, tol, h_ref, methods):
    t_ref, tip_ref, est = reference(n, t_end, h_ref)
    print(f"\n== hinged pendulum, {n} BE2D / ObjectANCFCable2D elements, [0, {t_end}] s, Newton tol {tol}; "
          f"reference Lobatto IIIA-3 h = {h_ref:g} (estimated error {est:.1e} m)", flush=True)
    configs = [("ours", m, x) for m in methods for x in OURS[m][1]]
    if peer is not None and peer.available():
        configs += [("exudyn", m, h) for m, hs in PEER.items() for h in hs]

    def run(side, method, x):
        return run_ours(n, method, x, t_end, tol) if side == "ours" else run_peer(n, method, x, t_end, tol)

    runs = equal.interleaved(configs, run, repeats)
    rows = equal.table(runs, lambda c, r: equal.tip_error(r, t_ref, tip_ref), x_name="h or rtol",
                       columns=[("it/step", 8, ".2f", "it_per_step"), ("LU", 7, "d", "lu")])
    equal.summary(rows)
    equal.per_method(rows)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, nargs="+", default=[25, 100])
    ap.add_argument("--t-end", type=float, default=0.5)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--tol", type=float, default=1e-6, help="Newton tolerance, both sides")
    ap.add_argument("--h-ref", type=float, default=1e-4)
    ap.add_argument("--methods", nargs="+", default=list(OURS), choices=list(OURS))
    a = ap.parse_args(argv)
    if peer is None or not peer.available():
        print("exudyn not importable: ancfdae only (pip install '.[benchmark]')")
    print("CPU = process time; machine possibly shared: read the ratios, not the absolute times")
    for n in a.elements:
        case(n, a.t_end, a.repeats, a.tol, a.h_ref, a.methods)


if __name__ == "__main__":
    main()
