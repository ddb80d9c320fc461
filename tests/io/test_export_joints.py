"""A System's joints in the ParaView series and the animation, from the result file alone (no script)."""
import math
import xml.etree.ElementTree as ET

import matplotlib
import meshio
import numpy as np
import pytest

matplotlib.use("Agg")

pytest.importorskip("ancfdae.joints")

from ancfdae import Result, simulate  # noqa: E402
from ancfdae.cli import main  # noqa: E402
from ancfdae.studies._multibody_models import crank_angle, slider_crank  # noqa: E402


@pytest.fixture(scope="module")
def b6_file(tmp_path_factory):
    b = slider_crank("BE2D", 2)
    res = simulate(b.system, (0.0, 0.01), "generalized-alpha", h=1e-3, t_eval=[0.0, 0.005, 0.01])
    assert res.success, res.message
    path = tmp_path_factory.mktemp("b6") / "b6.nc"
    res.save(path)
    return b, path


def test_vtk_writes_the_joints_as_points_with_their_axes_from_the_result_file(b6_file, tmp_path):
    # Catches: joints missing from the result file (the CLI could not draw them without the script), a joint
    # point taken from the wrong body's columns or body point, an axis not following its body.
    b, path = b6_file
    assert main(["export", "vtk", str(path), str(tmp_path), "--name", "b6"]) == 0
    res = Result.load(path)
    names = [j["name"] for j in res.model["system"]["joints"]]
    assert names == ["crank pivot", "crank drive", "crank pin", "slider pin", "slider guide"]
    entries = ET.parse(tmp_path / "b6.pvd").getroot().findall("./Collection/DataSet")
    assert sorted({e.get("part") for e in entries}) == ["0", "1", "2", "3"]     # crank, rod, slider, joints
    m = meshio.read(tmp_path / "b6_3_000002.vtu")
    s, q = b.system, res.q[-1]
    crank, slider = b.bodies["crank"], b.bodies["slider"]
    qc, qs = q[s.offsets[0]:s.offsets[0] + crank.n_dof], q[s.offsets[2]:s.offsets[2] + slider.n_dof]
    th = crank_angle(float(res.t[-1]))[0]
    pin = crank.attachment([0.15, 0.0]).position @ qc
    assert np.allclose(m.points[:, :2], [[0, 0], [0, 0], pin, qs[:2], qs[:2]], rtol=0, atol=1e-12)
    assert np.allclose(pin, 0.15 * np.array([math.cos(th), math.sin(th)]), rtol=0, atol=1e-9)
    axis = m.point_data["axis"]
    assert np.allclose(axis[1, :2], [math.cos(th), math.sin(th)], rtol=0, atol=1e-9)   # the drive: crank's d1
    assert np.allclose(axis[4], [1.0, 0.0, 0.0]) and np.abs(axis[[0, 2, 3]]).max() == 0.0
    assert np.array_equal(m.point_data["joint"], np.arange(5.0))
    assert "crank drive" in (tmp_path / "b6.pvd").read_text()


def test_animate_draws_the_joints_from_the_result_file(b6_file, tmp_path):
    # Catches: animate failing on a System's result (joint records not resolved to bodies) without the script.
    _, path = b6_file
    assert main(["animate", str(path), str(tmp_path / "b6.gif")]) == 0
    assert (tmp_path / "b6.gif").stat().st_size > 0
