"""Energy-momentum with a configuration-dependent mass (BE3D, BE3DSR): the mass forms, the exact Jacobian of
the kinetic part, energy kept to round-off between director updates, the update jumps as the only change."""
import numpy as np
import pytest

from ancfdae import EnergyMonitor, simulate
from ancfdae.integrators._kinetic_gradient import KineticPart
from ancfdae.studies._flying import b3_beam
from ancfdae.studies.flying3d import UpdateAudit
from support.numerics import fd_gradient, rel_err


def _random(beam, seed=3):
    rng = np.random.default_rng(seed)
    q = beam.initial_state()[0] + 0.05 * rng.standard_normal(beam.n_dof)
    return q, rng.standard_normal(beam.n_dof), rng.standard_normal(beam.n_dof)


@pytest.mark.parametrize("element", ["BE3D", "BE3DSR"])
def test_mass_forms_against_finite_differences(element):
    """Catches: a mass action or bilinear form whose derivatives are not those of M(q)."""
    beam = b3_beam(element, 2)
    beam.element.kernel = "numpy"
    q, u, w = _random(beam)
    Mu, X = beam.mass_action(q, u)
    assert rel_err(Mu, beam.mass(q) @ u) < 1e-13
    assert rel_err(X.toarray(), fd_gradient(lambda x: beam.mass_action(x, u, False)[0], q)) < 1e-7
    B, g, H = beam.mass_bilinear(q, u, w)
    assert B == pytest.approx(0.5 * u @ (beam.mass(q) @ w), rel=1e-13)
    assert rel_err(g, fd_gradient(lambda x: beam.mass_bilinear(x, u, w, 0)[0], q)) < 1e-7
    assert rel_err(H.toarray(), fd_gradient(lambda x: beam.mass_bilinear(x, u, w, 1)[1], q)) < 1e-7


def test_kinetic_part_jacobian_is_exact():
    """Catches: a missing or wrong term of the kinetic part's Jacobian (Newton would only slow down)."""
    beam = b3_beam("BE3D", 2)
    q0, v0, y = _random(beam, seed=4)
    part = KineticPart(beam, beam.mass(q0))
    part.start(q0, v0, 1e-2)
    y = 1e-4 * y
    assert rel_err(part.jacobian(y), fd_gradient(part.residual, y, h=1e-8)) < 1e-6


def test_be3d_without_update_keeps_its_energy_to_round_off():
    """BE3D, 2 elements, no director update: after the moment (0.5 s) T + U stays constant over 750 steps.

    Measured: 1.9e-13 relative (Lobatto IIIA at this step: 1e-8); the balance with the load 4.8e-14 J.
    Catches: a kinetic discrete gradient that is not exact (B(q1) - B(q0) != K . d), a stale M(q0) v0.
    """
    beam = b3_beam("BE3D", 2, t_load=0.5, director_update="none")
    h = 2e-3
    res = simulate(beam, (0.0, 1000 * h), method="energy-momentum", h=h, monitors=[EnergyMonitor()])
    assert res.status == "success"
    total, t = np.asarray(res.monitors["energy"]["total"]), res.t
    k = np.searchsorted(t, 0.5 + 1e-12)
    assert np.max(np.abs(total[k:] - total[k])) < 1e-10 * total[k]
    balance = np.asarray(res.monitors["energy"]["balance"])
    assert np.max(np.abs(balance - balance[0])) < 1e-10 * total[k]


def test_update_jumps_are_the_only_change_of_the_balance():
    """With every-step updates the balance changes by exactly the summed jumps: the mechanism isolated."""
    model = UpdateAudit(b3_beam("BE3D", 2, t_load=0.5, director_update="projected"))
    h = 2e-3
    res = simulate(model, (0.0, 300 * h), method="energy-momentum", h=h, monitors=[EnergyMonitor()])
    assert res.status == "success" and res.stats["model_events"] == 300
    jumps = np.array(model.jumps)
    cum = np.concatenate([[0.0], np.cumsum(jumps[:, 1])])[np.searchsorted(jumps[:, 0], res.t + 1e-12, side="right")]
    balance = np.asarray(res.monitors["energy"]["balance"])
    assert abs(cum[-1]) > 1e-6
    assert np.max(np.abs(balance - cum)) < 1e-12
