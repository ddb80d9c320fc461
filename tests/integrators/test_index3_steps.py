"""The Newmark family's compiled index-3 steps of a System (one compiled beam and rigid bodies, the driver's
``steps_until`` between output times: :mod:`ancfdae.integrators._index3_steps`) reach the Python path's states,
multipliers and failures with the same counters.

Catches: a step's work counted twice, not at all or counted when the step is handed back to Python (the counters
must match); a decision of the solver skipped or taken differently (a refresh, the stagnation test: the counters
differ); the predictor, the scaled multipliers, the algorithmic acceleration or the KKT matrix with a wrong
coefficient (states or counters differ); the drives' time functions, the rigid bodies' timed forces and moments
or the beam's dead loads at the wrong times or dropped (the loaded system below: states differ); the rigid
bodies' gravity dropped; a failure inside the steps losing the outputs before it, its time or its reason; the
drive's weight table differing from the time functions it tabulates, or a bad drive no longer named; the output
times a compiled call records across (``steps_sampling``) at other times, states or multipliers than the driver's
own samples, or a call that no longer runs across output times.
"""
import numpy as np
import pytest

from ancfdae import Gravity, Material, PointForce, PointMoment, RectangularSection, RigidBody, System, simulate
from ancfdae.integrators import _index3_steps, newmark
from ancfdae.joints import Prescribed, Spherical
from ancfdae.models import BE2D, Beam
from ancfdae.studies._multibody_models import slider_crank, spinup

pytest.importorskip("numba")

COUNTS = ("steps", "newton_iterations", "newton_solves", "residual_evals", "jacobian_evals", "factorizations",
          "retries", "failed_solves")


def _both(system, monkeypatch, t_end, method="generalized-alpha", **kw):
    """(compiled run, Python step-by-step run, the steps each compiled call accepted itself)."""
    taken = []
    run = _index3_steps.Index3Steps.run

    def spy(self, *a):
        out = run(self, *a)
        taken.append(out[1])
        return out
    monkeypatch.setattr(_index3_steps.Index3Steps, "run", spy)
    fast = simulate(system, (0.0, t_end), method, **kw)
    monkeypatch.setattr(newmark._AlphaFamily, "steps_until", None)   # the driver's step-by-step loop
    slow = simulate(system, (0.0, t_end), method, **kw)
    monkeypatch.undo()
    return fast, slow, taken


#: largest difference from the Python path relative to the largest value: the dense LU rounds differently from
#: LAPACK's banded one, so modified Newton's iterates differ at round-off and the converged steps within
#: Newton's tolerance; the index-3 step divides ``q``'s share by ``beta h^2`` for ``a`` and ``lam``
#: (measured on these runs: q 6e-14, v 2e-11, a 1e-6, lam 3e-9 relative, tol 1e-8)
RTOL = {"q": 1e-11, "v": 1e-8, "a": 1e-5, "lam": 1e-6}


#: the extrapolating predictor's first iteration often lands on the residual's round-off floor (B5: 1.1e-6 to
#: 1.25e-6 N against a floor of 1.19e-6 N), where the two paths' round-off decides a second iteration: counters
#: within this share (a step counted twice or the predictor missing in one path: 10-30 %)
COUNTS_RTOL = 0.01
#: and the states where such a decision differs: B5 (1.5 s, h = 5e-3) q 1.5e-12, v 1.5e-8, a 3e-6, lam 4.6e-8
RTOL_FLOOR = {"q": 1e-10, "v": 1e-7, "a": 1e-4, "lam": 1e-6}


def _same(fast, slow, exact=True):
    for key in COUNTS:
        if exact or key in ("steps", "retries", "failed_solves"):
            assert fast.stats[key] == slow.stats[key], key
        else:
            assert abs(fast.stats[key] - slow.stats[key]) <= COUNTS_RTOL * slow.stats[key], key
    np.testing.assert_array_equal(fast.t, slow.t)
    rtol = RTOL if exact else RTOL_FLOOR
    for name in ("q", "v", "a", "lam"):
        f, s = getattr(fast, name), getattr(slow, name)
        assert f.shape == s.shape
        assert np.abs(f - s).max() <= rtol[name] * np.abs(s).max(), name


