"""The energy-preserving collocation HBVM(k, 2) (``"energy-collocation"``): order 4 and exact energy.

Beams of B2/B3 revision 2 (``support.flying_beams``, as for the energy-momentum tests), the spring chain of the
toy models (the constant-mass order problem of the energy-momentum tests).
"""
import numpy as np
import pytest
import scipy.sparse as sp

from ancfdae import ConstraintMonitor, simulate
from ancfdae.constrained import consistent_state
from ancfdae.integrators import EnergyCollocation
from ancfdae.integrators._hbvm_constrained import constrained_hbvm_equations
from ancfdae.integrators._hbvm_coefficients import hbvm_coefficients, legendre01
from ancfdae.integrators.energy_collocation import _SplitMatrix
from ancfdae.integrators._linsolve import factorize
from ancfdae.integrators._hbvm_numba import kinetic_work, stage_residual
from ancfdae.monitors import EnergyMonitor
from ancfdae.problem import JacobianBlocks
from support.flying_beams import CASES, b2, b3, momenta, total_energy
from support.numerics import fd_gradient, rel_err
from support.pendulum_toy import PointPendulum
from support.toy_models import SpringChain


def run(model, h, t_end, monitor=None, **options):
    res = simulate(model, (0.0, t_end), "energy-collocation", h=h, monitors=[monitor] if monitor else (), **options)
    assert res.success, res.message
    return res


def test_coefficients():
    """Catches: a wrong X (closed form of Brugnano et al.), projection, predictor or midpoint row."""
    for k in (2, 3, 4, 6):
        co = hbvm_coefficients(k, 2)
        xi = 1.0 / (2.0 * np.sqrt(3.0))
        assert np.abs(co.X - [[0.5, -xi], [xi, 0.0]]).max() <= 1e-15
        assert np.abs(co.C.sum(axis=2) - co.X @ co.X).max() <= 1e-14       # frozen K -> X^2
        assert np.abs(co.b @ co.c ** (2 * k - 1) - 1.0 / (2 * k)).max() <= 1e-14   # Gauss: degree 2k - 1
    co = hbvm_coefficients(4, 2)
    # a linear acceleration a(c) = 1 + 2 c (units of h^2): its Legendre coefficients and the end/mid positions
    Y = np.array([[2.0, 2.0 / (2 * np.sqrt(3.0))]])          # P_0 coefficient 2, P_1 coefficient 1/sqrt(3)
    pos = lambda c: c ** 2 / 2 + c ** 3 / 3                   # int_0^c int_0^x (1 + 2 y) dy dx
    assert (Y @ co.q_end)[0] == pytest.approx(pos(1.0), abs=1e-15)
    assert (Y @ co.mid)[0] == pytest.approx(pos(0.5), abs=1e-15)
    # continued over the next step: a(1 + c) = 3 + 2 c
    assert np.abs(Y @ co.predictor.T - [[4.0, 2.0 / (2 * np.sqrt(3.0))]]).max() <= 1e-14
    assert legendre01(1)(1.0) == pytest.approx(np.sqrt(3.0))
    with pytest.raises(ValueError, match="`k`"):
        hbvm_coefficients(1, 2)


def _stepper(model, h=2e-2, **kw):
    st = EnergyCollocation(model, h, **kw)
    q, v = model.initial_state()
    rng = np.random.default_rng(3)
    q = q + 1e-2 * rng.standard_normal(q.size)
    v = v + 0.1 * rng.standard_normal(v.size)
    st.initialize(model, 0.2, q, v, np.zeros_like(q), 1.0)
    return st, rng


@pytest.mark.parametrize("name, kw", [("BE2D", {}), ("SQ3D", {"formulation": "continuum"})])
def test_exact_jacobian_matches_finite_differences(name, kw):
    """Block by block against central differences of the stage residual (loads on at t = 0.2 s).

    Catches: a wrong weight C[i, m, l], a stiffness taken at the wrong node, a missing M / h^2.
    """
    model = b2(name, 1, **kw) if name.endswith("2D") else b3(name, 1, **kw)
    st, rng = _stepper(model)
    residual, jacobian = st.stage_equations(st.t, st.h, [False])
    x = 1e-3 * rng.standard_normal(2 * model.n_dof)
    J = jacobian(x)[0].toarray()
    eps = 1e-6
    Jfd = np.column_stack([(residual(x + eps * e) - residual(x - eps * e)) / (2 * eps) for e in np.eye(x.size)])
    n = model.n_dof
    for i in range(2):
        for m in range(2):
            blk, ref = J[i::2, m::2], Jfd[i::2, m::2]
            assert np.abs(blk - ref).max() <= 1e-6 * np.abs(Jfd).max(), (i, m)
    assert J.shape == (2 * n, 2 * n)


