"""Cost of a constrained step against the unconstrained one: the same pin by elimination and by a joint.

``python -m benchmarks.constrained_cost [--elements 8 16] [--repeats 3]`` runs the flexible BE2D
pendulum (1 m, pinned at node 0, gravity, released horizontally) twice per method, interleaved in
this process:

* ``eliminated``: the pin by elimination (``supports={0: "pin"}``): an unconstrained Model;
* ``joint``: the free beam with the pin as two linear constraint rows ``r(node 0) = 0`` (the
  ``"constraints"`` capability, through the small wrapper below): Lobatto IIIA-3 on the GGL stage
  system, IDA on the GGL form ``[q, v, lam, mu]``.

It prints the median CPU time per step of each, their ratio, Newton iterations (Lobatto) or steps
(IDA), the largest tip difference between the two runs (the same motion to the methods' tolerance)
and max |g| of the joint run.
"""
from __future__ import annotations

import argparse
import time

import numpy as np
import scipy.sparse as sp

from ancfdae import Gravity, Material, RectangularSection
from ancfdae.integrators import IDA, Lobatto3
from ancfdae.integrators.driver import consistent_acceleration
from ancfdae.models import BE2D, Beam


def beam(n_el, supports):
    mat, sec = Material(E=2.1e10, nu=0.3, rho=4000.0), RectangularSection(0.05)
    return Beam(BE2D(mat, sec), n_el, 1.0, supports=supports, loads=[Gravity((0.0, -9.81))])


class PinJoint:
    """A free beam with node 0's position held at the origin by two constraint rows (a benchmark stand-in
    for a joint to the ground)."""

    mass_is_constant = True
    capabilities = frozenset({"constraints", "residual_stages"})
    n_constraints = 2

    def __init__(self, free_beam):
        self.beam = free_beam
        self.n_dof = free_beam.n_dof
        self._G = sp.csr_matrix((np.ones(2), ([0, 1], [0, 1])), shape=(2, self.n_dof))
        self._zero_h = sp.csr_matrix((self.n_dof, self.n_dof))

    def __getattr__(self, name):
        return getattr(self.beam, name)

    def constraints(self, t, q):
        return q[:2].copy()

    def constraint_jacobian(self, t, q):
        return self._G

    def constraint_force_jacobian(self, t, q, lam):
        return self._zero_h

    def constraint_rates(self, t, q, v):
        return np.zeros(2), np.zeros(2)

    def constraint_velocity_jacobian(self, t, q, v):
        return sp.csr_matrix((2, self.n_dof))


def _run(stepper, model, T, free):
    """Steps to T; returns CPU seconds per step, stats, the tip trajectory at the steps, max|g|."""
    q0, v0 = model.initial_state()
    a0 = consistent_acceleration(model, 0.0, q0, v0)[0]   # the joint's steppers solve the KKT system instead
    cpu = time.process_time()
    stepper.initialize(model, 0.0, q0, v0, a0, T)
    tips, g = [], 0.0
    while stepper.t < T - 1e-12:
        out = stepper.step()
        if not out.ok:
            raise RuntimeError(out.message)
        stepper.accept(out)
        tips.append((stepper.t, stepper.q[-4:-2].copy()))
        if free:
            g = max(g, float(np.abs(stepper.q[:2]).max()))
    cpu = time.process_time() - cpu
    return cpu / stepper.n_steps, stepper.stats, tips, g


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--elements", type=int, nargs="+", default=[8, 16])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--T", type=float, default=0.2)
    ap.add_argument("--h", type=float, default=1e-3)
    ap.add_argument("--rtol", type=float, default=1e-6)
    a = ap.parse_args(argv)
    print(f"BE2D pendulum, T = {a.T} s; lobatto3 h = {a.h}, ida rtol = {a.rtol}; medians of {a.repeats} "
          "interleaved runs (process CPU)")
    print(f"{'method':9s} {'n_el':>4s} {'elim us/step':>13s} {'joint us/step':>14s} {'ratio':>6s} "
          f"{'it or steps (elim/joint)':>25s} {'max tip diff':>12s} {'max|g|':>8s}")
    for n_el in a.elements:
        elim, joint = beam(n_el, {0: "pin"}), PinJoint(beam(n_el, None))
        for name, make in (("lobatto3", lambda m: Lobatto3(m, a.h)), ("ida", lambda m: IDA(m, rtol=a.rtol))):
            te, tj = [], []
            for _ in range(a.repeats):
                ce, se, tips_e, _ = _run(make(elim), elim, a.T, False)
                cj, sj, tips_j, g = _run(make(joint), joint, a.T, True)
                te.append(ce)
                tj.append(cj)
            key = "newton_iterations" if name == "lobatto3" else "steps"
            work = f"{se[key]}/{sj[key]}"
            if name == "lobatto3":
                diff = max(float(np.abs(x[1] - y[1]).max()) for x, y in zip(tips_e, tips_j))
            else:   # different step sequences: compare at the end
                diff = float(np.abs(tips_e[-1][1] - tips_j[-1][1]).max())
            me, mj = float(np.median(te)), float(np.median(tj))
            print(f"{name:9s} {n_el:4d} {1e6 * me:13.1f} {1e6 * mj:14.1f} {mj / me:6.2f} {work:>25s} "
                  f"{diff:12.2e} {g:8.1e}")


if __name__ == "__main__":
    main()
