"""Lobatto IIIA-3 (GGL) and IDA (GGL) on Systems of beams: the issue's runs for these two methods."""
import numpy as np
import pytest

from ancfdae import ConstraintMonitor, Gravity, Material, RectangularSection, System, simulate
from ancfdae.joints import Rigid, Spherical
from ancfdae.models import BE2D, Beam

MAT = Material(E=1e9, nu=0.3, rho=1000.0)
SEC = RectangularSection(0.02)
G2 = Gravity((0.0, -9.81))


@pytest.mark.parametrize("method, options, tol", [("lobatto3", dict(h=2e-3), 1e-10), ("ida", dict(rtol=1e-8), 1e-5)])
def test_clamp_by_elimination_and_by_rigid_joint(method, options, tol):
    """A BE2D cantilever under gravity clamped by elimination and free with a Rigid joint to the ground: the
    same free coordinates (Lobatto: for linear constraints the GGL stages reduce to the eliminated ones,
    mu = 0 -- measured difference 1.1e-13 of the motion; IDA at rtol 1e-8: 1.1e-6). Catches multipliers entering
    with a wrong sign or scale and a joint that fixes more or less than the clamp."""
    elim = Beam(BE2D(MAT, SEC), 2, 1.0, supports={0: "clamp"}, loads=[G2])
    free = Beam(BE2D(MAT, SEC), 2, 1.0, loads=[G2])
    joined = System([free], [Rigid("ground", (free, 0))])
    ra = simulate(elim, (0.0, 0.04), method=method, t_eval=[0.02, 0.04], **options)
    rb = simulate(joined, (0.0, 0.04), method=method, t_eval=[0.02, 0.04], **options)
    assert ra.success and rb.success
    scale = np.abs(ra.q[-1] - elim.initial_state()[0]).max()
    assert scale > 1e-4
    assert np.abs(rb.q[:, elim.free] - ra.q).max() < tol * scale
    assert abs(rb.lam[-1][1]) > 0.1          # the clamp's vertical reaction


@pytest.mark.parametrize("method, options, T", [("lobatto3", dict(h=5e-3), 0.2), ("ida", dict(rtol=1e-6), 0.01)])
def test_planar_double_pendulum(method, options, T):
    """Two 4-element BE2D beams pinned to the ground and to each other, released horizontally: the run
    succeeds, Lobatto keeps g and G v + g_t at round-off (measured 1.1e-16 / 4.4e-16), IDA below its
    position tolerance (the multipliers are out of its error and Newton tests; measured 3.5e-6 over 0.5 s
    against atol_q = 2e-6: 'about atol_q'). Spans shortened for the suite (IDA resolves the axial
    vibrations: 37,000 steps for 0.5 s at rtol 1e-6)."""
    b1 = Beam(BE2D(MAT, SEC), 4, 1.0, loads=[G2])
    b2 = Beam(BE2D(MAT, SEC), 4, 1.0, start=(1.0, 0.0), loads=[G2])
    s = System([b1, b2], [Spherical("ground", (b1, 0)), Spherical((b1, -1), (b2, 0))])
    res = simulate(s, (0.0, T), method=method, monitors=[ConstraintMonitor()], t_eval=np.linspace(0.0, T, 4),
                   **options)
    assert res.success, res.message
    cons = res.monitors["constraints"]
    if method == "lobatto3":
        assert cons["max_position"] < 1e-12 and cons["max_velocity"] < 1e-10
        assert res.q[-1][-3] < -0.15                     # the tip fell (y of the last node)
    else:
        assert cons["max_position"] < 1e-5
