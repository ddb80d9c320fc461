"""The Newmark family's extrapolating predictor on constrained models (:func:`ancfdae.integrators._alpha_index3.predictor`).

Catches: the predictor not applied (iterations as the constant start's), applied with the wrong sign or weight (more
iterations or a different solution), applied across a change of step size or after a model event (the first step
after one must start from the current state), the option accepted where it does nothing (an unconstrained model) or
a bad value accepted.
"""
import numpy as np
import pytest

from ancfdae import Material, RectangularSection, simulate
from ancfdae.integrators import GeneralizedAlpha, _alpha_index3
from ancfdae.models import BE2D, Beam
from ancfdae.studies._multibody_models import slider_crank


def _b6(predictor, t_end=0.05, h=1e-4, **kw):
    b = slider_crank("BE2D", 8)
    return simulate(b.system, (0.0, t_end), "generalized-alpha", h=h, rho_inf=0.9, newton={"tol": 1e-8},
                    predictor=predictor, t_eval=np.linspace(0.0, t_end, 11), **kw)


def test_extrapolation_saves_iterations_on_the_same_solution():
    const, auto, extra = _b6("constant"), _b6("auto"), _b6("extrapolate")
    assert const.status == auto.status == extra.status == "success"
    np.testing.assert_array_equal(auto.q, extra.q)   # "auto" is "extrapolate" on a constrained model
    # same solution to Newton's tolerance (measured 3e-10 m on B6), fewer iterations (measured 4.3 -> 3.1 a step)
    assert np.abs(auto.q - const.q).max() < 1e-8
    assert auto.stats["newton_iterations"] < 0.85 * const.stats["newton_iterations"]


def test_extrapolation_only_between_steps_of_one_size():
    """The guess is ``2 x_n - x_{n-1}`` only when the last step had the size of this one."""
    class St:
        predictor, _ah, lam = "auto", np.array([3.0]), np.array([5.0])
    st = St()
    st._last = None
    assert _alpha_index3.predictor(st, 0.1) == (st._ah, st.lam)
    st._last = (0.1, np.array([1.0]), np.array([4.0]))
    ah, lam = _alpha_index3.predictor(st, 0.1)
    assert ah[0] == 5.0 and lam[0] == 6.0
    assert _alpha_index3.predictor(st, 0.05) == (st._ah, st.lam)      # the last step shortened the grid
    st.predictor = "constant"
    assert _alpha_index3.predictor(st, 0.1) == (st._ah, st.lam)


def test_option_checked_and_refused_where_it_does_nothing():
    beam = Beam(BE2D(Material(E=2e11, nu=0.3, rho=7850.0), RectangularSection(0.01)), 2, 1.0)
    with pytest.raises(ValueError, match="predictor.*'extrapolate'.*constraints"):
        GeneralizedAlpha(beam, 1e-3, predictor="extrapolate")
    with pytest.raises(ValueError, match="predictor"):
        GeneralizedAlpha(beam, 1e-3, predictor="linear")
    assert GeneralizedAlpha(beam, 1e-3, predictor="constant").options()["predictor"] == "constant"


def test_failed_extrapolated_start_is_retried_from_the_constant_one(monkeypatch):
    """A step whose extrapolated start diverges is solved from the constant start (B5 at h = 0.05 needs it at
    9.3 s); the message of a step that fails from both names both."""
    from ancfdae.integrators import newton_stepper
    solve = newton_stepper.NewtonStepper._solve
    starts = []

    def flaky(self, residual, jacobian, x0, **kw):
        out = solve(self, residual, jacobian, x0, **kw)
        const = _alpha_index3.constant_start(self, self.h)   # self.h: the step's size to round-off
        if self._last is not None and np.abs(x0 - const).max() > 1e-12 * np.abs(const).max():
            starts.append("extrapolated")
            return type(out)(x0, False, 1, np.inf, "forced failure", out.floor)
        starts.append("constant")
        return out
    monkeypatch.setattr(newton_stepper.NewtonStepper, "_solve", flaky)
    monkeypatch.setattr("ancfdae.integrators.newmark._AlphaFamily.steps_until", None)
    res = _b6("auto", t_end=2e-3)
    assert res.status == "success", res.message
    assert starts.count("extrapolated") == 19 and starts.count("constant") == 20   # first step: constant only