def test_split_matrix_is_the_exact_jacobian_with_one_stiffness():
    """With the same stiffness at every node the eigen-split solve equals the exact Jacobian's.

    Catches: the h^2 scaling of the unknowns, X transposed, damping left in the split matrix.
    """
    model = b3("SQ3D", 1, formulation="continuum")
    st, rng = _stepper(model, h=3e-2)
    q = st.q
    z = np.zeros_like(q)
    blk = model.jacobian(0.3, q, z, z)
    K = blk.K
    one = JacobianBlocks(K, sp.csr_matrix((np.zeros_like(K.data), K.indices, K.indptr), shape=K.shape), blk.M, True)
    r = rng.standard_normal(2 * model.n_dof)
    zero = one.D
    exact = factorize(st._assemble([K] * st.silent_stages, [zero, zero], st.h)).solve(r)
    split = factorize(_SplitMatrix(one, st.h, hbvm_coefficients(st.silent_stages, 2).X)).solve(r)
    assert np.abs(split - exact).max() <= 1e-10 * np.abs(exact).max()


def test_potential_defect_is_the_energy_balance():
    """``energy_defect="potential"``: ``D = T(v1) + P(q1) - T(v0) - P(q0) - W`` with ``W`` the loads' work by their
    2-point rule at ``sigma``, ``sigma'`` (NumPy, from the model's energy and loads), to 1e-12 of the terms, with the
    loads re-evaluated and with those cached by the residual at ``x``; the compiled ``kinetic_work`` against its
    NumPy expression on a non-symmetric CSR.

    Catches: ``W`` without ``h v0`` in ``sigma'`` or by another rule, loads cached from another iterate, ``P(q0)``
    kept from another state, ``T`` of the wrong velocity, the CSR loop over columns.
    """
    rng = np.random.default_rng(5)
    n = 9
    M = sp.random(n, n, density=0.4, random_state=4, format="csr") + sp.identity(n, format="csr")
    v0, v1 = rng.standard_normal(n), rng.standard_normal(n)
    Y, F, WdT, b, h = (rng.standard_normal((n, 2)), rng.standard_normal((n, 2)), rng.standard_normal((2, 2)),
                       rng.random(2), 1e-2)
    dT, W = kinetic_work(M.data, M.indptr, M.indices, v0, v1, F, Y, WdT, b, h)
    assert dT == pytest.approx(0.5 * (v1 @ (M @ v1) - v0 @ (M @ v0)), rel=1e-13)
    assert W == pytest.approx(float(np.sum(F * (h * v0[:, None] + Y @ WdT), axis=0) @ b), rel=1e-13)
    st, rng = _stepper(b2("BE2D", 2, T=0.5))     # B2's dead force and moment, on at t = 0.2
    assert st.energy_defect == "potential"
    h, x = st.h, 1e-3 * rng.standard_normal(2 * st.n_dof)
    Y, ld = x.reshape(-1, 2), st._loads
    q1, v1 = st.q + h * st.v + Y @ st._co.q_end, st.v + Y[:, 0] / h
    ts, Q = st._nodes(st.t, h, Y, ld)
    Vd = st.v[:, None] + (Y @ ld.Wd.T) / h
    W = h * sum(ld.b[j] * st.model.nonconservative_force(ts[j], Q[:, j], False)[0] @ Vd[:, j] for j in range(2))
    E0, E1 = st.model.energy(st.t, st.q, st.v), st.model.energy(st.t + h, q1, v1)
    ref, scale = (E1.total - E0.total) - W, abs(E0.kinetic) + abs(E0.strain) + abs(E0.potential) + abs(W)
    assert abs(W) > 1e-6 * scale                # the loads work: a W left out misses by far
    assert st._defect(st.t, h, x, None, q1, v1) == pytest.approx(ref, abs=1e-12 * scale)
    residual, _ = st.stage_equations(st.t, st.h, [True])
    residual(x)                                  # caches the loads at x's nodes
    assert st._last_loads[0] is x
    assert st._defect(st.t, h, x, None, q1, v1) == pytest.approx(ref, abs=1e-12 * scale)


