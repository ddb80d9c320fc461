"""The driver checks what a user's stepper and callbacks return: a bad answer is a failed run, never a success
or a raw exception that loses the run; Ctrl-C keeps the part computed."""
import numpy as np
import pytest

from ancfdae import EnergyMonitor, Probe, simulate
from ancfdae.integrators import Integrator, RunInterrupted, StepOutcome
from support.toy_models import SpringChain


class Faulty(Integrator):
    """A variable-step user stepper (explicit Euler, h = 0.01) that turns faulty from its 4th step on."""

    name, fixed_step = "faulty", False
    fault = None

    def step(self):
        h = 0.01
        q, v, a = self.q + h * self.v, self.v + h * self.a, self.a.copy()
        t = self.t + h
        if self.n_steps >= 3:
            if self.fault == "nan":
                q = q.copy()
                q[1] = np.nan
            elif self.fault == "short":
                q = q[:-1]
            elif self.fault == "past_end":
                t = self.t_bound + 0.5
            elif self.fault == "none":
                return None
            elif self.fault == "back":
                t = self.t - h
            elif self.fault == "grow":
                q, v = self.q * 1e80, self.v * 1e80
        return StepOutcome(ok=True, t=min(t, self.t_bound) if self.fault != "past_end" else t, q=q, v=v, a=a)


def _run(fault, **kw):
    model = SpringChain(2)
    stepper = Faulty(model)
    stepper.fault = fault
    return simulate(model, (0.0, 0.1), stepper, **kw)


@pytest.mark.parametrize("fault, words", [
    ("nan", "returned a non-finite q at t = 0.04"),
    ("short", "returned q of shape (3,) at t = 0.04, expected (4,)"),
    ("past_end", "stepped past the end of the run: t = 0.6 > tf = 0.1"),
    ("none", "returned NoneType (None) from step(), expected a StepOutcome"),
    ("back", "made no progress"),
])
def test_a_bad_step_outcome_is_a_failed_run_naming_the_stepper(fault, words):
    """Catches the audit's NaN with ok=True reported as success, output after the end of the run, a raw
    numpy error for a short state and "'NoneType' object has no attribute 'ok'"."""
    res = _run(fault)
    assert res.status == "failed" and words in res.message, res.message
    assert "Faulty ('faulty')" in res.message or fault == "back"
    assert res.t.size == 4 and res.t[-1] == pytest.approx(0.03) and res.t_fail == pytest.approx(0.03)
    assert np.all(np.isfinite(res.q)) and res.q.shape == (4, 4)


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
def test_an_overflowing_run_reports_a_blow_up_with_a_meaningful_relative_drift():
    """Catches relative_drift = 0.0 with blow_up = True (an infinite scale dividing a finite drift)."""
    res = _run("grow", monitors=[EnergyMonitor()])
    log = res.monitors["energy"]
    assert log["blow_up"] is True and not np.all(np.isfinite(log["total"]))
    assert log["relative_drift"] == np.inf and np.isfinite(log["scale"]) and log["scale"] > 0


def test_a_finite_run_keeps_its_relative_drift():
    res = _run(None, monitors=[EnergyMonitor()])
    log = res.monitors["energy"]
    assert res.success and 0 < log["relative_drift"] < np.inf
    assert log["relative_drift"] == pytest.approx(np.max(np.abs(log["drift"])) / log["scale"], rel=1e-15)


def test_truthy_hook_answers_stop_and_hooks_cannot_change_the_state():
    """Catches the driver testing ``is True`` (numpy.bool_(True) ignored) and a hook editing q in place."""
    res = _run(None, hooks=[lambda t, q, v, a: np.bool_(t > 0.045)])
    assert res.success and "stopped by a hook at t = 0.05" in res.message and res.t[-1] == pytest.approx(0.05)

    def editor(t, q, v, a):
        q[0] = 1e9
    res = _run(None, hooks=[editor])
    assert res.status == "failed" and "read-only" in res.message and np.all(np.abs(res.q) < 10)

    def ambiguous(t, q, v, a):
        return q
    res = _run(None, hooks=[ambiguous])
    assert res.status == "failed" and "hook 'ambiguous' returned" in res.message and res.t.size == 2


def test_a_probe_changing_shape_fails_the_run_and_keeps_it():
    """Catches the audit's raw numpy error out of simulate (a ragged log) that lost the run."""
    probe = Probe("tip", lambda t, q, v, a: q[:2] if t < 0.035 else q[:3])
    res = _run(None, monitors=[probe])
    assert res.status == "failed" and "Probe 'tip'" in res.message and "shape (3,)" in res.message
    assert res.t.size == 4 and res.monitors["tip"]["value"].shape == (4, 2)


def test_ctrl_c_ends_the_run_with_the_part_computed_on_the_exception():
    """Catches a KeyboardInterrupt that returns nothing of the run (or is swallowed)."""
    def ctrl_c(t, q, v, a):
        if t > 0.055:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt) as info:
        _run(None, hooks=[ctrl_c])
    assert isinstance(info.value, RunInterrupted)
    res = info.value.result
    assert res.status == "failed" and "interrupted" in res.message and res.t.size == 7
    assert res.t_fail == pytest.approx(0.06)
