"""Static Newton solver with load steps (chapter Sect. 5.1)."""
import numpy as np
import pytest

from ancfdae import PointForce, solve_static
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
    assert res.iterations == sum(s["iterations"] for s in res.steps) == res.stats.iterations
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
