"""Lobatto IIIA-3 on constrained models (GGL stabilised index 2, ``lobatto_constrained``)."""
import numpy as np
import pytest

from ancfdae.integrators import Lobatto3, NewtonOptions
from ancfdae.integrators.lobatto_constrained import GGLStages
from support.numerics import fd_gradient
from support.toy_constrained import (WithoutVelocityJacobian, consistent_start, double_pendulum, hanging_link, hub,
                                     kkt, reference, step_to)

T = 0.25
STEPS = (20, 40, 80)


def run(model, h, t_end=T, newton=None, lam0=True):
    """Step a Lobatto3 to ``t_end``; returns the stepper and the largest |g| and |G v + g_t| after a step."""
    st = Lobatto3(model, h, newton=newton)
    q0, v0, a0, l0 = consistent_start(model)
    st.initialize(model, 0.0, q0, v0, a0, t_end, lam0=l0 if lam0 else None)
    g, gv = step_to(st, model, t_end)
    return st, g, gv


def slope(hs, errs):
    return float(np.polyfit(np.log(hs), np.log(errs), 1)[0])


@pytest.fixture(scope="module", params=["link", "hub"])
def convergence(request):
    """Errors at T of q, v, the step's lam and lam recomputed from (q, v), against DOP853 on the
    index-1 ODE, for h = T/20, T/40, T/80; and the drift of both constraint levels."""
    model = {"link": hanging_link, "hub": hub}[request.param]()
    qr, vr, lr = reference(model, np.array([0.0, T]), rtol=1e-12)
    errs, drift = [], []
    for N in STEPS:
        st, g, gv = run(model, T / N)
        lc = kkt(model, st.t, st.q, st.v)[1]
        errs.append([np.abs(x - r[-1]).max() for x, r in ((st.q, qr), (st.v, vr), (st.lam, lr), (lc, lr))])
        drift.append((g, gv))
    return request.param, np.array(errs), np.array(drift)


def test_order_four_in_q_v_and_recomputed_multipliers(convergence):
    """q, v and lam_c order 4 (measured slopes 4.11 / 4.08 / 3.61 on the distance link, 3.98 / 3.99 / 3.96 on
    the hub). Catches an index-3 formulation (order 2 in q and v on the quadratic distance constraint), a
    missing velocity constraint or a wrong g_t (the hub's rows depend on time)."""
    name, errs, _ = convergence
    hs = T / np.array(STEPS)
    assert slope(hs, errs[:, 0]) > 3.8
    assert slope(hs, errs[:, 1]) > 3.5
    assert slope(hs, errs[:, 3]) > 3.3
    assert errs[-1, 0] < 1e-8


def test_step_multipliers_converge(convergence):
    """The step's own lam (stage value at t_{n+1}) converges: measured slope 2.61 on the hub (lam_c: 3.96);
    4.26 on the distance link at these steps (2.3 in the finer, longer runs of the prototype)."""
    name, errs, _ = convergence
    assert errs[-1, 2] < 0.05 * errs[0, 2]


def test_constraints_held_at_every_step(convergence):
    """g and G v + g_t stay at the Newton tolerance, without growing with the number of steps (measured
    max |g| <= 2.3e-13, |G v + g_t| <= 1.3e-10). Catches an index-3 step (velocity drift) and a position
    constraint imposed only at the end."""
    _, _, drift = convergence
    assert drift[:, 0].max() < 1e-11
    assert drift[:, 1].max() < 1e-8


def _stage_system(model, seed=0):
    """A GGL stage system at a perturbed state, with its unknowns perturbed (U = 0: see the test)."""
    st = Lobatto3(model, 0.02, newton=NewtonOptions(jacobian="full"))
    q0, v0, a0, l0 = consistent_start(model)
    rng = np.random.default_rng(seed)
    st.initialize(model, 0.3, q0 + 0.02 * rng.standard_normal(q0.size), rng.standard_normal(q0.size), a0,
                  1.0, lam0=l0)
    sysm = GGLStages(st)
    x = sysm.guess(st.h)
    x[:-sysm.m * sysm.ns] += 0.1 * rng.standard_normal(x.size - sysm.m * sysm.ns)
    return st, sysm, x


