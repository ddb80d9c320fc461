"""Pictures (through the returned matplotlib objects), the animation, and the command line."""
import subprocess
import sys
import xml.etree.ElementTree as ET

import matplotlib
import numpy as np
import pytest
from matplotlib.figure import Figure
from PIL import Image

import ancfdae
from ancfdae import EnergyMonitor, Gravity, Material, PointForce, RectangularSection, Result, simulate
from ancfdae import plot
from ancfdae.cli import main
from ancfdae.models import BE2D, Beam, Cable3D

SOFT = Material(E=1e6, nu=0.3, rho=1000.0)
SEC = RectangularSection(0.1)


@pytest.fixture(scope="module")
def run2d():
    beam = Beam(BE2D(SOFT, SEC), 3, 1.0, supports={0: "clamp"}, loads=[Gravity([0.0, -9.81])])
    return beam, simulate(beam, (0, 0.1), "lobatto3", h=0.01, monitors=[EnergyMonitor()])


def test_configuration_2d_draws_axis_and_faces(run2d):
    beam, res = run2d
    ax = Figure().add_subplot()
    backend = matplotlib.get_backend()
    out = plot.configuration(beam, res.q[-1], ax)
    assert out is ax and matplotlib.get_backend() == backend
    axis = ax.lines[0].get_xydata()
    s = np.linspace(0, 1.0, 8 * 3 + 1)
    np.testing.assert_allclose(axis, beam.position(res.q[-1], s), atol=1e-14)   # the axis drawn is r(s)
    # faces at eta = +-h/2: the band is h wide, normal to r' at the nodes
    top, bottom = ax.lines[1].get_xydata(), ax.lines[2].get_xydata()
    np.testing.assert_allclose(np.linalg.norm(top - bottom, axis=1), 0.1, atol=1e-12)
    assert len(ax.lines) == 3 + beam.n_nodes


def test_configuration_3d_and_axes_check():
    beam = Beam(Cable3D(SOFT, SEC), 2, 1.0, supports={0: "clamp"})
    q = beam.initial_state()[0]
    ax = Figure().add_subplot(projection="3d")
    plot.configuration(beam, q, ax)
    x, y, z = ax.lines[0].get_data_3d()
    np.testing.assert_allclose(x, np.linspace(0, 1, 17), atol=1e-14)
    assert np.all(y == 0) and np.all(z == 0)
    ring = np.array(ax.lines[1].get_data_3d()).T   # the first node's section: square of side 0.1 in y-z
    assert np.allclose(ring[:, 0], 0) and np.isclose(np.ptp(ring[:, 1]), 0.1) and np.isclose(np.ptp(ring[:, 2]), 0.1)
    with pytest.raises(ValueError, match="3D"):
        plot.configuration(beam, q, Figure().add_subplot())
    with pytest.raises(ValueError, match="`q` must have shape"):
        plot.configuration(beam, q[:-1], ax)


def test_energy_and_tip_plots(run2d):
    beam, res = run2d
    ax = plot.energy(res, Figure().add_subplot())
    assert [line.get_label() for line in ax.lines] == ["kinetic", "strain", "potential", "total"]
    np.testing.assert_array_equal(ax.lines[3].get_ydata(), res.monitors["energy"]["total"])
    ax = plot.tip(res, Figure().add_subplot())          # beam rebuilt from the result's description
    u = np.array([beam.position(q, 1.0) for q in res.q]) - beam.position(beam.initial_state()[0], 1.0)
    np.testing.assert_allclose(ax.lines[1].get_ydata(), u[:, 1], atol=1e-14)
    assert ax.lines[1].get_ydata().min() < -1e-4       # it sagged
    with pytest.raises(ValueError, match="no monitor 'energy'"):
        plot.energy(Result(t=res.t, q=res.q, v=res.v, a=res.a))


def test_animate_writes_a_gif(run2d, tmp_path):
    _, res = run2d
    out = plot.animate(res, tmp_path / "a.gif", every=2)
    with Image.open(out) as im:
        assert im.format == "GIF" and im.n_frames == (res.t.size + 1) // 2


def test_cli_version_export_animate(run2d, tmp_path, capsys):
    _, res = run2d
    path = res.save(tmp_path / "r.nc")
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and ancfdae.__version__ in capsys.readouterr().out
    assert main(["export", "vtk", str(path), str(tmp_path / "vtk"), "--every", "5"]) == 0
    pvd = tmp_path / "vtk" / "beam.pvd"
    assert len(ET.parse(pvd).getroot().findall("./Collection/DataSet")) == 3
    assert main(["animate", str(path), str(tmp_path / "m.gif"), "--every", "5"]) == 0
    assert (tmp_path / "m.gif").stat().st_size > 0
    bad = tmp_path / "bad.nc"
    bad.write_text("x")
    with pytest.raises(SystemExit, match="bad.nc: not a NetCDF4/HDF5 file"):
        main(["export", "vtk", str(bad), str(tmp_path / "v2")])


def test_studies_missing_from_an_uninstalled_checkout_is_a_clear_exit(monkeypatch):
    """Catches a bare ModuleNotFoundError traceback where a checkout's ancfdae, not installed (on the path
    before the installed one), lacks the studies, which only installation maps to ancfdae.studies."""
    monkeypatch.setitem(sys.modules, "ancfdae.studies", None)     # what such an import finds: nothing
    with pytest.raises(SystemExit, match="studies are not importable.*not installed.*pip install -e"):
        main(["studies"])
    with pytest.raises(SystemExit, match="studies are not importable"):
        main(["study", "cantilever", "--quick"])


def test_python_dash_m(tmp_path):
    # run outside the checkout, as a user would: -m puts the current folder first on sys.path
    out = subprocess.run([sys.executable, "-m", "ancfdae", "--version"], capture_output=True, text=True, check=True,
                         cwd=tmp_path)
    assert out.stdout.strip() == f"ancfdae {ancfdae.__version__}"


def test_no_backend_switch_in_library_or_studies():
    """A notebook user's backend survives importing and plotting: no matplotlib.use anywhere."""
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    hits = [str(p.relative_to(root)) for base in ("ancfdae", "studies") for p in (root / base).rglob("*.py")
            if "matplotlib.use(" in p.read_text()]
    assert not hits, f"matplotlib.use in {hits}"
