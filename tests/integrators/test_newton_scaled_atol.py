"""The time integrators' Newton tolerance follows the problem's force scale (issue 14)."""
import numpy as np
import pytest
import scipy.sparse as sp

from ancfdae import CircularSection, Material, PointForce, simulate, solve_static
from ancfdae.integrators import NewtonOptions
from ancfdae.integrators._newton import NewtonSolver
from ancfdae.models import BE2D, Beam

E, RHO = 70e9, 2500.0


def _fibre_run(scale, newton=None):
    """A glass micro-fibre cantilever (d 1 um, L 1 mm, tip force 1e-10 N) lengths x ``scale``, forces x
    ``scale**2`` (the same dimensionless problem); lobatto3, h = period/100, to 0.4 first periods.
    Returns the tip deflection over L and the number of Newton iterations."""
    d, L, P = 1e-6 * scale, 1e-3 * scale, 1e-10 * scale**2
    mat, sec = Material(E=E, nu=0.2, rho=RHO), CircularSection(d)
    beam = Beam(BE2D(mat, sec), 4, L, supports={0: "clamp"}, loads=[PointForce((0.0, P), node=-1)])
    omega = 1.8751**2 * np.sqrt(E * sec.I3 / (RHO * sec.A * L**4))   # first bending mode
    T = 2 * np.pi / omega
    kw = {} if newton is None else {"newton": newton}
    res = simulate(beam, (0.0, 0.4 * T), "lobatto3", h=T / 100, t_eval=[0.0, 0.4 * T], **kw)
    assert res.success, res.message
    return beam.position(res.q[-1], L)[1] / L, res.stats["newton_iterations"]


@pytest.fixture(scope="module")
def micro():
    return {"default": _fibre_run(1.0), "zero": _fibre_run(1.0, NewtonOptions(residual_atol=0.0)),
            "fixed": _fibre_run(1.0, NewtonOptions(residual_atol=1e-10))}


def test_micro_fibre_default_tolerance_scales(micro):
    # Catches a fixed absolute tolerance in newtons: 1e-10 N is the whole tip load of the fibre, so the
    # old default stopped early (measured 196 instead of 300 iterations, 1.2e-4 away from atol=0).
    w, it = micro["default"]
    w0, it0 = micro["zero"]
    assert abs(w / w0 - 1) < 1e-6                 # measured: identical to atol=0
    assert it >= 0.9 * it0
    wf, _ = micro["fixed"]
    assert abs(wf / w0 - 1) > 1e-5                 # the fixed 1e-10 N is visibly wrong (this is why)


def test_same_run_scaled_by_1e6_gives_same_dimensionless_result(micro):
    # Catches a tolerance in absolute units anywhere in the dynamic Newton (atol or floor): the run
    # scaled by 1e6 in length (1e12 in force) must give the same w/L. Measured 6e-7 apart; the floors
    # kmax * max(1, max|q|) pair the stiffness of position coordinates with unit slopes, so they are
    # not exactly scale-free.
    w, _ = micro["default"]
    w_big, _ = _fibre_run(1e6)
    assert abs(w_big / w - 1) < 2e-6


def test_residual_atol_is_a_per_solve_argument():
    # Catches the per-solve tolerance being ignored, the options' value not being the default, or None
    # reaching the comparison (the solver keeps no tolerance of its own).
    def f(x):
        return x - 1.0 + 1e-7

    def jac(x):
        return sp.eye(1, format="csr")

    s = NewtonSolver(NewtonOptions(residual_atol=1e-6))
    assert s.solve(f, jac, np.array([1.0])).iterations == 0                       # the options' 1e-6
    assert s.solve(f, jac, np.array([1.0]), residual_atol=1e-8).iterations == 1   # the argument wins
    assert NewtonSolver().solve(f, jac, np.array([1.0])).iterations == 1          # None: 0
    with pytest.raises(ValueError, match="residual_atol"):
        NewtonOptions(residual_atol=-1.0)


def test_the_old_atol_keyword_names_its_new_name():
    # Catches a rename that leaves users with Python's bare "unexpected keyword argument".
    beam = Beam(BE2D(Material(E=E, nu=0.2, rho=RHO), CircularSection(1e-3)), 2, 1.0, supports={0: "clamp"},
                loads=[PointForce((0.0, 1e-3), node=-1)])
    with pytest.raises(TypeError, match="`atol` was renamed `residual_atol`.*IDA"):
        NewtonOptions(atol=1e-6)
    with pytest.raises(TypeError, match="residual_atol"):
        simulate(beam, (0.0, 0.1), "lobatto3", h=0.01, newton={"atol": 0.0})
    with pytest.raises(TypeError, match="residual_atol"):
        solve_static(beam, atol=1e-6)
