"""Result: time-major arrays, status, save/load round trip (design.md Sect. 6)."""
import numpy as np
import pytest

from ancfdae import EnergyMonitor, PointSensor, Result, simulate
from toy_models import SpringChain


def test_save_load_round_trip(tmp_path):
    res = simulate(SpringChain(3, force=(1.0, 0.0), T=0.3), (0, 0.5), "lobatto3", h=0.01,
                   t_eval=np.linspace(0, 0.5, 6), monitors=[EnergyMonitor(), PointSensor(s=2.5)])
    path = res.save(tmp_path / "run")
    assert path.suffix == ".npz" and path.exists()
    back = Result.load(path)
    for name in ("t", "q", "v", "a"):
        np.testing.assert_array_equal(getattr(back, name), getattr(res, name))
    assert (back.status, back.message, back.method, back.t_fail) == (res.status, res.message, res.method, None)
    assert back.stats == res.stats and back.options == res.options
    for name, log in res.monitors.items():
        assert set(back.monitors[name]) == set(log)
        for key, val in log.items():
            if isinstance(val, np.ndarray):
                np.testing.assert_array_equal(back.monitors[name][key], val)
            else:
                assert back.monitors[name][key] == val
    assert back.success


def test_failed_result_round_trip(tmp_path):
    res = simulate(SpringChain(2), (0, 1), "newmark", h=0.05, monitors=[EnergyMonitor()],
                   newton={"max_iter": 1, "tol": 1e-14, "atol": 0.0, "jacobian": "full"})
    assert not res.success
    back = Result.load(res.save(tmp_path / "failed.npz"))
    assert back.status == "failed" and back.t_fail == res.t_fail and back.message == res.message
    assert back.t.size == res.t.size >= 1
    assert "failed" in repr(back)


def test_time_major_shapes_and_validation():
    r = Result(t=[0.0, 1.0], q=np.zeros((2, 3)), v=np.zeros((2, 3)), a=np.zeros((2, 3)))
    assert r.q.shape == (2, 3) and r.success and r.status == "success"
    with pytest.raises(ValueError, match="status"):
        Result(t=[0.0], q=np.zeros((1, 2)), v=np.zeros((1, 2)), a=np.zeros((1, 2)), status="ok")
    with pytest.raises(ValueError, match="`q` must have shape"):
        Result(t=[0.0, 1.0], q=np.zeros((3, 2)), v=np.zeros((2, 2)), a=np.zeros((2, 2)))
    empty = Result(t=[], q=np.zeros((0, 4)), v=np.zeros((0, 4)), a=np.zeros((0, 4)), status="failed")
    assert not empty.success and "[]" in repr(empty)


def test_load_rejects_foreign_file(tmp_path):
    p = tmp_path / "x.npz"
    np.savez(p, metadata=np.array('{"format": "other"}'), t=np.zeros(1))
    with pytest.raises(ValueError, match="not an ancfdae Result"):
        Result.load(p)
