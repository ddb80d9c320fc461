"""B3's linearised equations along a run: the fastest frequency against the step, and the growing modes.

``python -m benchmarks.b3_linearised [--element BE3DSR] [--elements 16] [--t-end 2.0] [--h 5e-4] [--every 0.1]``
integrates B3 (revision 2, Lobatto IIIA-3, modified Newton tol 1e-8) to ``t_end`` and, at every ``every``
seconds, linearises the residual ``M(q) a + f(q, v) - f_ext(t, q, v) = 0`` about the computed state (the
acceleration from the mass solve): ``M da + D dv + K dq = 0`` with the model's exact blocks
``K = dr/dq`` (stiffness, load and ``dM/dq a`` terms), ``D = dr/dv``, ``M = dr/da``. The eigenvalues of the
first-order matrix ``[[0, I], [-M^-1 K, -M^-1 D]]`` give, per output time, the largest frequency
``omega_max = max |Im lambda|`` (times the step ``h``: the accuracy measure of a one-step method, the
Lobatto IIIA stage equations being A-stable for a linear system at any ``h``) and the largest real part
``max Re lambda`` (a frozen-coefficient growth rate, in 1/s; a conservative system at rest has none), with
the frequency of that mode, over all modes and over those above 100 rad/s (the elastic modes the step must
resolve; the rigid rotation and the lowest bending modes lie below), and the same with the moment switched off (the linearisation at ``t = 100 s``, after
the hat, about the same state: what the dead moment's load stiffness adds). Printed as a table; nothing is
asserted. At rest the system is conservative,
so ``max Re lambda`` at ``t = 0`` measures the eigen-solver's round-off.

``--from FILE`` takes the states of a stored run instead (a ``Result`` file, e.g. a case of
``ancfdae study flying3d --out DIR``: ``DIR/cases/*.nc``; ``--element``/``--elements`` must name its beam), at
the stored output times nearest to ``--times`` (comma-separated, s).

The matrix is dense (``2 n_dof`` squared): meant for the B3 meshes up to 32 elements.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.linalg as sla
import scipy.sparse.linalg as spla

from ancfdae import Result
from ancfdae.studies._flying import b3_beam, simulate_case


def linearised_spectrum(beam, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Eigenvalues of the first-order linearisation of ``beam`` about ``(t, q, v)``."""
    a = spla.spsolve(beam.mass(q).tocsc(), -beam.residual(t, q, v, np.zeros_like(q)))
    J = beam.jacobian(t, q, v, a)
    M = J.M.toarray()
    n = M.shape[0]
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -np.linalg.solve(M, J.K.toarray())
    A[n:, n:] = -np.linalg.solve(M, J.D.toarray())
    return sla.eigvals(A)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--element", default="BE3DSR")
    p.add_argument("--elements", type=int, default=16)
    p.add_argument("--t-end", type=float, default=2.0)
    p.add_argument("--h", type=float, default=5e-4)
    p.add_argument("--every", type=float, default=0.1)
    p.add_argument("--from", dest="source", default=None)
    p.add_argument("--times", default="0,0.5,1,1.5,1.8,1.9,2.0")
    a = p.parse_args()
    beam = b3_beam(a.element, a.elements)
    c0 = time.process_time()
    if a.source:
        res = Result.load(a.source)
        if res.q.shape[1] != beam.n_dof:
            raise SystemExit(f"--from: the stored run has {res.q.shape[1]} coordinates, B3 {a.element} with "
                             f"{a.elements} elements {beam.n_dof}.")
        rows = sorted({int(np.argmin(np.abs(res.t - float(x)))) for x in a.times.split(",")})
        print(f"B3 {a.element} {a.elements} el, states of the stored run (status {res.status}, to "
              f"{res.t[-1]:.3f} s), {beam.n_dof} dof")
    else:
        res = simulate_case(beam, a.t_end, h=a.h, dt_out=a.every)["result"]
        rows = range(res.t.size)
        print(f"B3 {a.element} {a.elements} el, Lobatto IIIA-3 h = {a.h:g} to {a.t_end:g} s: status {res.status}, "
              f"{res.t[-1]:.3f} s reached, {time.process_time() - c0:.0f} s CPU, {beam.n_dof} dof")
    log = res.monitors["energy"]
    print("   t (s) | balance (J) | omega_max (rad/s) | omega_max h(=1e-3) | max Re lambda (1/s) at |Im| (rad/s): "
          "all modes, modes above 100 rad/s; without the moment: all, above 100 rad/s")
    for i in rows:
        t = res.t[i]
        st = {k: np.asarray(x)[i] for k, x in res.model_state.items()}
        model = beam.bind(st) if st else beam
        lam = linearised_spectrum(model, float(t), res.q[i], res.v[i])
        free = linearised_spectrum(model, 100.0, res.q[i], res.v[i])
        w_max = float(np.max(np.abs(lam.imag)))
        print(f"  {t:6.2f} | {log['balance'][i]: .2e} | {w_max:7.1f} | {w_max * 1e-3:.3f} | "
              + " | ".join(_fastest_growth(x, w) for x in (lam, free) for w in (0.0, 100.0)), flush=True)


def _fastest_growth(lam: np.ndarray, above: float) -> str:
    """``max Re`` among the eigenvalues with ``|Im| > above`` and that mode's ``|Im|``."""
    sel = lam[np.abs(lam.imag) > above] if above > 0 else lam
    if sel.size == 0:
        return "-"
    k = int(np.argmax(sel.real))
    return f"{sel.real[k]: .3e} at {abs(sel.imag[k]):6.1f}"


if __name__ == "__main__":
    main()
