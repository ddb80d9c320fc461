"""A beam's conservative force at several configurations in one element pass (``potential_gradient_stages``,
the ``"potential_stages"`` capability that the energy-preserving collocation evaluates at its silent
stages) equals ``potential_gradient`` column by column, on the compiled (fused) and the NumPy assembly.

Catches: stacked configurations mixed (a column holding another configuration's force, a wrong offset of
the stacked gather or scatter), gravity's share left out or scaled wrongly (``load_factor``), the
capability declared where the model cannot keep it, and, through the integrator, a node of the HBVM rule
given the wrong position or weight on the stacked path (its step must equal the one-call-per-node step).
"""
import numpy as np
import pytest

from ancfdae import Gravity, Material, PointForce, RectangularSection, models, simulate
from ancfdae.models import Beam
from ancfdae.problem import capabilities
from support.flying_beams import b2, b3

pytest.importorskip("numba")

CASES = [("BE2D", "structural", "numba"), ("BE2D", "continuum", "numba"), ("SQ2D", "structural", "numba"),
         ("SQ3D", "structural", "numba"), ("SQ3D", "continuum", "numba"), ("SQ3D", "structural", "numpy")]


def _beam(name, formulation, kernel):
    el = getattr(models, name)(Material(2.1e11, 0.3, 7800.0), RectangularSection(0.1), formulation=formulation,
                               kernel=kernel)
    g = np.r_[0.0, -9.81, np.zeros(el.dim - 2)]
    return Beam(el, 3, 2.0, supports={0: "clamp"}, loads=[PointForce(np.r_[1e5, 2e5, np.zeros(el.dim - 2)], s=1.3),
                                                         Gravity(g)])


@pytest.mark.parametrize("name, formulation, kernel", CASES)
def test_stages_equal_the_per_configuration_gradient(name, formulation, kernel):
    beam = _beam(name, formulation, kernel)
    assert "potential_stages" in capabilities(beam)
    assert (beam.element.fused_kernel(beam.geom) is None) == (kernel == "numpy")
    beam.load_factor = 0.7                   # gravity's share scaled as in potential_gradient
    rng = np.random.default_rng(5)
    n = beam.n_dof
    q = beam.initial_state()[0]
    ts = np.array([0.0, 0.1, 0.25, 0.5, 0.75, 0.9])
    Q = q[:, None] + 0.02 * rng.standard_normal((n, ts.size))   # six distinct configurations
    G = beam.potential_gradient_stages(ts, Q)
    ref = np.column_stack([beam.potential_gradient(t, Q[:, i], False)[0] for i, t in enumerate(ts)])
    assert G.shape == (n, ts.size)
    assert np.array_equal(G, ref)            # the same sums in the same order: equal bits
    assert np.abs(ref[:, 1:] - ref[:, :-1]).max() > 1e-3 * np.abs(ref).max()   # columns differ: mixing shows
    # one configuration, and a different count after six (the stacked geometry is cached per count)
    assert np.array_equal(beam.potential_gradient_stages(ts[:1], Q[:, :1])[:, 0], ref[:, 0])


def test_bad_shapes_name_the_argument():
    beam = _beam("BE2D", "structural", "numba")
    Q = np.zeros((beam.n_dof, 3))
    with pytest.raises(ValueError, match="Q"):
        beam.potential_gradient_stages(np.zeros(3), Q[:-1])
    with pytest.raises(ValueError, match="ts"):
        beam.potential_gradient_stages(np.zeros((3, 1)), Q)


class _PerNode:
    """The beam without the ``"potential_projection"`` capability and, unless ``stages``, without
    ``"potential_stages"``: the collocation calls it once per node (or once per step's stacked nodes)."""

    def __init__(self, beam, stages=False):
        self.beam = beam
        self.capabilities = capabilities(beam) - {"potential_projection"} - (set() if stages else {"potential_stages"})
        self._hidden = {"potential_gradient_projection"} | (set() if stages else {"potential_gradient_stages"})

    def __getattr__(self, name):
        if name in self._hidden:
            raise AttributeError(name)
        return getattr(self.beam, name)


@pytest.mark.parametrize("name", ["BE2D", "SQ3D"])
def test_collocation_step_equals_its_per_node_twin(name):
    beam = b2(name, 2) if name == "BE2D" else b3(name, 2)
    runs = [simulate(m, (0.0, 0.2), "energy-collocation", h=2e-2)
            for m in (_PerNode(beam, stages=True), _PerNode(beam))]
    assert all(r.success for r in runs)
    scale = np.abs(runs[1].q).max()
    assert np.abs(runs[0].q - runs[1].q).max() <= 1e-13 * scale
    assert np.abs(runs[0].v - runs[1].v).max() <= 1e-13 * np.abs(runs[1].v).max()
