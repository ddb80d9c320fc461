"""Result: time-major arrays, status, and the NetCDF4 file round trip."""
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from ancfdae import EnergyMonitor, Gravity, Material, PointSensor, RectangularSection, Result, ResultFileError, simulate
from ancfdae import _filecheck, _resultfile
from ancfdae.export import beam_of
from ancfdae.models import BE2D, BE3D, SQ2D, SQ3D, Beam, Cable3D
from support.toy_models import SpringChain

SOFT = Material(E=1e6, nu=0.3, rho=1000.0)
SEC = RectangularSection(0.1)


def _beam(element_cls, **options):
    el = element_cls(SOFT, SEC, **options)
    g = [0.0, -9.81] if el.dim == 2 else [0.0, -9.81, 0.0]
    return Beam(el, 2, 1.0, supports={0: "clamp"}, loads=[Gravity(g)])


def _assert_same(back, res):
    """Every field equal, arrays bit for bit (a float cast or a lossy codec would fail here)."""
    for name in ("t", "q", "v", "a"):
        np.testing.assert_array_equal(getattr(back, name), getattr(res, name))
        assert getattr(back, name).dtype == getattr(res, name).dtype
    assert (back.status, back.message, back.method, back.t_fail) == (res.status, res.message, res.method, res.t_fail)
    assert back.stats == res.stats and back.options == res.options
    assert back.model == res.model
    assert set(back.monitors) == set(res.monitors)
    for name, log in res.monitors.items():
        assert set(back.monitors[name]) == set(log)
        for key, val in log.items():
            if isinstance(val, np.ndarray):
                np.testing.assert_array_equal(back.monitors[name][key], val)
            elif isinstance(val, float) and np.isnan(val):
                assert np.isnan(back.monitors[name][key])
            else:
                assert back.monitors[name][key] == val
    assert set(back.model_state) == set(res.model_state)
    for key, val in res.model_state.items():
        np.testing.assert_array_equal(back.model_state[key], val)


def test_save_load_round_trip_toy_model(tmp_path):
    res = simulate(SpringChain(3, force=(1.0, 0.0), T=0.3), (0, 0.5), "lobatto3", h=0.01,
                   t_eval=np.linspace(0, 0.5, 6), monitors=[EnergyMonitor(), PointSensor(s=2.5)])
    path = res.save(tmp_path / "run")
    assert path.suffix == ".nc" and path.exists()
    back = Result.load(path)
    _assert_same(back, res)
    assert back.success and back.model == {}


@pytest.mark.parametrize("method, h", [("lobatto3", 0.01), ("lobatto2", 0.01), ("newmark", 0.01), ("hht", 0.01),
                                       ("generalized-alpha", 0.01), ("ida", None)])
def test_round_trip_every_integrator(tmp_path, method, h):
    res = simulate(_beam(BE2D), (0, 0.03), method, h=h, monitors=[EnergyMonitor(), PointSensor(s=1.0)])
    assert res.success, res.message
    _assert_same(Result.load(res.save(tmp_path / f"{method}.nc")), res)


@pytest.mark.parametrize("element_cls, options", [(BE2D, {}), (Cable3D, {}), (BE3D, {}), (SQ2D, {}),
                                                  (SQ3D, {"formulation": "continuum"})])
def test_round_trip_every_element_with_model_description(tmp_path, element_cls, options):
    beam = _beam(element_cls, **options)
    res = simulate(beam, (0, 0.02), "lobatto3", h=0.005, monitors=[EnergyMonitor()])
    assert res.success, res.message
    assert res.model["element"]["type"] == element_cls.name
    if element_cls is BE3D:   # the nodal directors, one row per output, recorded by the driver
        assert res.model_state["directors"].shape == (res.t.size, beam.n_nodes, 3)
    back = Result.load(res.save(tmp_path / "r.nc"))
    _assert_same(back, res)
    ds = xr.open_dataset(tmp_path / "r.nc")    # plain xarray: labelled variables and the recipe
    try:
        node, coord = beam.dof_labels()
        np.testing.assert_array_equal(ds["node"].values, node)
        assert list(ds["coordinate"].values) == list(coord)
        assert ds["q"].dims == ("time", "dof") and ds["monitor.energy.total"].dims == ("time",)
        assert json.loads(ds.attrs["element"])["type"] == element_cls.name
        np.testing.assert_array_equal(ds["reference_nodes"].values, beam.points)
        np.testing.assert_array_equal(ds["element_nodes"].values, beam.element_nodes)
        assert ds.attrs["formulation"] == options.get("formulation", "structural")
        if element_cls is BE3D:
            assert ds["state.directors"].shape == (res.t.size, beam.n_nodes, 3)
    finally:
        ds.close()