@pytest.mark.parametrize("predictor", ["constant", "auto"])
@pytest.mark.parametrize("case, t_end, h, dt", [("b6", 0.03, 1e-4, 1e-3), ("b5", 1.5, 5e-3, 0.02)])
def test_benchmarks_match_the_python_path(case, t_end, h, dt, predictor, monkeypatch):
    b = slider_crank("BE2D", 8) if case == "b6" else spinup("BE2D", 8, w_s=4.0)
    t_eval = np.linspace(0.0, t_end, int(round(t_end / dt)) + 1)
    fast, slow, taken = _both(b.system, monkeypatch, t_end, h=h, rho_inf=0.9, t_eval=t_eval, newton={"tol": 1e-8},
                              predictor=predictor)
    assert fast.status == slow.status == "success"
    _same(fast, slow, exact=predictor == "constant")
    # every step but the last of each compiled call was taken in it, and the calls ran across output times (their
    # samples recorded inside: same times, states and multipliers as the driver's)
    assert sum(taken) == fast.stats["steps"] - len(taken)
    assert len(taken) < (t_eval.size - 1) / 10


def _loaded(dead=True, force=lambda t: np.cos(20 * t), angle=lambda t: (np.array([2 * t * t]), np.array([4 * t]),
                                                                         np.array([4.0]))):
    """A beam pinned to the ground whose tip holds a rigid body with gravity, a timed force and a timed moment;
    the beam carries gravity and (``dead``) a timed dead load; its root angle is driven by ``angle``."""
    el = BE2D(Material(2.0e9, 0.3, 1200.0), RectangularSection(0.02))
    loads = [Gravity((0.0, -9.81))] + ([PointForce((0.0, 3.0), node=4, time=lambda t: np.sin(30 * t))] if dead else [])
    beam = Beam(el, 6, 0.6, loads=loads)
    body = RigidBody(0.3, 2e-4, [0.6, 0.0], com=[0.05, 0.0], loads=[
        Gravity((0.0, -9.81)), PointForce((2.0, -1.0), node=0, time=force),
        PointMoment(0.4, node=0, time=lambda t: 1.0 + t)])
    drive = Prescribed((beam, 0), position=lambda t: (np.zeros(2), np.zeros(2), np.zeros(2)),
                       angle=angle)
    return System([beam, body], [drive, Spherical((beam, -1), (body, (0.0, 0.0)))])



@pytest.mark.parametrize("case, t_end, h", [("b6", 0.01025, 1e-4), ("b5", 0.5, 5e-3)])
def test_output_at_every_step_runs_across_the_steps(case, t_end, h, monkeypatch):
    """No ``t_eval``: output at every step, from compiled calls that run across the steps (the defect: the driver
    stepping in Python whenever it records every step, 0.8 ms a step on B6 instead of ~40 us); the times are the
    step grid (B6: the last step shortened to end at ``t_end``) and the samples those of the Python path."""
    b = slider_crank("BE2D", 8) if case == "b6" else spinup("BE2D", 8, w_s=4.0)
    fast, slow, taken = _both(b.system, monkeypatch, t_end, h=h, rho_inf=0.9, newton={"tol": 1e-8})
    assert fast.status == slow.status == "success"
    _same(fast, slow, exact=False)
    steps = fast.stats["steps"]
    assert fast.t.size == steps + 1 and fast.t[-1] == t_end
    np.testing.assert_allclose(np.diff(fast.t[:-1]), h, rtol=1e-9)
    assert sum(taken) == steps - len(taken) and len(taken) < steps / 10

@pytest.mark.parametrize("dead, method, opts", [(True, "generalized-alpha", {"rho_inf": 0.8}),
                                                (False, "generalized-alpha", {"rho_inf": 0.8}),
                                                (True, "hht", {"alpha": 0.1}), (True, "newmark", {"beta": 0.3025, "gamma": 0.6})])
