"""The energy-preserving collocation's velocity correction (``energy_correction="velocity"``, the default):
Newton stops at a tolerance and the step's known energy and linear-momentum defects are removed from ``v1``.

Beams of B3 revision 2 (``support.flying_beams``) and the spring chain of the toy models (no translations).
"""
import numpy as np
import pytest

from ancfdae import simulate
from ancfdae.integrators import EnergyCollocation, NewtonOptions
from ancfdae.integrators._energy_correction import MAX_SCALING, VelocityCorrection, energy_defect
from support.flying_beams import b3, momenta, total_energy
from support.toy_models import SpringChain


def test_correction_removes_the_given_defects_exactly():
    """Given ``v1``, ``R_0`` and ``D``: ``T(v1c) = T(v1) - D``, ``T^T M v1c = T^T M v1 - h T^T R_0``, and the
    velocity relative to the translations only scaled.

    Catches: a wrong sign of either defect, the scaling applied to the translations (momentum broken), a
    relative part that is not M-orthogonal to the translations (the energy misses by the cross term).
    """
    beam = b3("SQ3D", 2)
    M = beam.mass(None)
    T, _ = beam.symmetry_generators()
    rng = np.random.default_rng(7)
    v1, R0, h = rng.standard_normal(beam.n_dof), rng.standard_normal(beam.n_dof), 1e-2
    kin = 0.5 * v1 @ (M @ v1)
    for D in (1e-3 * kin, -2e-6 * kin):
        vc = VelocityCorrection(beam, M)(h, v1, R0, D)
        assert abs(0.5 * vc @ (M @ vc) - (kin - D)) <= 1e-14 * kin
        p, p_c = T.T @ (M @ v1), T.T @ (M @ vc)
        assert np.abs(p_c - (p - h * (T.T @ R0))).max() <= 1e-14 * np.abs(M @ v1).sum()
        w = lambda v: v - T @ np.linalg.solve(T.T @ (M @ T), T.T @ (M @ v))
        ratio = w(vc) / w(v1)
        assert np.ptp(ratio) <= 1e-12 and abs(ratio[0] - 1.0) > 1e-8
    # no translations (spring chain): the whole velocity scaled; a defect beyond MAX_SCALING is refused
    chain = SpringChain()
    Mc = chain.mass(None)
    v = rng.standard_normal(chain.n_dof)
    kc = 0.5 * v @ (Mc @ v)
    vc = VelocityCorrection(chain, Mc)(h, v, np.ones(chain.n_dof), 1e-4 * kc)
    assert abs(0.5 * vc @ (Mc @ vc) - (1 - 1e-4) * kc) <= 1e-14 * kc
    assert np.ptp(vc / v) <= 1e-14
    assert VelocityCorrection(chain, Mc)(h, v, v, 1.01 * MAX_SCALING * kc) is None


def test_compiled_correction_equals_the_numpy_reference():
    """``VelocityCorrection`` (one compiled call) against its NumPy ``reference`` to a few ulp: with translations
    (SQ3D, free), without (spring chain), a defect refused (None from both), at rest with and without a defect.

    Catches: a kernel that drifts from the reference (a sign, the momentum's translation not added to ``M v1``,
    the refusal or the at-rest branch returning something else).
    """
    rng = np.random.default_rng(11)
    h = 1e-2
    for model in (b3("SQ3D", 2), SpringChain()):
        M = model.mass(None)
        vc = VelocityCorrection(model, M)
        v1, R0 = rng.standard_normal(model.n_dof), rng.standard_normal(model.n_dof)
        kin = 0.5 * v1 @ (M @ v1)
        for D in (1e-3 * kin, -2e-6 * kin, 0.0):
            got, want = vc(h, v1, R0, D), vc.reference(h, v1, R0, D)
            assert np.abs(got - want).max() <= 1e-14 * np.abs(want).max(), D
        assert vc(h, v1, R0, 1.01 * MAX_SCALING * kin) is None and vc.reference(h, v1, R0, 1.01 * MAX_SCALING * kin) is None
    beam = b3("SQ3D", 2)
    vc, z = VelocityCorrection(beam, beam.mass(None)), np.zeros(beam.n_dof)     # at rest: nothing to scale
    assert np.array_equal(vc(h, z, z, 0.0), vc.reference(h, z, z, 0.0)) and not vc(h, z, z, 0.0).any()
    assert vc(h, z, z, 1e-9) is None and vc.reference(h, z, z, 1e-9) is None