def test_dof_labels_name_node_and_coordinate():
    beam = _beam(BE3D)   # clamp at node 0 fixes all of node 0 except the axial slope x'
    node, coord = beam.dof_labels()
    assert node.size == beam.n_dof
    full = beam.element.node_coordinates
    for i, (n, c) in enumerate(zip(node, coord)):   # the label points at the coordinate it names
        assert beam.free[i] == n * len(full) + full.index(c)
    assert "theta" in coord and "x'" in coord


def test_a_users_element_rebuilds_from_the_file_by_its_name(tmp_path):
    # Catches a hard-coded list of the built-in elements in the rebuild (a user's element could not be
    # read back) and a registry that lets two classes claim one name.
    from ancfdae.models import Element

    class StiffBE2D(BE2D):
        name = "StiffBE2D"

    beam = _beam(StiffBE2D, bending_points=4)
    res = simulate(beam, (0, 0.01), "lobatto3", h=0.005)
    back = Beam.from_description(Result.load(res.save(tmp_path / "r.nc")).model)
    assert type(back.element) is StiffBE2D and back.element.bending_points == 4
    np.testing.assert_array_equal(back.q_ref, beam.q_ref)
    assert Element.by_name("StiffBE2D") is StiffBE2D
    with pytest.raises(TypeError, match="StiffBE2D"):
        type("Impostor", (BE2D,), {"name": "StiffBE2D"})
    with pytest.raises(ValueError, match="element type must be one of .*got 'Nonesuch'"):
        Element.by_name("Nonesuch")


def test_failed_result_round_trip(tmp_path):
    res = simulate(SpringChain(2), (0, 1), "newmark", h=0.05, monitors=[EnergyMonitor()],
                   newton={"max_iter": 1, "tol": 1e-14, "residual_atol": 0.0, "jacobian": "full"})
    assert not res.success
    back = Result.load(res.save(tmp_path / "failed.nc"))
    assert back.status == "failed" and back.t_fail == res.t_fail and back.message == res.message
    assert back.t.size == res.t.size >= 1
    assert "failed" in repr(back)


def test_other_engine_reads_and_writes(tmp_path):
    pytest.importorskip("h5py")
    res = simulate(SpringChain(2), (0, 0.1), "lobatto3", h=0.01, monitors=[EnergyMonitor()])
    back = Result.load(res.save(tmp_path / "h5.nc", engine="h5netcdf"))
    _assert_same(back, res)


def test_time_major_shapes_and_validation():
    r = Result(t=[0.0, 1.0], q=np.zeros((2, 3)), v=np.zeros((2, 3)), a=np.zeros((2, 3)))
    assert r.q.shape == (2, 3) and r.success and r.status == "success"
    with pytest.raises(ValueError, match="status"):
        Result(t=[0.0], q=np.zeros((1, 2)), v=np.zeros((1, 2)), a=np.zeros((1, 2)), status="ok")
    with pytest.raises(ValueError, match="`q` must have shape"):
        Result(t=[0.0, 1.0], q=np.zeros((3, 2)), v=np.zeros((2, 2)), a=np.zeros((2, 2)))
    with pytest.raises(ValueError, match="model_state"):
        Result(t=[0.0, 1.0], q=np.zeros((2, 2)), v=np.zeros((2, 2)), a=np.zeros((2, 2)),
               model_state={"directors": np.zeros((3, 2, 3))})
    empty = Result(t=[], q=np.zeros((0, 4)), v=np.zeros((0, 4)), a=np.zeros((0, 4)), status="failed")
    assert not empty.success and "[]" in repr(empty)


def test_save_names_what_is_not_json_able(tmp_path):
    r = Result(t=[0.0], q=np.zeros((1, 2)), v=np.zeros((1, 2)), a=np.zeros((1, 2)), options={"f": object()})
    with pytest.raises(ValueError, match="Result.options must be JSON-able"):
        r.save(tmp_path / "x.nc")


def test_empty_failed_result_round_trip(tmp_path):
    empty = Result(t=[], q=np.zeros((0, 4)), v=np.zeros((0, 4)), a=np.zeros((0, 4)), status="failed",
                   message="failed at once", t_fail=0.0)
    back = Result.load(empty.save(tmp_path / "empty.nc"))
    _assert_same(back, empty)


@pytest.fixture
def saved(tmp_path):
    res = simulate(SpringChain(2), (0, 0.1), "lobatto3", h=0.01, monitors=[EnergyMonitor()])
    return res.save(tmp_path / "good.nc")


