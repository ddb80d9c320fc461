"""A beam's conservative force at several configurations, weighted, in one compiled call
(``potential_gradient_projection``, the ``"potential_projection"`` capability the energy-preserving collocation
projects its silent stages with) equals ``k`` single-configuration ``potential_gradient`` calls weighted, per
element and formulation, with the compiled projection kernels and with the NumPy reference path.

Catches: a configuration built from the wrong coefficients (a row of ``A`` or a column of ``Z`` mixed up), a
fixed coordinate not kept at its value in every configuration, a weight applied to the wrong output column or
configuration, the fixed coordinates' share scattered into a free one, gravity's share left out or not
weighted by ``sum_l B[l, s]``, and, through the integrator, the step's nodes or projection given wrongly on
the compiled path (its step must equal the stacked and the one-call-per-node steps).
"""
import numpy as np
import pytest

from ancfdae import Gravity, Material, RectangularSection, models, simulate
from ancfdae.models import Beam
from ancfdae.problem import capabilities
from support.flying_beams import b2, b3

pytest.importorskip("numba")

ELEMENTS = [("BE2D", "structural"), ("BE2D", "continuum"), ("SQ2D", "structural"), ("SQ2D", "continuum"),
            ("SQ3D", "structural"), ("SQ3D", "continuum")]


def _beam(name, formulation, kernel):
    el = getattr(models, name)(Material(2.1e11, 0.3, 7800.0), RectangularSection(0.1), formulation=formulation,
                               kernel=kernel)
    g = np.r_[0.0, -9.81, np.zeros(el.dim - 2)]
    return Beam(el, 3, 2.0, supports={0: "clamp"}, loads=[Gravity(g)])


@pytest.mark.parametrize("kernel", ["numba", "numpy"])
@pytest.mark.parametrize("name, formulation", ELEMENTS)
def test_projection_equals_the_weighted_single_calls(name, formulation, kernel):
    beam = _beam(name, formulation, kernel)
    assert "potential_projection" in capabilities(beam)
    assert bool(beam._stages._projection_call()) == (kernel == "numba")    # compiled call or NumPy reference
    beam.load_factor = 0.7
    rng = np.random.default_rng(3)
    n, k = beam.n_dof, 5
    q = beam.initial_state()[0]
    Z = np.column_stack([q, 0.03 * rng.standard_normal((n, 3))])    # a base and three directions
    A = np.vstack([1.0 + 0.1 * rng.standard_normal(k), rng.standard_normal((3, k))])   # the base scaled, too
    B = rng.standard_normal((k, 2))
    ts = np.linspace(0.0, 1.0, k)
    P = beam.potential_gradient_projection(ts, Z, A, B)
    Q = Z @ A
    G = np.column_stack([beam.potential_gradient(t, Q[:, l], False)[0] for l, t in enumerate(ts)])
    assert P.shape == (n, 2)
    # the configurations are formed in another order than NumPy's Z @ A: round-off of the largest force
    # (measured <= 6e-16 of max|G|)
    assert np.abs(P - G @ B).max() <= 1e-13 * np.abs(G).max()
    assert np.abs(G[:, 1:] - G[:, :-1]).max() > 1e-3 * np.abs(G).max()     # configurations differ: mixing shows
    assert np.abs(P[:, 0] - P[:, 1]).max() > 1e-3 * np.abs(P).max()         # outputs differ


def test_gravity_share_weighted_by_the_column_sums():
    beam = _beam("BE2D", "structural", "numba")
    q = beam.initial_state()[0]
    Z, A, B = q[:, None], np.ones((1, 3)), np.array([[1.0, 0.5], [2.0, -0.5], [0.5, 0.0]])
    beam.load_factor = 0.0
    P0 = beam.potential_gradient_projection(np.zeros(3), Z, A, B)
    beam.load_factor = 0.7
    P1 = beam.potential_gradient_projection(np.zeros(3), Z, A, B)
    expected = -0.7 * beam._load_set.gravity[:, None] * np.array([3.5, 0.0])[None, :]
    assert np.abs(beam._load_set.gravity).max() > 0.0
    assert np.allclose(P1 - P0, expected, rtol=1e-14, atol=1e-14 * np.abs(expected).max())


def test_bad_shapes_name_the_argument():
    beam = _beam("BE2D", "structural", "numba")
    n = beam.n_dof
    Z, A, B = np.zeros((n, 2)), np.zeros((2, 3)), np.zeros((3, 2))
    with pytest.raises(ValueError, match="Z"):
        beam.potential_gradient_projection(np.zeros(3), Z[:-1], A, B)
    with pytest.raises(ValueError, match="A"):
        beam.potential_gradient_projection(np.zeros(3), Z, A[:, :2], B)
    with pytest.raises(ValueError, match="B"):
        beam.potential_gradient_projection(np.zeros(3), Z, A, B[:2])
    with pytest.raises(ValueError, match="ts"):
        beam.potential_gradient_projection(np.zeros((3, 1)), Z, A, B)


_METHODS = {"potential_stages": "potential_gradient_stages", "potential_projection": "potential_gradient_projection"}


class _Without:
    """The beam without some capabilities (and their methods): the collocation takes its older paths."""

    def __init__(self, beam, drop):
        self.beam, self._hidden = beam, {_METHODS[c] for c in drop}
        self.capabilities = capabilities(beam) - set(drop)

    def __getattr__(self, name):
        if name in self._hidden:
            raise AttributeError(name)
        return getattr(self.beam, name)


@pytest.mark.parametrize("name", ["BE2D", "SQ3D"])
def test_collocation_step_equals_its_stacked_and_per_node_twins(name):
    beam = b2(name, 2) if name == "BE2D" else b3(name, 2)
    models_ = [beam, _Without(beam, ("potential_projection",)),
               _Without(beam, ("potential_projection", "potential_stages"))]
    runs = [simulate(m, (0.0, 0.2), "energy-collocation", h=2e-2) for m in models_]
    assert all(r.success for r in runs)
    # The projection's forces differ from the stacked ones at round-off (the nodes are summed in another order);
    # Newton stops at the relative tolerance 1e-8, so the accepted iterates differ at round-off carried through
    # the iterations (measured: 7.5e-14 / 4.6e-13 of max|v| for BE2D / SQ3D). A wiring error moves the step by
    # far more: the rule of k = 3 instead of 5 alone changes v by 6.7e-10 / 1.8e-7 of max|v| (measured); the
    # forces themselves are held to round-off by test_projection_equals_the_weighted_single_calls.
    for other in runs[1:]:
        assert np.abs(runs[0].q - other.q).max() <= 1e-11 * np.abs(other.q).max()
        assert np.abs(runs[0].v - other.v).max() <= 1e-11 * np.abs(other.v).max()