def test_compiled_stage_residual_equals_the_numpy_expression():
    """``stage_residual`` against ``ih2 M Y + G BP^T - F BL^T`` (a non-symmetric CSR, random blocks), and the
    stepper's residual against ``M Y / h^2 + _forces`` on a loaded B2 beam: equal to 1e-14 of the terms.

    Catches: the CSR loop over columns instead of rows (the matrix is not symmetric), projection rows
    swapped, the loads' sign, the mass term without ``1/h^2``. A wrong ``BP`` shared by both paths passes
    here and fails the order and energy tests.
    """
    rng = np.random.default_rng(11)
    n, k = 9, 5
    M = sp.random(n, n, density=0.4, random_state=3, format="csr") + sp.identity(n, format="csr")
    Y, G, F = rng.standard_normal((n, 2)), rng.standard_normal((n, k)), rng.standard_normal((n, 2))
    BPT, BlT, ih2 = rng.standard_normal((k, 2)), rng.standard_normal((2, 2)), 1e4
    R = np.empty((n, 2))
    stage_residual(Y, G, BPT, F, BlT, M.data, M.indptr, M.indices, ih2, R)
    ref = ih2 * (M @ Y) + G @ BPT - F @ BlT
    scale = ih2 * (abs(M) @ abs(Y)) + abs(G) @ abs(BPT) + abs(F) @ abs(BlT)
    assert np.abs(R - ref).max() <= 1e-14 * scale.max()
    st, rng = _stepper(b2("BE2D", 2, T=0.5))
    residual, _ = st.stage_equations(st.t, st.h, [True])
    Y = 1e-4 * rng.standard_normal((st.n_dof, 2))
    ref = (st._M @ Y) / st.h ** 2 + st._forces(st.t, st.h, Y)
    assert np.abs(residual(Y.ravel()) - ref.ravel()).max() <= 1e-14 * np.abs(ref).max()


def _differences(runs):
    """max|x_h - x_{h/2}| of successive runs: ~ C h^p for a method of order p."""
    return [np.abs(a - b).max() for a, b in zip(runs[:-1], runs[1:])]


def test_observed_order_four_spring_chain():
    """Spring chain with gravity and a pulse force (the energy-momentum order problem): q and v ~ h^4.

    Catches: an order-2 projection (wrong Legendre weights, forces at the wrong nodes, v1 off the polynomial).
    """
    model = SpringChain(force=(3.0, -2.0), T=0.5)
    hs = [1 / 20, 1 / 40, 1 / 80, 1 / 160]
    res = [run(model, h, 1.0) for h in hs]
    for x in ("q", "v"):
        d = _differences([getattr(r, x)[-1] for r in res])
        slope = np.polyfit(np.log(hs[:-1]), np.log(d), 1)[0]
        assert abs(slope - 4.0) < 0.2, (x, slope, d)


def test_observed_order_four_b2():
    """B2 with 4 BE2D elements (pulse force and moment on) over [0, 0.2] s: q and v ~ h^4."""
    model = b2("BE2D", 4)
    hs = [1e-2, 5e-3, 2.5e-3, 1.25e-3]
    res = [run(model, h, 0.2, t_eval=[0.2]) for h in hs]
    for x in ("q", "v"):
        d = _differences([getattr(r, x)[-1] for r in res])
        slope = np.polyfit(np.log(hs[:-1]), np.log(d), 1)[0]
        assert abs(slope - 4.0) < 0.2, (x, slope, d)


FREE_STEPS = 100


@pytest.mark.parametrize("name, n, kw", [(c[0], 1, c[2]) for c in CASES], ids=lambda c: str(c))
def test_free_motion_energy_constant_every_element(name, n, kw):
    """Every constant-mass element and formulation, one element: a short load, then FREE_STEPS steps of
    10 ms; energy constant to 1e-12 relative at every step (the 10^4-step runs: ``python -m
    benchmarks.energy_collocation long``).

    Catches: too few silent stages for a formulation ('auto'), a Newton stop above round-off, a
    non-polynomial potential left to the rule's defect (SQ3D structural, k = 4, these 100 steps: 1.8e-11 with the
    rule's, 2.8e-15 with the potential's).
    """
    t_load = 0.3 if name.endswith("2D") else 0.4
    beam = b2(name, n, T=t_load, **kw) if name.endswith("2D") else b3(name, n, t_load=t_load, **kw)
    res = run(beam, 1e-2, t_load + FREE_STEPS * 1e-2)
    E = total_energy(beam, list(zip(res.t, res.q, res.v)), t_load)
    assert E.size >= FREE_STEPS
    assert np.ptp(E) <= 1e-12 * np.abs(E).max(), np.ptp(E) / np.abs(E).max()
    polynomial = name.startswith("SQ") and "continuum" in kw.get("formulation", "")
    assert res.options["silent_stages"] == 4
    assert res.options["energy_defect"] == ("rule" if polynomial else "potential")


