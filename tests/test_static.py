"""Static Newton solver with load steps (chapter Sect. 5.1)."""
import warnings

import numpy as np
import pytest

from ancfdae import CircularSection, Gravity, Material, PointForce, RectangularSection, solve_static
from ancfdae._scale import force_scale
from ancfdae.models import BE2D, Beam


def test_failure_names_the_load_step(steel, square):
    F = 3 * steel.E * square.I3 / 4.0
    beam = Beam(BE2D(steel, square), 4, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, 20 * F), node=-1)])
    res = solve_static(beam, load_steps=1, max_iter=3)
    assert res.status == "failed" and not res.success
    assert "load step 1 of 1" in res.message
    # nothing unconverged is returned as the solution
    assert np.array_equal(res.q, beam.initial_state()[0])
    assert beam.load_factor == 1.0


def test_steps_record_each_converged_load(steel, square):
    F = 3 * steel.E * square.I3 / 4.0
    beam = Beam(BE2D(steel, square), 4, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, F), node=-1)])
    res = solve_static(beam, load_steps=4)
    assert [s["load_factor"] for s in res.steps] == [0.25, 0.5, 0.75, 1.0]
    assert all(s["converged"] for s in res.steps)
    assert res.iterations == sum(s["iterations"] for s in res.steps) == res.stats["newton_iterations"]
    tips = [beam.position(s["q"], 2.0)[1] for s in res.steps]
    assert np.all(np.diff(tips) > 0)


def test_fine_mesh_converges_at_roundoff_floor(steel, square):
    # Beyond ~100 elements the residual's round-off floor exceeds 1e-8 of the first residual.
    F = 3 * steel.E * square.I3 / 4.0
    beam = Beam(BE2D(steel, square), 256, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, F), node=-1)])
    res = solve_static(beam)
    assert res.success, res.message
    u = beam.position(res.q, 2.0) - [2.0, 0.0]
    assert np.linalg.norm(u - [-0.50853730436, 1.20723985455]) < 1e-9


@pytest.mark.parametrize("kwargs, match", [
    ({"load_steps": 0}, "load_steps"),
    ({"tol": 0.0}, "tol"),
    ({"max_iter": 0}, "max_iter"),
    ({"jacobian": "exact"}, "jacobian"),
    ({"q0": np.zeros(3)}, "q0"),
])
def test_bad_static_options(steel, square, kwargs, match):
    beam = Beam(BE2D(steel, square), 2, 2.0, supports={0: "clamp"})
    with pytest.raises(ValueError, match=match):
        solve_static(beam, **kwargs)


# -- tolerances that scale with the problem (issue 14) ----------------------------------------
def _tip_deflection(material, section, length, load, n_el=8):
    beam = Beam(BE2D(material, section), n_el, length, supports={0: "clamp"}, loads=load)
    res = solve_static(beam)
    assert res.success, res.message
    return beam, res


def test_micro_fibre_matches_linear_theory():
    # Catches an absolute Newton tolerance in newtons: a 1e-10 N tip load on a 1 um glass fibre gives
    # residuals below 1e-10 N, which a fixed atol declared "converged" at 0 iterations (deflection 0).
    glass, fibre = Material(E=70e9, nu=0.2, rho=2500.0), CircularSection(1e-6)
    L, P = 1e-3, 1e-10
    beam, res = _tip_deflection(glass, fibre, L, [PointForce((0.0, P), node=-1)])
    w = beam.position(res.q, L)[1]
    w_lin = P * L**3 / (3 * glass.E * fibre.I3)          # Euler-Bernoulli cantilever, tip force
    assert res.iterations >= 10                           # every load step iterated
    assert abs(w / w_lin - 1) < 1e-3                      # measured 1.2e-4: geometric nonlinearity
    # (w/L = 1 %; it falls as P^2: 1.2e-6 at P/10, 1.2e-8 at P/100)


def test_macro_beam_under_gravity_matches_linear_theory(steel):
    # A 100 m steel beam: the residual's round-off floor (eps * max|K| * max|q|, ~1e-3 N) lies far above
    # 1e-8 of a load step's first residual; the derived floor must let it converge, to the right answer.
    section = RectangularSection(1.0)
    L, g = 100.0, 9.81e-3                                 # small load: w/L = 6e-4, linear theory holds
    beam, res = _tip_deflection(steel, section, L, [Gravity((0.0, -g))])
    w = beam.position(res.q, L)[1]
    w_lin = -steel.rho * section.A * g * L**4 / (8 * steel.E * section.I3)   # uniform load q L^4 / 8EI
    # Hermite cubic elements are nodally exact for a uniform load; what is left is geometric nonlinearity.
    assert abs(w / w_lin - 1) < 1e-3


def test_force_scale_is_unit_free(steel, square):
    # The same beam in mm/N/MPa-like units scaled by 1e-6 in force gives a 1e-6 smaller scale.
    b1 = Beam(BE2D(steel, square), 2, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, 1e3), node=-1)])
    soft = Material(E=steel.E * 1e-6, nu=steel.nu, rho=steel.rho)
    b2 = Beam(BE2D(soft, square), 2, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, 1e-3), node=-1)])
    s1 = force_scale(b1, 0.0, b1.initial_state()[0])
    s2 = force_scale(b2, 0.0, b2.initial_state()[0])
    assert s2 == pytest.approx(1e-6 * s1, rel=1e-12)
    # with motion: the inertia forces count (M a), so a model at rest with large accelerations has a scale
    q, v = b1.initial_state()
    a = np.full_like(q, 1e3)
    assert force_scale(b1, 0.0, q, v, a) > s1


def test_unsupported_beam_fails_clearly_without_warning(steel, square):
    beam = Beam(BE2D(steel, square), 2, 2.0, loads=[PointForce((0.0, 1e3), node=-1)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")                    # a scipy LinAlgWarning would fail the test
        res = solve_static(beam)
    assert res.status == "failed"
    assert "singular" in res.message and "supports" in res.message


def test_static_result_speaks_the_vocabulary_of_result(steel, square):
    # Catches StaticResult drifting from Result: "converged" for "success", or stats as a record with
    # other names than Result.stats (a dataclass there, a dict here).
    from ancfdae import Result
    beam = Beam(BE2D(steel, square), 2, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, 1e3), node=-1)])
    res = solve_static(beam, load_steps=2)
    assert res.status == "success" and res.success
    Result(t=[0.0], q=res.q[None], v=0 * res.q[None], a=0 * res.q[None], status=res.status)   # a valid status
    assert {"newton_iterations", "newton_solves", "residual_evals", "jacobian_evals", "factorizations",
            "cpu_time"} <= set(res.stats)
    assert res.stats["newton_iterations"] == res.iterations > 0
