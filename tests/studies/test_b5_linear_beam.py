"""B5: the conventional linear beam diverges at the benchmark's spin where the ANCF beam stays bounded."""
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("ancfdae.joints")

from ancfdae import simulate  # noqa: E402
from ancfdae.studies._linear_beam import _matrices, first_bending_frequency, linear_spinup  # noqa: E402
from ancfdae.studies._multibody_models import SPINUP, spinup  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data" / "exudyn_b5_reference.npz"


def test_linear_model_has_the_clamped_beam_frequency_and_follows_ancf_at_slow_spin():
    # Catches: a wrong Hermite stiffness or mass (the frequency), a wrong sign or arm of the hub's inertia
    # load theta_tt x (the early deflection, where both models must agree: the spin is still slow).
    K, M, _ = _matrices(8, SPINUP["EI"], SPINUP["rhoA"], SPINUP["L"])
    w1 = np.sqrt(np.linalg.eigvals(np.linalg.solve(M, K)).real.min())
    assert w1 == pytest.approx(first_bending_frequency(), rel=1e-5)        # 3.7977 rad/s
    ref = np.load(DATA)
    t = np.array([0.0, 1.0, 2.5])
    w = linear_spinup(t)
    for ti, wi in zip(t[1:], w[1:]):
        k = int(np.argmin(np.abs(ref["t"] - ti)))
        assert wi == pytest.approx(ref["b5-4/deflection"][k], rel=1e-3)    # measured 2e-6 and 7e-4


def test_ancf_beam_stays_bounded_where_the_linear_beam_diverges():
    # Catches: a beam without geometric stiffening (its deflection would grow as the linear model's once the
    # hub rate passes the first bending frequency, at 12 s) or a linear reference that cannot fail.
    t = np.linspace(0.0, 20.0, 41)
    b = spinup("BE2D", 8)
    res = simulate(b.system, (0.0, 20.0), "generalized-alpha", h=0.05, t_eval=t)
    assert res.success, res.message
    ancf = b.outputs["tip_deflection"](res.t, res.q, res.v, res.lam)
    lin = linear_spinup(t)
    assert np.abs(ancf).max() < 0.45                                        # measured 0.397 m at 7.5 s
    assert np.abs(ancf[t >= 15.0]).max() < 0.05
    assert np.abs(lin[t >= 15.0]).min() > 50.0                             # measured 69 m at 15 s, 3.7e4 at 20 s
    assert abs(lin[-1]) > 1e3 * np.abs(ancf).max()
