"""The Exudyn peer runners return correct physics (skipped where exudyn is not installed)."""
import pathlib
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

pytest.importorskip("exudyn", reason="exudyn is not installed (pip install '.[benchmark]')")
# benchmarks/ is a folder of the repository, not part of the installed package: reach it from the
# checkout (appended, so an installed ancfdae keeps precedence over the source tree).
sys.path.append(str(pathlib.Path(__file__).resolve().parents[2]))
from benchmarks import _exudyn_peer as peer  # noqa: E402

if not peer.available():
    pytest.skip("exudyn is not installed", allow_module_level=True)


def test_be2d_cantilever_tip_has_the_expected_discretisation_error():
    # Exudyn's ANCFcantileverTest gives 5.06e-5 m at 8 elements; BE2D converges with order ~4-5.
    r8 = peer.cantilever_be2d(8, repeats=1)
    r16 = peer.cantilever_be2d(16, repeats=1)
    assert 3e-5 < r8["error"] < 8e-5
    assert r16["error"] < r8["error"] / 16
    assert np.allclose(r8["tip"], peer.B1_REF_BE, atol=1e-4)
    assert 10 <= r8["newton_iterations"] <= 80  # 10 load steps of full Newton
    assert r8["n_dof"] == 4 * 9 and len(r8["walls"]) == 1


def test_beam3d_cantilever_error_against_the_shear_deformable_reference():
    r = peer.cantilever_beam3d(8, repeats=1)
    # regression value of the peer, measured with Exudyn 1.9: relative tip error 1.0e-2 at 8 elements
    # (2.6e-3, 6.5e-4, 1.6e-4 at 16, 32, 64: order 2, as a linear element must)
    assert 0.8e-2 < r["rel_error"] < 1.2e-2
    assert r["tip"][1] < peer.B1_REF_SQ[1]  # the coarse linear element is too stiff


def test_hinged_pendulum_starts_as_the_rigid_pendulum():
    # EI is large: over 0.2 s the beam swings like a rigid bar, theta'' = 3 g cos(theta) / (2 L).
    r = peer.pendulum(25, t_end=0.2, h=1e-3, output_period=0.01)
    rigid = solve_ivp(lambda t, z: [z[1], 1.5 * 9.81 * np.cos(z[0])], (0.0, 0.2), [0.0, 0.0],
                      t_eval=r["t"], rtol=1e-10, atol=1e-12)
    assert r["t"][-1] == pytest.approx(0.2) and r["steps"] == 200
    assert np.max(np.abs(r["y"] + np.sin(rigid.y[0]))) < 1e-3
    assert np.max(np.abs(r["x"] - np.cos(rigid.y[0]))) < 1e-3
    assert abs(r["energy_drift"]) < 1e-4


def test_free_beam_energy_trapezoidal_conserves_generalized_alpha_dissipates():
    kw = dict(free=True, t_end=0.1, h=1e-3, output_period=0.01)
    trap = peer.pendulum(25, **kw)
    alpha = peer.pendulum(25, integrator="generalized_alpha", **kw)
    assert trap["energy0"] == pytest.approx(10.0, rel=1e-5)  # int rhoA (2 sin(pi x))^2 / 2 dx
    assert abs(trap["energy_drift"]) < 1e-4
    assert alpha["energy_drift"] < -1e-3
    assert trap["jacobians"] >= 1 and 1 <= trap["newton_iterations_per_step"] < 10


def test_bad_input_names_the_argument():
    with pytest.raises(ValueError, match="n_elements"):
        peer.cantilever_be2d(0)
    with pytest.raises(ValueError, match="integrator"):
        peer.pendulum(4, integrator="euler")


def test_energy_is_the_one_exudyn_minimises():
    # At the B1 equilibrium (8 ObjectANCFCable2D) the gradient of our evaluation of Exudyn's strain
    # energy (central differences) must balance the tip load on every free coordinate.
    from benchmarks._exudyn_pendulum import _cable2d_energy, _nodal

    exu = peer._exu
    SC, mbs, tip = peer._build_b1_be2d(8)
    assert exu.MainSolverStatic().SolveSystem(mbs, peer._static_settings())
    nodes = list(range(1, 10))  # node 0 of the model is the ground node
    sd = mbs.systemData
    q = _nodal(mbs, nodes, sd.GetODE2Coordinates() + sd.GetODE2Coordinates(exu.ConfigurationType.Reference))
    a, E = peer.B1["a"], peer.B1["E"]

    def strain(x):
        x = x.reshape(q.shape)
        return _cable2d_energy(x, np.zeros_like(x), 0.25, 1.0, E * a**2, E * a**4 / 12, 0.0)[1]

    x0 = q.ravel()
    grad = np.empty_like(x0)
    for i in range(x0.size):
        d = np.zeros_like(x0)
        d[i] = 1e-7 * max(1.0, abs(x0[i]))
        grad[i] = (strain(x0 + d) - strain(x0 - d)) / (2 * d[i])
    load = np.zeros_like(x0)
    load[-3] = peer.B1["F"]  # y of the last node
    free = np.setdiff1d(np.arange(x0.size), [0, 1, 3])
    assert np.max(np.abs(grad - load)[free]) < 1e-6 * peer.B1["F"]
