"""Rigid bodies in the ParaView series, ancfdae.plot and the CLI: the box of their inertia, rebuilt from the
result file alone."""
import xml.etree.ElementTree as ET
from types import SimpleNamespace

import matplotlib
import meshio
import numpy as np
import pytest

matplotlib.use("Agg")

from ancfdae import Material, RectangularSection, Result, plot  # noqa: E402
from ancfdae._resultfile import describe_model  # noqa: E402
from ancfdae.bodies import RigidBody  # noqa: E402
from ancfdae.bodies.picture import box_corners, box_points  # noqa: E402
from ancfdae.cli import main  # noqa: E402
from ancfdae.export import vtk  # noqa: E402
from ancfdae.models import BE2D, Beam  # noqa: E402
from support import constrained_midpoint as cm  # noqa: E402

THETA = [[0.02, 0.001, 0.0], [0.001, 0.03, -0.002], [0.0, -0.002, 0.04]]


def _spinning_body():
    body = RigidBody(3.0, THETA, [0.1, 0.2, 0.3], com=[0.05, 0.0, -0.02], velocity=[0.5, 0.0, 0.0],
                     angular_velocity=[0.3, -1.0, 4.0], name="payload")
    t, Q, V, _ = cm.run(body, cm.Constraints(body), 0.1, 0.01)
    return body, Result(t=t, q=Q, v=V, a=np.zeros_like(Q), method="test", model=describe_model(body))


def test_the_box_has_the_mass_and_inertia_of_the_body():
    # Catches: box sides from Theta instead of the Euler tensor, or the box not centred at the centre of mass.
    body, _ = _spinning_body()
    X = box_corners(body)
    assert np.allclose(X.mean(axis=0), body.com, rtol=0, atol=1e-15)
    # Sample the box uniformly: its inertia tensor about its centre equals the body's.
    u = np.stack(np.meshgrid(*[(np.arange(40) + 0.5) / 40] * 3, indexing="ij"), -1).reshape(-1, 3)
    P = X[0] + u[:, :1] * (X[1] - X[0]) + u[:, 1:2] * (X[3] - X[0]) + u[:, 2:] * (X[4] - X[0]) - body.com
    theta = body.body_mass * ((P * P).sum(1).mean() * np.eye(3) - P.T @ P / len(P))
    assert np.allclose(theta, THETA, rtol=0, atol=2e-3 * np.max(THETA))   # midpoint sampling: 1/(12 * 40^2)


def test_vtk_of_a_rigid_body_rebuilt_from_the_result_file(tmp_path):
    # Catches: a result file that does not carry the body (the CLI could not export), corners or velocities
    # that do not follow the state.
    body, res = _spinning_body()
    path = res.save(tmp_path / "body.nc")
    assert main(["export", "vtk", str(path), str(tmp_path / "vtk"), "--name", "top"]) == 0
    entries = ET.parse(tmp_path / "vtk" / "top.pvd").getroot().findall("./Collection/DataSet")
    assert [float(e.get("timestep")) for e in entries] == pytest.approx(res.t.tolist(), abs=0)
    for i, e in enumerate(entries):
        mesh = meshio.read(tmp_path / "vtk" / e.get("file"))
        assert mesh.cells[0].type == "hexahedron"
        assert np.allclose(mesh.points, box_points(body, res.q[i]), rtol=0, atol=1e-14)
        assert np.allclose(mesh.point_data["velocity"], box_points(body, res.q[i] + res.v[i]) - mesh.points,
                           rtol=0, atol=1e-13)
    assert np.abs(mesh.point_data["displacement"]).max() > 0.04
    loaded = Result.load(path)
    assert RigidBody.from_description(loaded.model).n_dof == 12


def test_vtk_of_a_system_writes_one_part_per_body(tmp_path):
    # Catches: the coordinates of the second body taken from the wrong columns.
    beam = Beam(BE2D(Material(E=1e7, nu=0.3, rho=1000.0), RectangularSection(0.02)), 2, 0.5)
    body = RigidBody(0.5, 0.01, [0.6, 0.0], angular_velocity=2.0)
    (qb, vb), (qr, vr) = beam.initial_state(), body.initial_state()
    q = np.concatenate([qb, qr])[None].repeat(2, 0)
    v = np.concatenate([vb, vr])[None].repeat(2, 0)
    q[1, beam.n_dof:beam.n_dof + 2] += [0.1, 0.2]              # move the body only
    res = Result(t=np.array([0.0, 1.0]), q=q, v=v, a=0 * q,       # as a System describes itself
                 model={"system": {"bodies": [beam.describe(), body.describe()], "offsets": [0, beam.n_dof]}})
    pvd = vtk(res, directory=tmp_path, name="sys")
    entries = ET.parse(pvd).getroot().findall("./Collection/DataSet")
    assert [(e.get("part"), e.get("file")) for e in entries[:2]] == [("0", "sys_0_000000.vtu"), ("1", "sys_1_000000.vtu")]
    last_beam = meshio.read(tmp_path / "sys_0_000001.vtu")
    last_body = meshio.read(tmp_path / "sys_1_000001.vtu")
    assert np.abs(last_beam.point_data["displacement"]).max() < 1e-15
    assert np.allclose(last_body.point_data["displacement"][:, :2], [0.1, 0.2], rtol=0, atol=1e-15)
    assert last_body.cells[0].type == "quad"
    # The system object itself (bodies at their offsets) gives the same files.
    system = SimpleNamespace(bodies=[beam, body], offsets=[0, beam.n_dof], n_dof=beam.n_dof + body.n_dof)
    vtk(res, system, directory=tmp_path / "given", name="sys")
    again = meshio.read(tmp_path / "given" / "sys_1_000001.vtu")
    assert np.array_equal(again.points, last_body.points)
    res_bad = Result(t=res.t, q=q[:, :-1], v=v[:, :-1], a=0 * q[:, :-1], model=res.model)
    with pytest.raises(ValueError, match="coordinates"):
        vtk(res_bad, directory=tmp_path)


def test_plot_and_animate_a_rigid_body(tmp_path):
    # Catches: the plot drawing something other than the box's 12 edges, animate failing without the script.
    body, res = _spinning_body()
    ax = plot.configuration(body, res.q[-1])
    lines = ax.get_lines()
    assert len(lines) == 1 + 12
    ends = np.array([np.column_stack(line.get_data_3d()) for line in lines[1:]]).reshape(-1, 3)
    assert np.allclose(np.unique(ends.round(12), axis=0), np.unique(box_points(body, res.q[-1]).round(12), axis=0))
    with pytest.raises(ValueError, match="3D"):
        plot.configuration(body, res.q[-1], matplotlib.figure.Figure().add_subplot())
    out = plot.animate(res, tmp_path / "top.gif", every=5)
    assert out.stat().st_size > 0