def test_truncated_file_is_a_clear_error(saved, tmp_path):
    data = saved.read_bytes()
    bad = tmp_path / "truncated.nc"
    bad.write_bytes(data[: len(data) // 2])
    with pytest.raises(ResultFileError, match="truncated.nc.*damaged or truncated"):
        Result.load(bad)


def test_foreign_files_are_clear_errors(tmp_path):
    text = tmp_path / "notes.txt"
    text.write_text("hello")
    with pytest.raises(ResultFileError, match="notes.txt.*not a NetCDF4/HDF5"):
        Result.load(text)
    old = tmp_path / "old.npz"
    np.savez(old, metadata=np.array('{"format": "ancfdae.Result/1"}'), t=np.zeros(1))
    with pytest.raises(ResultFileError, match="old.npz.*no longer read"):
        Result.load(old)
    foreign = tmp_path / "foreign.nc"
    xr.Dataset({"x": ("i", np.arange(3.0))}, attrs={"title": "other"}).to_netcdf(foreign, engine="netcdf4")
    with pytest.raises(ResultFileError, match="foreign.nc.*not an ancfdae result"):
        Result.load(foreign)
    with pytest.raises(ResultFileError, match="missing.nc.*no such"):
        Result.load(tmp_path / "missing.nc")
    assert issubclass(ResultFileError, ValueError)


def _rewritten(ds, path, refresh_checksums):
    """Write ``ds`` as a hand-edited file; with ``refresh_checksums`` its checksums are recomputed (a forger)."""
    ds = ds.copy()
    if refresh_checksums:
        ds.attrs[_filecheck.CHECKSUM_ATTR] = json.dumps(_filecheck.checksums(ds))
    ds.to_netcdf(path, engine="netcdf4", encoding=_filecheck.encoding(ds))
    return path


def test_damaged_content_is_a_clear_error(saved, tmp_path):
    """Catches an edited file read as data (checksums) and malformed content past the checksums read wrongly."""
    with xr.open_dataset(saved) as ds:
        ds.load()
    with pytest.raises(ResultFileError, match="novar.nc.*variable 'v' is missing"):
        Result.load(_rewritten(ds.drop_vars("v"), tmp_path / "novar.nc", False))
    with pytest.raises(ResultFileError, match="novar2.nc.*variable 'v' is missing"):
        Result.load(_rewritten(ds.drop_vars("v"), tmp_path / "novar2.nc", True))
    ds.attrs["stats"] = "{not json"
    with pytest.raises(ResultFileError, match="badattr.nc.*attribute 'stats' does not match its stored checksum"):
        Result.load(_rewritten(ds, tmp_path / "badattr.nc", False))
    with pytest.raises(ResultFileError, match="badattr2.nc.*'stats' is not JSON"):
        Result.load(_rewritten(ds, tmp_path / "badattr2.nc", True))
    ds.attrs["stats"] = "{}"
    ds.attrs["status"] = "converged"          # read fine, but Result refuses it: still a file error
    with pytest.raises(ResultFileError, match="badstatus.nc: damaged ancfdae result file: `status` must be one of"):
        Result.load(_rewritten(ds, tmp_path / "badstatus.nc", True))


#: A result file written by the code before the result-file module stopped building Results itself
#: (format ancfdae.Result/2): BE3D, 2 elements clamped at node 0, gravity and a tip moment (0, 0, 0.5),
#: E = 1e6, nu = 0.3, rho = 1000, square 0.1; lobatto3, h = 0.005 over [0, 0.02]; monitors
#: EnergyMonitor(), PointSensor(s=1.0) and Probe("tip_q", the last three coordinates).
OLD_FILE = Path(__file__).resolve().parents[1] / "data" / "result_format2_be3d.nc"


def test_a_file_written_by_earlier_code_loads_and_is_written_again_identically(tmp_path):
    """Catches a change of the on-disk layout (a variable, dimension or attribute renamed or dropped, a
    dtype or a JSON text changed) that would leave users' earlier files unreadable or new files different.
    The format-2 file has no checksums; written again it is format 3: the same file plus the checksums."""
    old = Result.load(OLD_FILE)
    assert old.success and old.method == "lobatto3" and old.t.size == 5 and old.q.shape == (5, 15)
    assert set(old.monitors) == {"energy", "point@1", "tip_q"} and old.monitors["energy"]["blow_up"] is False
    assert old.model_state["directors"].shape == (5, 3, 3)
    again = old.save(tmp_path / "again.nc")
    with xr.open_dataset(OLD_FILE) as before, xr.open_dataset(again) as after:
        assert before.attrs.pop("format") == "ancfdae.Result/2" and after.attrs.pop("format") == _resultfile.FORMAT
        assert after.attrs.pop(_filecheck.CHECKSUM_ATTR)
        xr.testing.assert_identical(before, after)        # values bit for bit, names, dims, attributes
        for name in before.variables:
            assert before[name].dtype == after[name].dtype, name
            assert bool(after[name].encoding.get("fletcher32")) == (after[name].dtype.kind in "fi"), name
        np.testing.assert_array_equal(old.q, before["q"].values)
    _assert_same(Result.load(again), old)
    beam = beam_of(old)                                    # the description still rebuilds the beam
    assert beam.element.name == "BE3D" and beam.n_dof == old.q.shape[1]


def test_the_result_file_module_writes_every_field_of_result():
    """Catches a field added to Result but not to the file layout (it would be lost by save/load)."""
    assert _resultfile.FIELDS == tuple(f.name for f in dataclasses.fields(Result))
