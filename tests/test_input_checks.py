"""Every entry point checks what it receives (issue 14): wrong shapes, numpy scalars, the obvious forms
of `supports` and `loads`. Each case names the argument in its error instead of failing deep in numpy
or, worse, returning a wrong-sized answer."""
import warnings

import numpy as np
import pytest

from ancfdae import CircularSection, Material, PointForce, RectangularSection, pulse, solve_static
from ancfdae.models import BE2D, SQ2D, Beam


@pytest.fixture
def beam(steel, square):
    return Beam(BE2D(steel, square), 2, 2.0, supports={0: "clamp"}, loads=[PointForce((0.0, 1e3), node=-1)])


def _bad_vectors(n):
    return {"one too long": np.zeros(n + 1), "one too short": np.zeros(n - 1), "2-D": np.zeros((n, 1))}


@pytest.mark.parametrize("case", ["one too long", "one too short", "2-D"])
@pytest.mark.parametrize("arg", ["q", "v", "a"])
def test_contract_methods_name_the_wrong_argument(beam, arg, case):
    # Catches: a q one entry too long assembled silently into a wrong (n+1,) residual and (n+1)^2 K.
    n = beam.n_dof
    good = {"q": beam.initial_state()[0], "v": np.zeros(n), "a": np.zeros(n)}
    args = dict(good, **{arg: _bad_vectors(n)[case]})
    calls = [lambda: beam.residual(0.0, args["q"], args["v"], args["a"]),
             lambda: beam.jacobian(0.0, args["q"], args["v"], args["a"]),
             lambda: beam.residual_jacobian(0.0, args["q"], args["v"], args["a"])]
    if arg != "a":
        calls += [lambda: beam.energy(0.0, args["q"], args["v"]),
                  lambda: beam.external_power(0.0, args["q"], args["v"])]
    if arg == "q":
        calls += [lambda: beam.mass(args["q"]), lambda: beam.position(args["q"], 1.0)]
    for call in calls:
        with pytest.raises(ValueError, match=rf"`{arg}` must have shape \({n},\)"):
            call()


def test_residual_stages_checks_stage_arrays(beam):
    n = beam.n_dof
    Q = np.tile(beam.initial_state()[0][:, None], (1, 3))
    Z = np.zeros((n, 3))
    assert beam.residual_stages(np.zeros(3), Q, Z, Z).shape == (n, 3)
    with pytest.raises(ValueError, match="`Q` must have shape"):
        beam.residual_stages(np.zeros(3), Q[:-1], Z, Z)
    with pytest.raises(ValueError, match="`A` must have shape"):
        beam.residual_stages(np.zeros(3), Q, Z, Z[:, :2])


def test_numpy_scalars_are_numbers(steel):
    # Catches: isinstance(value, (int, float)) checks that reject np.float32(0.3), and float32 kept in
    # the section (single-precision stiffness).
    mat = Material(E=np.float64(2.07e11), nu=np.float32(0.3), rho=np.int64(7800))
    sec = RectangularSection(np.float32(0.1), np.float32(0.2), shear_factor=np.float32(0.8))
    assert type(mat.nu) is float and type(sec.h) is float and type(sec.shear_factor) is float
    assert type(CircularSection(np.float32(1e-3)).d) is float
    assert mat.nu == pytest.approx(0.3, rel=1e-7)
    force = PointForce(np.array([0.0, 1.0], dtype=np.float32), node=np.int64(-1))
    beam = Beam(BE2D(mat, sec), np.int64(2), np.float32(2.0), supports={np.int64(0): "clamp"}, loads=force)
    assert pulse(np.float32(0.5))(np.float64(0.25)) == pytest.approx(1.0)
    assert solve_static(beam, load_steps=np.int64(2)).success


def test_single_load_is_accepted(steel, square):
    P = PointForce((0.0, 1e3), node=-1)
    one = Beam(BE2D(steel, square), 2, 2.0, supports={0: "clamp"}, loads=P)
    seq = Beam(BE2D(steel, square), 2, 2.0, supports={0: "clamp"}, loads=[P])
    q = one.initial_state()[0]
    z = np.zeros_like(q)
    assert np.array_equal(one.residual(0.0, q, z, z), seq.residual(0.0, q, z, z))


@pytest.mark.parametrize("kwargs, error, match", [
    ({"supports": [0]}, TypeError, r"`supports` must be a dict \{node: kind\}"),
    ({"supports": {0: None}}, ValueError, "`supports` kind must be 'clamp', 'pin' or a tuple"),
    ({"supports": {0: 1}}, ValueError, "`supports` kind must be"),
    ({"loads": 3.0}, TypeError, "`loads` must be a load or a sequence of loads"),
    ({"loads": [3.0]}, TypeError, "`loads` entries must be"),
])
def test_supports_and_loads_say_what_they_expect(steel, square, kwargs, error, match):
    with pytest.raises(error, match=match):
        Beam(BE2D(steel, square), 2, 2.0, **kwargs)


def test_sq_element_checks_too(steel, square):
    beam = Beam(SQ2D(steel, square), 2, 2.0, supports={0: "clamp"})
    q = beam.initial_state()[0]
    with pytest.raises(ValueError, match="`q` must have shape"):
        beam.residual(0.0, np.append(q, 0.0), np.zeros(q.size), np.zeros(q.size))


def test_checks_do_not_warn(beam):
    n = beam.n_dof
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError):
            beam.jacobian(0.0, np.zeros(n + 1), np.zeros(n), np.zeros(n))
