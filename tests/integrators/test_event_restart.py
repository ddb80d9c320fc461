"""After a model event the driver restarts every stepper with the acceleration of the changed state and model.

A step's own acceleration belongs to the model before the event (BE3D: the old director field, the remapped
torsion rate); Lobatto IIIA starts its step from it and the Newmark family carries it, so a stale one puts an
energy error into every step after an update (issue: the update jumps then missed the balance by 6 %).
"""
import numpy as np
import pytest
import scipy.sparse.linalg as spla

from ancfdae import METHODS, simulate
from support.toy_models import SpringChain


class StiffeningChain(SpringChain):
    """A damped spring chain whose event after every accepted step changes the model (the stiffness, the state
    ``k``) and the velocity: the step's own acceleration is then inconsistent with the restarted state."""

    capabilities = frozenset({"step_events"})

    def __init__(self, k=200.0, **kw):
        super().__init__(k=k, **kw)
        self.restarts = []

    def event_state(self):
        return {"k": np.array(self.k)}

    def bind(self, state):
        other = StiffeningChain.__new__(StiffeningChain)
        other.__dict__.update(self.__dict__)
        other.k = float(state["k"])
        return other

    def step_event(self, t, q, v):
        return q, 0.99 * v, {"k": np.array(1.01 * self.k)}


def _recording(method):
    """``method``'s class with a ``restart`` that keeps the arguments it was given."""
    base = METHODS[method]

    def restart(self, t, q, v, a, model):
        self.seen.append((t, q.copy(), v.copy(), a.copy(), model))
        base.restart(self, t, q, v, a, model)

    return type(base.__name__ + "Recording", (base,), {"restart": restart, "seen": None})


@pytest.mark.parametrize("method", ["lobatto3", "generalized-alpha", "newmark"])
def test_restart_acceleration_is_consistent_with_the_changed_state_and_model(method):
    """Catches: the driver passing the step's own acceleration (the old model's) to ``restart``."""
    model = StiffeningChain(n_masses=3, damping=2.0, v0=np.linspace(-1.0, 2.0, 6))
    cls = _recording(method)
    cls.seen = []
    res = simulate(model, (0.0, 0.05), method=cls, h=0.01)
    assert res.status == "success" and len(cls.seen) == 5 and res.stats["model_events"] == 5
    ks = []
    for t, q, v, a, bound in cls.seen:
        ks.append(bound.k)
        r = bound.residual(t, q, v, np.zeros_like(q))
        a_ref = spla.spsolve(bound.mass(q).tocsc(), -r)
        assert np.max(np.abs(a - a_ref)) <= 1e-12 * np.max(np.abs(a_ref))
        # the old model's acceleration at the same state differs: the check can fail
        old = StiffeningChain(k=bound.k / 1.01, n_masses=3, damping=2.0)
        a_old = spla.spsolve(old.mass(q).tocsc(), -old.residual(t, q, v / 0.99, np.zeros_like(q)))
        assert np.max(np.abs(a_old - a_ref)) > 1e-3 * np.max(np.abs(a_ref))
    assert np.allclose(ks, 200.0 * 1.01 ** np.arange(1, 6))


def test_generalized_alpha_restart_keeps_its_algorithmic_offset():
    """Catches: generalized-alpha restarting with the physical acceleration, which resets the O(h) offset of
    its algorithmic acceleration at every event (on B3 with an update per step: -5.7e-5 J in 2 s)."""
    model = StiffeningChain(n_masses=3, damping=2.0, v0=np.linspace(-1.0, 2.0, 6))
    cls = _recording("generalized-alpha")
    cls.seen = []
    res = simulate(model, (0.0, 0.02), method=cls, h=0.01, rho_inf=0.5)
    assert res.status == "success" and len(cls.seen) == 2
    t, q, v, a_cons, bound = cls.seen[0]
    # the first step from the consistent initial acceleration, without the event, gives the algorithmic a
    plain = METHODS["generalized-alpha"](model, h=0.01, rho_inf=0.5)
    q0, v0 = model.initial_state()
    a0 = spla.spsolve(model.mass(q0).tocsc(), -model.residual(0.0, q0, v0, np.zeros_like(q0)))
    plain.initialize(model, 0.0, q0, v0, a0, 0.02)
    out = plain.step()
    a_alg = out.a
    old = model
    a_old = spla.spsolve(old.mass(out.q).tocsc(), -old.residual(t, out.q, out.v, np.zeros_like(q0)))
    offset = a_alg - a_old
    assert np.max(np.abs(offset)) > 1e-3 * np.max(np.abs(a_old))      # rho_inf < 1: the offset is there
    plain.accept(out)
    plain.restart(t, q, v, a_cons, bound)
    assert np.allclose(plain.a, a_cons + offset, rtol=0, atol=1e-12 * np.max(np.abs(a_cons)))