@pytest.mark.parametrize("name", ["link", "hub", "link-fallback"])
def test_newton_matrix_against_finite_differences(name):
    """The reduced factorisation solves the stage system's exact Newton matrix: J_fd @ solve(r) = r.

    At U = 0 the only left-out term, h H(h U) in the kinematic rows, vanishes, so every block must be
    exact: a missing H(lam) or Z(v), a missing G_t (hub), a wrong sign or scaling, or a wrong elimination
    of the kinematic rows fails. "link-fallback": the model without ``constraint_velocity_jacobian``
    (Z(v) from products of H(e_i)).
    """
    model = {"link": hanging_link, "hub": hub, "link-fallback": lambda: WithoutVelocityJacobian(hanging_link())}[name]()
    st, s, x = _stage_system(model)
    t, h = st.t, st.h
    J = fd_gradient(lambda y: s.residual(y, t, h), x, h=1e-6)
    lu = s.blocks(x, t, h, range(s.ns))[0].factorize()
    mine = np.linalg.inv(np.array([lu.solve(e) for e in np.eye(x.size)]).T)
    n, m, ns = s.n, s.m, s.ns
    cut = np.cumsum([0, n * ns, n * ns, m * ns, m * ns])
    for r0, r1 in zip(cut[:-1], cut[1:]):          # rows: kinematic, dynamic, g, G v + g_t
        for c0, c1 in zip(cut[:-1], cut[1:]):      # unknowns: K, A, Lam, U
            ref = J[r0:r1, c0:c1]
            assert np.abs(mine[r0:r1, c0:c1] - ref).max() <= 1e-6 * max(np.abs(J[r0:r1]).max(), 1e-12), \
                (r0, c0)


def test_linear_constraints_and_no_multiplier_start():
    """Double pendulum (linear g): order 4 in q between h = T/40 and T/80 as well; and a stepper given no
    lam0 computes (a0, lam0) itself by the KKT system: the same run to round-off."""
    model = double_pendulum()
    a, _, _ = run(model, T / 40, t_end=0.1)
    b, _, _ = run(model, T / 40, t_end=0.1, lam0=False)
    assert np.abs(a.q - b.q).max() < 1e-12 and np.abs(a.lam - b.lam).max() < 1e-9


def test_through_the_driver():
    """``Integrator.run`` on a constrained model: the run succeeds and holds g = 0 at the outputs."""
    model = hanging_link()
    res = Lobatto3(model, 0.01).run((0.0, 0.2), t_eval=np.linspace(0.0, 0.2, 5))
    assert res.success
    for t, q in zip(res.t, res.q):
        assert np.abs(model.constraints(t, q)).max() < 1e-12


def test_constrained_lobatto_refuses_the_extrapolating_predictor():
    # Catches: predictor="extrapolate" accepted and silently ignored on a constrained model (the GGL stage
    # system has only the constant guess).
    with pytest.raises(ValueError, match="`predictor`"):
        Lobatto3(hanging_link(), 0.01, predictor="extrapolate")


def test_modified_newton_step_falls_back_to_full_newton():
    # Catches: the modified-Newton policy failing a step that full Newton solves (B5 spin-up, BE2D 8 elements,
    # h = 0.1: modified Newton stopped at t = 7.4 s, full Newton at 9.4 s; with the fallback 9.4 s).
    from ancfdae import simulate
    from ancfdae.studies._multibody_models import spinup
    res = simulate(spinup("BE2D", 8).system, (0.0, 8.5), "lobatto3", h=0.1, t_eval=[0.0, 8.5])
    assert res.success, res.message


def test_round_off_floor_covers_the_scaled_position_rows():
    # Catches: a Newton floor from the elastic stiffness alone. The position rows (m_s / h^2) g stall at their
    # own round-off, which outgrows the elastic forces' at small steps: B7 (Cable3D 4 el, E = 5e7) at
    # h = 3.125e-4 stalled at 5.7e-10 N (floor 2.5e-10 N) and failed its first step "diverging".
    from ancfdae import simulate
    from ancfdae.studies._multibody_models import spatial_pendulum
    h = 3.125e-4
    res = simulate(spatial_pendulum("Cable3D", 4, E=5e7).system, (0.0, 4 * h), "lobatto3", h=h)
    assert res.success, res.message