class _Uncorrected(EnergyCollocation):
    """The velocity correction switched off: Newton's tolerance alone decides (the bug this file guards)."""

    def _bind(self):
        super()._bind()
        self._correct = lambda h, v1, R0, defect: v1


@pytest.mark.parametrize("tol", [1e-4, 1e-8])
def test_loose_newton_keeps_energy_and_momentum_exact(tol):
    """SQ3D, one element, a moment pulse then 100 free steps of 10 ms, Newton stopped at ``tol``: energy
    constant to 1e-12 and linear momentum zero to 1e-13 with the correction; without it the energy drifts
    by more than 1e-9 at tol = 1e-4 (measured 3.6e-5; with it 2.4e-14). The momentum stays exact even
    uncorrected here (measured 3.7e-16): a Newton matrix with ``K T = 0`` settles ``T^T R`` in one iteration;
    the momentum formula is held by the unit test above.

    Catches: the defect taken from a residual other than the final iterate's, ``V`` without ``h v0``, the
    correction skipped, a momentum correction with the wrong sign or step.
    """
    drift, mom = {}, {}
    for cls in (EnergyCollocation, _Uncorrected):
        beam = b3("SQ3D", 1, t_load=0.4)
        st = cls(beam, 1e-2, newton=NewtonOptions(tol=tol))
        res = simulate(beam, (0.0, 1.4), method=st)
        assert res.success, res.message
        E = total_energy(beam, list(zip(res.t, res.q, res.v)), 0.4)
        p, _ = momenta(beam, list(zip(res.t, res.q, res.v)))
        drift[cls], mom[cls] = np.ptp(E) / np.abs(E).max(), np.abs(p).max() / np.abs(beam.mass(None) @ res.v[-1]).sum()
    assert drift[EnergyCollocation] <= 1e-12 and mom[EnergyCollocation] <= 1e-13, (drift, mom)
    if tol == 1e-4:
        assert drift[_Uncorrected] >= 1e-9, (drift, mom)


def test_energy_defect_is_the_energy_identity():
    """``energy_defect`` at an arbitrary (unconverged) ``Y`` equals ``T1 - T0 + P1 - P0`` of the step built
    from it (free motion, a quartic potential: the 4-node rule is exact).

    Catches: ``V`` with the wrong Legendre weights or ``h v0`` in the wrong row, the wrong residual row order.
    """
    beam = b3("SQ3D", 1, t_load=0.4, formulation="continuum")       # the load is over at t = 1
    st = EnergyCollocation(beam, 2e-2)
    q, v = beam.initial_state()
    rng = np.random.default_rng(5)
    q, v = q + 1e-2 * rng.standard_normal(q.size), v + 0.1 * rng.standard_normal(v.size)
    st.initialize(beam, 1.0, q, v, np.zeros_like(q), 2.0)
    h = st.h
    residual, _ = st.stage_equations(1.0, h, [False])
    Y = 1e-4 * rng.standard_normal((beam.n_dof, 2))
    R = residual(Y.ravel()).reshape(-1, 2)
    co = st._co
    q1, v1 = q + h * v + Y @ co.q_end, v + Y[:, 0] / h
    E0, E1 = beam.energy(1.0, q, v).total, beam.energy(1.0 + h, q1, v1).total
    D = energy_defect(Y, R, co.X, h * v)
    assert abs((E1 - E0) - D) <= 1e-10 * abs(D) + 1e-13 * abs(E0), (E1 - E0, D)
    assert abs(D) > 1e-6 * abs(E0)


def test_bad_correction_refused_with_reason():
    from support.pendulum_toy import PointPendulum
    with pytest.raises(ValueError, match="energy_correction"):
        EnergyCollocation(b3("SQ3D", 1), 1e-2, energy_correction="scale")
    with pytest.raises(ValueError, match="energy_correction.*constraints"):
        EnergyCollocation(PointPendulum(), 1e-2, energy_correction="velocity")
    assert EnergyCollocation(PointPendulum(), 1e-2).energy_correction == "newton"