ROUNDOFF_STEPS = 300


@pytest.mark.parametrize("name, kw, bound, correction", [
    ("SQ2D", {}, 1e-13, "auto"), ("SQ3D", {}, 1e-13, "auto"), ("SQ3D", {"formulation": "continuum"}, 2e-14, "auto"),
    ("SQ3D", {}, 1e-13, "newton")], ids=str)
def test_energy_at_round_off_over_hundreds_of_steps(name, kw, bound, correction):
    """The three cases whose 10^4-step energy missed 1e-12 with Newton stopped at its residual's round-off
    floor: one element, ROUNDOFF_STEPS free steps of 10 ms; the default (Newton to 1e-8 and the velocity
    correction) and Newton on to the energy's round-off (``"newton"``). Measured with ``"newton"``: SQ2D
    1.2e-14, SQ3D 3.3e-14, SQ3D continuum 4.5e-15 relative; the residual test alone 1.9e-13, 1.9e-13,
    5.5e-14 (exceeding ``bound``).

    Catches: Newton's energy test dropped or too loose (the defect left biased along the step piles up),
    a wrong energy defect (``sum V . R`` with the wrong ``V``: the test would accept the floor's steps), a
    velocity correction that leaves a bias.
    """
    t_load = 0.3 if name.endswith("2D") else 0.4
    beam = b2(name, 1, T=t_load, **kw) if name.endswith("2D") else b3(name, 1, t_load=t_load, **kw)
    res = run(beam, 1e-2, t_load + ROUNDOFF_STEPS * 1e-2, energy_correction=correction)
    E = total_energy(beam, list(zip(res.t, res.q, res.v)), t_load)
    assert np.ptp(E) <= bound * np.abs(E).max(), np.ptp(E) / np.abs(E).max()


def test_too_few_silent_stages_lose_the_energy():
    """SQ3D continuum (quartic P) with k = 3 < 4 nodes: the rule's defect no longer is the energy's (the
    docstring's rule), and the potential's own defect (``"auto"`` at k = 3) keeps it exact again.

    Catches: a test above that would pass whatever k (a model or load that does not excite the nonlinearity);
    an ``"auto"`` defect that trusts a rule too short for the declared degree.
    """
    drift, chosen = {}, {}
    for k, defect in ((3, "rule"), (4, "auto"), (3, "auto")):
        beam = b3("SQ3D", 1, t_load=0.4, formulation="continuum")
        res = run(beam, 2e-2, 1.2, silent_stages=k, energy_defect=defect)
        E = total_energy(beam, list(zip(res.t, res.q, res.v)), 0.4)
        drift[k, defect], chosen[k, defect] = np.ptp(E) / np.abs(E).max(), res.options["energy_defect"]
    assert drift[4, "auto"] <= 1e-12 and drift[3, "rule"] >= 1e3 * drift[4, "auto"], drift
    assert drift[3, "auto"] <= 1e-12, drift
    assert chosen == {(3, "rule"): "rule", (4, "auto"): "rule", (3, "auto"): "potential"}, chosen


def test_energy_balance_with_loads_and_linear_momentum():
    """Under loads T + U + V - W_ext (W_ext by the step's k-node rule, its Quadrature) is constant; under a
    pure moment the linear momentum stays zero.

    Catches: a quadrature that is not the scheme's (nodes, velocities sigma', weights), loads evaluated off
    the nodes, internal forces with a resultant.
    """
    beam = b2("SQ2D", 2, T=0.5)
    res = run(beam, 5e-3, 0.5, monitor=EnergyMonitor())
    log = res.monitors["energy"]
    assert np.abs(log["work"]).max() > 1e-4
    assert np.abs(log["drift"]).max() <= 1e-12 * log["scale"], log["relative_drift"]
    beam = b3("SQ3D", 1, t_load=0.5)
    res = run(beam, 1e-2, 1.0)
    p, _ = momenta(beam, list(zip(res.t, res.q, res.v)))
    scale = np.abs(beam.mass(None) @ res.v[-1]).sum()
    assert np.abs(p).max() <= 1e-13 * scale, np.abs(p).max() / scale


