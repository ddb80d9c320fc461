"""The director-geometry monitor: the angle between an element's nodal directors, the smallest projection of
Eq. 99 inside it, with the directors valid at each output time (after the updates of a run)."""
import numpy as np
import pytest

from ancfdae import DirectorGeometry, Material, PointMoment, RectangularSection, hat, simulate
from ancfdae.models import BE2D, BE3D, Beam

MAT, SEC = Material(E=1e5, nu=0.3, rho=2500.0), RectangularSection(0.05)


def _beam(n=2, **kw):
    return Beam(BE3D(MAT, SEC, **kw), n, 1.0, start=(0, 0, 0), direction=(0.6, 0.8, 0.0),
                loads=[PointMoment(np.array([0.1, 0.05, 0.2]), node=0, time=hat(0.5))])


def _sample(model, q, points=9):
    mon = DirectorGeometry(points=points)
    mon.start(model, 0.0, q, 0 * q, 0 * q)
    mon.sample(0.0, q, 0 * q, 0 * q)
    return mon.log()


def test_turned_director_gives_its_angle_and_the_midpoint_projection():
    """Catches: degrees/radians, a normalised interpolated director (projection 1), the wrong element."""
    beam = _beam(3)
    q, _ = beam.initial_state()
    log = _sample(beam, q)
    assert log["max_angle"][0] == pytest.approx(0.0, abs=1e-6) and log["min_projection"][0] == pytest.approx(1.0)
    d = np.array(beam.geom["directors"])
    e1 = np.array([0.6, 0.8, 0.0])
    phi = np.radians(100.0)
    # node 2's director turned by 100 degrees about the (straight) axis: elements 1 and 2 see it
    d[2] = np.cos(phi) * d[2] + np.sin(phi) * np.cross(e1, d[2])
    log = _sample(beam.bind({"directors": d}), q)
    assert log["max_angle"][0] == pytest.approx(100.0, rel=1e-12)
    assert log["max_angle_element"][0] in (1, 2)
    assert log["min_projection"][0] == pytest.approx(np.cos(phi / 2), rel=1e-12)   # at the midpoint
    assert log["min_projection_element"][0] in (1, 2)
    # with 2 points (the ends only) the interior is not seen
    assert _sample(beam.bind({"directors": d}), q, points=2)["min_projection"][0] == pytest.approx(1.0)


def test_monitor_follows_the_director_updates_of_a_run():
    """Catches: a monitor that keeps the initial directors (no rebind after the model events)."""
    beam = _beam(2)
    res = simulate(beam, (0.0, 0.3), method="lobatto3", h=0.01, t_eval=np.linspace(0, 0.3, 7),
                   monitors=[DirectorGeometry()])
    assert res.status == "success" and res.stats["model_events"] == 30
    log = res.monitors["directors"]
    D = res.model_state["directors"]
    angles = [np.degrees(np.max(np.arccos(np.clip(np.einsum("ei,ei->e", d[:-1], d[1:]), -1, 1)))) for d in D]
    assert np.allclose(log["max_angle"], angles, rtol=1e-10, atol=1e-9)
    assert log["max_angle"][-1] > 1e-3                 # the directors did move apart
    assert np.all((log["min_projection"] > 0.9) & (log["min_projection"] <= 1.0))


def test_needs_a_be3d_beam_and_valid_points():
    beam = Beam(BE2D(MAT, SEC), 2, 1.0)
    q, v = beam.initial_state()
    res = simulate(beam, (0.0, 0.02), method="newmark", h=0.01, monitors=[DirectorGeometry()])
    assert res.status == "failed" and "DirectorGeometry needs a beam of BE3D-type elements" in res.message
    with pytest.raises(ValueError, match="`points` must be at least 2"):
        DirectorGeometry(points=1)
