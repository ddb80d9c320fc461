"""Flexible multibody benchmarks B5 and B6 at equal accuracy: ancfdae against Exudyn (same process).

``python -m benchmarks.multibody_vs_exudyn [--cases b5 b6] [--t-end-b5 5] [--t-end-b6 0.1] [--repeats 3]
[--methods generalized-alpha lobatto3 ida]``

Models: B5 spin-up (8 BE2D / ObjectANCFCable2D elements, w_s = 4 rad/s; ours
``studies._multibody_models.spinup``, Exudyn's ``_exudyn_spinup.spinup`` with its hub clamp) and B6
slider-crank (8 elements; ``slider_crank`` on each side). The same semi-discrete beam on both sides
(same strain measures and Gauss rules), the clamp and joints written differently (ours: a Prescribed
joint and rotationless rigid bodies; Exudyn: a rigid hub or crank with a rotation coordinate).

Error: max over the output times of the compared channels, **each code against its own converged
reference** of the same mesh (generalized-alpha at ``h_ref`` on its side; its own error estimated
from the run at 2 h_ref, order 2: |e(2h) - e(h)| / 3, and printed). B5 compares the tip deflection in
the hub frame (m); B6 the slider position and the rod's midpoint deflection from its chord (m, the
norm of both). The difference between the two references is printed as the codes' agreement.

Cost: process time of the solve call (model built untimed), median of ``--repeats`` rounds with every
configuration of both codes run once per round (:mod:`benchmarks._equal_accuracy`).

Newton: relative tolerance 1e-8 and absolute tolerance 1e-6 on both sides, ours in a norm no looser than
Exudyn's. Exudyn (``CSolverBase::Newton``, its modified Newton) stops when the 2-norm of its residual
``[M a - f + G^T lam; g]`` is within 1e-8 of the step's first one (taken at lam = 0) or within 1e-6: its force
rows in N, its constraint rows ``g`` in m, unscaled. Ours stops when the max-norm of ``[r + G^T lam; s m g]``
is within 1e-8 of the step's first one (taken at the last step's lam), within ``1e-6 / sqrt(N)`` (N unknowns:
then the 2-norm of the force rows is within 1e-6 too) or at the residual's round-off floor; its constraint
rows are scaled by ``s m ~ 1e8`` kg/s^2, so ours holds ``g`` far tighter than Exudyn. IDA (x = rtol) has
SUNDIALS' own Newton test. Generalized-alpha: spectral radius 0.9 on both sides. A failed run (either side)
is printed and not timed; the final line counts them.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from ancfdae import simulate
from ancfdae.studies._multibody_models import slider_crank as our_slider_crank
from ancfdae.studies._multibody_models import spinup as our_spinup

from . import _equal_accuracy as equal
from ._exudyn_base import available, module_variant
from ._exudyn_constrained import NEWTON_ATOL   # Exudyn's, of every constrained peer run

try:
    from ._exudyn_slider_crank import slider_crank as peer_slider_crank
    from ._exudyn_spinup import spinup as peer_spinup
except ImportError:  # pragma: no cover - exudyn missing
    peer_spinup = peer_slider_crank = None

NEWTON_RTOL = 1e-8
RHO_INF = 0.9
N_ELEMENTS = 8
#: per case: output period (s), reference step of each side, our methods' steps (IDA: rtol), Exudyn's steps
CASES = {
    "b5": dict(dt_out=0.02, h_ref=1.25e-3,  # dt_out >= every step: each run samples every output time
               ours={"generalized-alpha": [2e-2, 1e-2, 5e-3, 2.5e-3], "lobatto3": [5e-2, 2.5e-2, 1.25e-2],
                     "ida": [1e-4, 1e-5]},  # quick study: rtol 1e-5 takes 8 s CPU on [0, 4] s
               exudyn={"generalized_alpha": [2e-2, 1e-2, 5e-3, 2.5e-3]}),
    "b6": dict(dt_out=1e-3, h_ref=2.5e-5,
               ours={"generalized-alpha": [2e-4, 1e-4, 5e-5], "lobatto3": [4e-4, 2e-4, 1e-4],
                     "ida": [1e-4, 1e-5]},  # rtol 1e-6: 46 s CPU on [0, 0.02] s
               exudyn={"generalized_alpha": [2e-4, 1e-4, 5e-5]}),
}


def _ours_outputs(case, b, res):
    """The compared channels of a result of ours, columns of an array (m)."""
    o = b.outputs
    args = (np.asarray(res.t), np.asarray(res.q), np.asarray(res.v), np.asarray(res.lam))
    if case == "b5":
        return o["tip_deflection"](*args)[:, None]
    return np.column_stack([o["slider_x"](*args), o["midpoint_deflection"](*args)])


def run_ours(case, method, x, t_end):
    """One timed run of ours; ``x`` is the step (fixed-step methods) or rtol (IDA)."""
    b = our_spinup("BE2D", N_ELEMENTS, w_s=4.0) if case == "b5" else our_slider_crank("BE2D", N_ELEMENTS)
    if method == "ida":
        opts = dict(rtol=x)
    else:
        n_unknowns = b.system.n_dof + b.system.n_constraints
        opts = dict(h=x, newton={"tol": NEWTON_RTOL, "residual_atol": NEWTON_ATOL / np.sqrt(n_unknowns)})
        if method == "generalized-alpha":
            opts["rho_inf"] = RHO_INF
    dt = CASES[case]["dt_out"]
    t_eval = np.linspace(0.0, t_end, int(round(t_end / dt)) + 1)
    c0 = time.process_time()
    res = simulate(b.system, (0.0, t_end), method, t_eval=t_eval, **opts)
    cpu = time.process_time() - c0
    ok = res.status == "success" and np.asarray(res.t).size == t_eval.size
    return dict(ok=ok, message=f"{res.status}: {res.message}", cpu=cpu, t=np.asarray(res.t),
                tip=_ours_outputs(case, b, res) if ok else None)


def run_peer(case, integrator, h, t_end):
    """One timed Exudyn run (not strict: a failure comes back with ``ok`` False and its reason)."""
    dt = CASES[case]["dt_out"]
    if case == "b5":
        r = peer_spinup(N_ELEMENTS, h, integrator, w_s=4.0, t_end=t_end, output_period=dt, rho_inf=RHO_INF,
                        strict=False)
        tip = r["deflection"][:, None] if r["ok"] else None
    else:
        r = peer_slider_crank(N_ELEMENTS, h, integrator, t_end=t_end, output_period=dt, rho_inf=RHO_INF,
                              strict=False)
        tip = np.column_stack([r["slider_x"], r["mid_deflection"]]) if r["ok"] else None
    if r["ok"] and r["t"].size != int(round(t_end / dt)) + 1:
        r = dict(r, ok=False, reason=f"{r['t'].size} samples, expected {int(round(t_end / dt)) + 1}")
    return dict(ok=r["ok"], message=r["reason"], cpu=r["cpu"], t=r["t"], tip=tip)


def _reference(side, case, t_end):
    """Generalized-alpha at h_ref on ``side`` and its estimated error (against the run at 2 h_ref)."""
    h = CASES[case]["h_ref"]
    run = run_ours if side == "ours" else run_peer
    method = "generalized-alpha" if side == "ours" else "generalized_alpha"
    fine, coarse = run(case, method, h, t_end), run(case, method, 2 * h, t_end)
    for r in (fine, coarse):
        if not r["ok"]:
            raise RuntimeError(f"{case}: {side} reference run failed ({r['message']})")
    return fine, equal.tip_error(coarse, fine["t"], fine["tip"]) / 3.0


def case_run(case, t_end, repeats, methods):
    """Print the table of runs and the ratios at equal accuracy of one case; return the rows."""
    c = CASES[case]
    refs = {side: _reference(side, case, t_end) for side in ("ours", "exudyn")}
    agree = equal.tip_error(refs["exudyn"][0], refs["ours"][0]["t"], refs["ours"][0]["tip"])
    print(f"\n== {case.upper()}, {N_ELEMENTS} elements, [0, {t_end:g}] s, Newton rtol {NEWTON_RTOL:g}; references "
          f"generalized-alpha h = {c['h_ref']:g}: ours estimated error {refs['ours'][1]:.1e} m, Exudyn's "
          f"{refs['exudyn'][1]:.1e} m; ours against Exudyn's reference: {agree:.2e} m", flush=True)
    configs = [("ours", m, x) for m in methods for x in c["ours"][m]]
    configs += [("exudyn", m, h) for m, hs in c["exudyn"].items() for h in hs]
    failures = []

    def run(side, method, x):
        r = run_ours(case, method, x, t_end) if side == "ours" else run_peer(case, method, x, t_end)
        if not r["ok"]:
            failures.append((side, method, x))
        return r

    runs = equal.interleaved(configs, run, repeats)

    def error(cfg, r):
        ref = refs[cfg[0]][0]
        return equal.tip_error(r, ref["t"], ref["tip"])

    rows = equal.table(runs, error, x_name="h or rtol")
    equal.summary(rows)
    equal.per_method(rows)
    peer_failed = sorted({f for f in failures if f[0] == "exudyn"})
    print(f"{case.upper()}: {sum(len(v) for k, v in runs.items() if k[0] == 'exudyn')} Exudyn runs succeeded, "
          f"{len(peer_failed)} configurations failed{': ' + str(peer_failed) if peer_failed else ''}; "
          f"ours failed: {sorted({f for f in failures if f[0] == 'ours'}) or 'none'}", flush=True)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", choices=tuple(CASES), default=list(CASES))
    ap.add_argument("--t-end-b5", type=float, default=5.0, help="B5 span (benchmark: 30 s)")
    ap.add_argument("--t-end-b6", type=float, default=0.1, help="B6 span (benchmark: 0.5 s)")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--methods", nargs="+", default=["generalized-alpha", "lobatto3", "ida"],
                    choices=["generalized-alpha", "lobatto3", "ida"])
    a = ap.parse_args(argv)
    if peer_spinup is None or not available():
        raise SystemExit("exudyn is not installed: pip install '.[benchmark]'")
    print(f"Exudyn {module_variant()} module, one thread; CPU = process time; machine possibly shared: read the "
          "ratios (ours / Exudyn, < 1: ours cheaper), not the absolute times")
    for case in a.cases:
        case_run(case, a.t_end_b5 if case == "b5" else a.t_end_b6, a.repeats, a.methods)


if __name__ == "__main__":
    main()