def test_loaded_system_matches_the_python_path(dead, method, opts, monkeypatch):
    # t_end off the output grid and off the step grid: a shortened last step (a new matrix in the compiled call)
    t_eval = [0.0, 0.01, 0.0155, 0.03, 0.0405]
    fast, slow, taken = _both(_loaded(dead), monkeypatch, 0.0405, method, h=5e-4, t_eval=t_eval,
                              newton={"tol": 1e-10, "contraction": 0.2}, **opts)
    assert fast.status == slow.status == "success"
    _same(fast, slow)
    assert sum(taken) > fast.stats["steps"] // 2
    assert fast.t.tolist() == t_eval


@pytest.mark.filterwarnings("ignore:invalid value encountered:RuntimeWarning")   # the planted infinite load
@pytest.mark.parametrize("where", ["force", "drive"])
def test_failure_inside_the_steps_is_python_s(where, monkeypatch):
    # a load that becomes infinite (Newton's first residual is not finite) or a drive that returns NaN (its
    # checked call raises) after 0.0123 s: the compiled steps stop before that step, Python's fails as alone
    system = _loaded(force=lambda t: np.inf if t > 0.0123 else 1.0) if where == "force" else _loaded(
        angle=lambda t: tuple(np.array([x]) for x in (np.nan if t > 0.0123 else t * t, 2 * t, 2.0)))
    fast, slow, taken = _both(system, monkeypatch, 0.03, h=5e-4, rho_inf=0.8, t_eval=np.linspace(0.0, 0.03, 7),
                              newton={"tol": 1e-10})
    assert fast.status == slow.status == "failed"
    assert fast.message == slow.message and ("not finite" if where == "force" else "finite arrays") in fast.message
    assert fast.t_fail == slow.t_fail == pytest.approx(0.012)
    assert sum(taken) > 10
    _same(fast, slow)


def test_weight_table_is_the_time_functions():
    b = spinup("BE2D", 4, w_s=4.0)
    rows = b.system.compiled_rows
    times = np.array([0.0, 0.3, 7.5, 14.9, 15.0, 22.0])
    table = rows.weight_table(times)
    expect = np.array([rows.weights(t)[0] for t in times])
    np.testing.assert_allclose(table, expect, rtol=0, atol=1e-15)
    assert np.ptp(table[:, 1:], axis=0).max() > 0.5   # the drive's terms do vary over these times


def test_bad_drive_named_from_the_table():
    beam = Beam(BE2D(Material(2.0e9, 0.3, 1200.0), RectangularSection(0.02)), 2, 0.5)
    bad = Prescribed((beam, 0), angle=lambda t: (np.array([np.nan if t > 0.1 else 0.0]), np.zeros(1), np.zeros(1)))
    rows = System([beam], [bad]).compiled_rows
    with pytest.raises(ValueError, match=r"`angle`\(t\) must return three finite arrays.*t = 0.2"):
        rows.weight_table(np.array([0.0, 0.2]))


def test_constrained_runs_take_the_index3_threshold():
    # catches: the index-3 refresh threshold not applied on a System, applied to a beam alone, or over the user's
    from ancfdae.integrators._newton_records import CONTRACTION
    from ancfdae.integrators.newmark import INDEX3_CONTRACTION
    b = slider_crank("BE2D", 4)
    run = lambda model, **nw: simulate(model, (0.0, 1e-3), "generalized-alpha", h=1e-4, newton=nw).options["newton"]
    assert run(b.system)["contraction"] == INDEX3_CONTRACTION != CONTRACTION
    assert run(b.system, contraction=0.2)["contraction"] == 0.2
    beam = Beam(BE2D(Material(2.0e9, 0.3, 1200.0), RectangularSection(0.02)), 2, 0.5)
    assert run(beam)["contraction"] == CONTRACTION