def test_bad_input_refused_with_reason():
    beam = b2("BE2D", 1)
    with pytest.raises(ValueError, match="constant mass matrix"):
        EnergyCollocation(b3("BE3D", 1), 1e-2)
    for bad in (1, 2.5, "six", True):
        with pytest.raises(ValueError, match="silent_stages"):
            EnergyCollocation(beam, 1e-2, silent_stages=bad)
    with pytest.raises(ValueError, match="iteration_matrix"):
        EnergyCollocation(beam, 1e-2, iteration_matrix="lu")
    with pytest.raises(ValueError, match="energy_defect"):
        EnergyCollocation(beam, 1e-2, energy_defect="exact")
    with pytest.raises(ValueError, match="energy_defect.*velocity correction only"):
        EnergyCollocation(beam, 1e-2, energy_correction="newton", energy_defect="potential")
    with pytest.raises(ValueError, match="h"):
        EnergyCollocation(beam, 0.0)
    res = simulate(SpringChain(damping=0.5), (0.0, 1.0), "energy-collocation", h=1e-2)
    assert not res.success and "velocity-dependent" in res.message


# -- constrained models (quadratic rows: the point-mass pendulum of the constrained tests) -------------
def _started_constrained(model, h):
    q0, v0 = model.initial_state()
    cs = consistent_state(model, 0.0, q0, v0 + np.array([0.0, 0.3, 0.0, -0.2]))
    st = EnergyCollocation(model, h)
    st.initialize(model, 0.0, cs.q, cs.v, cs.a, 1.0, lam0=cs.lam)
    for _ in range(3):                     # off the initial state: a general step
        st.accept(st.step())
    return st


def test_constrained_newton_matrix_is_the_derivative_of_the_step_residual():
    """Block by block against central differences, scleronomic pendulum (catches a wrong multiplier
    weight P_j(c_l), a dropped constraint Hessian, a wrong d(G v)/dq, a scale between rows and unknowns)."""
    model = PointPendulum()
    st = _started_constrained(model, 0.02)
    residual, jacobian, x0 = constrained_hbvm_equations(st, st.t, 0.02)
    x = x0 + 1e-3 * np.random.default_rng(0).standard_normal(x0.size) * np.abs(x0).max()
    J = jacobian(x)[0].toarray()
    Jfd = fd_gradient(residual, x, h=1e-7)
    n2 = 2 * model.n_dof
    for rows, cols in ((slice(0, n2), slice(0, n2)), (slice(0, n2), slice(n2, None)), (slice(n2, None), slice(0, n2))):
        assert rel_err(J[rows, cols], Jfd[rows, cols]) < 1e-6
    assert np.abs(J[n2:, n2:]).max() == 0.0


def test_constrained_energy_and_constraints_exact_and_order_four_in_q():
    """Quadratic constraints: energy (its balance) to 1e-13, g(q) to 1e-14 at every step; q of order 4
    (v is of order 2 with quadratic rows, whose velocity constraint the scheme does not impose).

    Catches: a multiplier constant over the step (the joint then works), g imposed at the wrong time."""
    model = PointPendulum()
    hs, q_end = [0.02, 0.01, 0.005], []
    for h in hs:
        res = simulate(model, (0.0, 1.0), "energy-collocation", h=h, monitors=[EnergyMonitor(), ConstraintMonitor()])
        assert res.success, res.message
        assert res.monitors["energy"]["relative_drift"] < 1e-13
        assert res.monitors["constraints"]["max_position"] < 1e-14
        q_end.append(res.q[-1])
    d = _differences(q_end)
    assert abs(np.log(d[0] / d[1]) / np.log(2.0) - 4.0) < 0.3, d


def test_constraints_above_quadratic_refused():
    class Cubic(PointPendulum):
        constraint_degree = 3
    with pytest.raises(ValueError, match="constraint_degree"):
        EnergyCollocation(Cubic(), 1e-2)
