"""solve_static says what its solution is: stable or not, plausible or not; bad starts named."""
import logging

import numpy as np
import pytest
import scipy.sparse as sp

from ancfdae import PointForce, solve_static
from ancfdae import _static_checks
from ancfdae.models import BE2D, Beam

L = 2.0


def _b1(steel, square, n, support="clamp", force=None):
    """The chapter's B1 cantilever (Sect. 5.1: L = 2 m, tip force 3 E I / L^2 upwards) with another support."""
    force = (0.0, 3.0 * steel.E * square.I3 / L**2) if force is None else force
    return Beam(BE2D(steel, square), n, L, supports={0: support}, loads=[PointForce(force, node=-1)])


def test_pin_only_cantilever_reports_an_unstable_equilibrium(steel, square, caplog):
    """Catches the audit's silent answer: held by a pin only, Newton converges to the beam pointing down
    against its upward tip force (tip y = -1.999 m), an equilibrium with one negative stiffness eigenvalue."""
    beam = _b1(steel, square, 2, "pin")
    with caplog.at_level(logging.WARNING, logger="ancfdae"):
        res = solve_static(beam)
    assert res.success and beam.position(res.q, L)[1] < -1.99        # the equilibrium the audit found
    assert res.negative_eigenvalues == 1 and res.zero_eigenvalues == 0 and res.stable is False
    assert len(res.warnings) == 1 and "unstable equilibrium" in res.warnings[0]
    assert any("unstable equilibrium" in r.getMessage() for r in caplog.records)
    z = np.zeros(beam.n_dof)                                           # against the eigenvalues themselves
    K = beam.jacobian(0.0, res.q, z, z).K.toarray()
    assert np.sum(np.linalg.eigvalsh(K) < 0) == 1


def test_the_clamped_cantilever_is_stable_and_plausible(steel, square, caplog):
    """Catches a check that cries wolf on the chapter's own benchmark (no warning, no log)."""
    with caplog.at_level(logging.WARNING, logger="ancfdae"):
        res = solve_static(_b1(steel, square, 4))
    assert res.success and res.stable is True and res.negative_eigenvalues == 0 and res.warnings == []
    assert not caplog.records


@pytest.mark.parametrize("force, words", [((-1e11, 0.0), "axial strain up to +48"),
                                          ((0.0, 1e15), "axial strain up to +5.54e+05")])
def test_loads_far_beyond_the_model_are_flagged(steel, square, force, words):
    """Catches the audit's silent answers: 1e11 N of compression "converging" to a beam inverted and
    stretched to x = -98.6 m, a 1e15 N load to positions of 1e5 m."""
    beam = _b1(steel, square, 4, force=force)
    res = solve_static(beam)
    assert res.success and any(words in w for w in res.warnings), res.warnings
    assert solve_static(beam, max_strain=None).warnings == []


def test_a_folded_element_is_flagged(steel, square):
    beam = _b1(steel, square, 2)
    q = beam.initial_state()[0].copy()
    nodal = beam.nodal(q)                      # node 2's slope (x', y') reversed x3: element 1 turns back
    q_full = beam.expand(q)
    q_full[beam.element.n_node_dof * 2 + 2: beam.element.n_node_dof * 2 + 4] *= -3.0
    q = q_full[beam.free]
    assert nodal.shape[0] == 3
    assert any("element(s) [1] folded" in w for w in _static_checks.plausibility(beam, q))


@pytest.mark.parametrize("stretch, flagged", [(1.05, False), (1.09, False), (1.12, True), (0.85, True), (1.3, True)])
def test_the_strain_threshold_is_on_the_axial_strain(steel, square, stretch, flagged):
    """Catches a threshold on the wrong quantity (the stretch instead of the strain, a shifted bound): a beam
    stretched uniformly by a factor (x and x' scaled) is flagged exactly when |stretch - 1| > 0.1."""
    beam = _b1(steel, square, 2)
    full = beam.expand(beam.initial_state()[0]).reshape(beam.n_nodes, -1).copy()
    full[:, [0, 2]] *= stretch                       # BE2D node coordinates (x, y, x', y')
    q = full.reshape(-1)[beam.free]
    warnings = _static_checks.plausibility(beam, q)
    assert bool(warnings) == flagged, warnings
    if flagged:
        assert f"stretch {stretch:.4g}" in warnings[0]


@pytest.mark.parametrize("seed", range(6))
def test_inertia_counts_the_negative_eigenvalues(seed):
    """Catches a wrong count from the sparse factorisation (pivoting, 2x2 blocks): random sparse symmetric
    indefinite matrices against their eigenvalues."""
    rng = np.random.default_rng(seed)
    n = 40
    A = sp.random(n, n, density=0.1, random_state=seed) + sp.diags(rng.normal(size=n) * 3)
    A = (A + A.T).toarray()
    want = int(np.sum(np.linalg.eigvalsh(A) < 0))
    n_neg, n_zero, how = _static_checks.inertia(sp.csr_matrix(A))
    assert (n_neg, n_zero) == (want, 0), how
    assert _static_checks._dense(A) == (want, 0)


def test_inertia_of_a_saddle_point_matrix_with_zero_diagonal():
    """Catches counting the pivots of a factorisation that pivoted rows (a zero diagonal forces it; its
    diagonal of U is then not the D of L D L^T): [[0, I], [I, 0]] has n negative and n positive eigenvalues."""
    n = 10
    A = sp.bmat([[None, sp.eye(n)], [sp.eye(n), None]]).tocsr()
    assert _static_checks.inertia(A)[:2] == (n, 0)


def test_bad_starts_name_the_argument(steel, square):
    """Catches the audit's "`atol` must be a finite real number" for a NaN start, time or load."""
    beam = _b1(steel, square, 2)
    with pytest.raises(ValueError, match=r"`q0` must be finite"):
        solve_static(beam, q0=np.full(beam.n_dof, np.nan))
    with pytest.raises(ValueError, match=r"`t` must be a finite real number.*got nan"):
        solve_static(beam, t=float("nan"))
    with pytest.raises(ValueError, match=r"`t` must be a finite real number.*got '1'"):
        solve_static(beam, t="1")
    nan_load = Beam(BE2D(steel, square), 2, L, supports={0: "clamp"},
                    loads=[PointForce((0.0, 1.0), node=-1, time=lambda t: np.nan)])
    with pytest.raises(ValueError, match=r"residual at `q0` \(t = 0\) is not finite: a load"):
        solve_static(nan_load)
    with pytest.raises(ValueError, match="`check_stability` must be True or False"):
        solve_static(beam, check_stability="yes")
