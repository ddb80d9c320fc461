"""The Model contract's Jacobian of every element, block by block, against finite differences.

``dr/dq`` of a moving beam is the elastic tangent plus the q-derivative of the inertia (BE3D's rotary
inertia depends on the slopes) plus the load tangent (moments follow the slopes). Elastic terms are
orders of magnitude larger, so a check of the whole ``dr/dq`` normalised by ``max|K|`` cannot see an
inertia derivative that is 10 % wrong. Here each part is compared normalised by its *own* size:

* ``K_el``: ``dr/dq`` at ``v = a = 0`` (elastic and load tangent);
* ``K_in``: ``dr/dq(q, v, a) - dr/dq(q, 0, 0)``, against finite differences of
  ``r(q, v, a) - r(q, 0, 0)`` (the motion-dependent forces alone);
* ``D = dr/dv`` and ``M = dr/da``, each against its own finite differences.
"""
import numpy as np
import pytest

from ancfdae import PointForce, PointMoment, RectangularSection
from ancfdae.models import BE2D, BE3D, SQ2D, SQ3D, Beam, Cable3D
from support.numerics import fd_gradient, rel_err

FLAT = RectangularSection(0.1, 0.05)


def _beam(steel, cls):
    el = cls(steel, RectangularSection(0.1) if cls is Cable3D else FLAT)   # Cable3D: I2 = I3 only
    dim = el.dim
    moment = 2e3 if dim == 2 else (2e3, -1e3, 5e2)
    force = np.arange(1.0, dim + 1) * 1e3
    return Beam(el, 3, 1.0, supports={0: "clamp"},
                loads=[PointMoment(moment, s=0.7), PointForce(force, s=0.4)])


@pytest.mark.parametrize("cls", [BE2D, Cable3D, BE3D, SQ2D, SQ3D])
def test_every_jacobian_block_against_its_own_finite_differences(steel, cls):
    beam = _beam(steel, cls)
    rng = np.random.default_rng(11)
    q = beam.initial_state()[0] + 0.02 * rng.standard_normal(beam.n_dof)
    v, a = 10 * rng.standard_normal((2, beam.n_dof))
    z = np.zeros(beam.n_dof)
    J, J0 = beam.jacobian(0.0, q, v, a), beam.jacobian(0.0, q, z, z)
    K_el = J0.K.toarray()
    assert rel_err(K_el, fd_gradient(lambda x: beam.residual(0.0, x, z, z), q)) < 1e-7
    moving = lambda x: beam.residual(0.0, x, v, a) - beam.residual(0.0, x, z, z)   # noqa: E731
    K_in = J.K.toarray() - K_el
    # The elastic forces cancel in `moving` only to round-off of their size: a larger step keeps that
    # round-off (eps |f_el| / h) below the truncation error of the smooth inertia forces.
    fd_in = fd_gradient(moving, q, h=1e-4)
    if beam.mass_is_constant:
        # the motion-dependent forces are M a: no q-dependence at all
        assert np.abs(K_in).max() == 0.0 and np.abs(fd_in).max() < 1e-6 * np.abs(K_el).max()
    else:
        assert np.abs(fd_in).max() > 1e-9 * np.abs(K_el).max()           # the block is not empty...
        assert rel_err(K_in, fd_in) < 1e-6                                # ...and right on its own scale
    # r is quadratic in v and linear in a: central differences with step 1 are exact up to round-off
    fd_D = fd_gradient(lambda x: beam.residual(0.0, q, x, a), v, h=1.0)
    if beam.mass_is_constant:
        assert np.abs(J.D.toarray()).max() == 0.0 and np.abs(fd_D).max() < 1e-6 * np.abs(K_el).max()
    else:
        assert rel_err(J.D.toarray(), fd_D) < 1e-7
    assert rel_err(J.M.toarray(), fd_gradient(lambda x: beam.residual(0.0, q, v, x), a, h=1.0)) < 1e-8
