"""Study records in one NetCDF4 file: exact round trip, plain-xarray access, clear errors."""
import numpy as np
import pytest
import xarray as xr

from ancfdae import ResultFileError
from ancfdae.records import load_records, save_records


def _record(i):
    rng = np.random.default_rng(i)
    return {"t": np.linspace(0, 1, 11), "tip": rng.standard_normal((11, 2)),
            "energy": {"total": rng.standard_normal(11), "t_blow_up": None, "flags": {"n": np.arange(3)}},
            "stats": {"steps": 10 + i, "rate": 0.5}, "cpu": 1.25 + i, "status": "success", "t_fail": None,
            "message": "done", "dof": 33, "reference": bool(i % 2), "meshes": [2, 4], "empty": {}}


def test_records_round_trip_exactly(tmp_path):
    records = [_record(i) for i in range(3)]
    path = save_records(records, tmp_path / "records")
    assert path.suffix == ".nc"
    back = load_records(path)
    assert len(back) == 3
    for r, b in zip(records, back):
        assert set(b) == set(r)
        for key in ("t", "tip"):
            np.testing.assert_array_equal(b[key], r[key])
            assert b[key].dtype == r[key].dtype
        np.testing.assert_array_equal(b["energy"]["total"], r["energy"]["total"])
        np.testing.assert_array_equal(b["energy"]["flags"]["n"], r["energy"]["flags"]["n"])
        assert b["energy"]["t_blow_up"] is None and b["t_fail"] is None and b["empty"] == {}
        assert b["stats"] == r["stats"] and b["meshes"] == r["meshes"]
        assert (b["cpu"], b["status"], b["dof"], b["reference"]) == (r["cpu"], r["status"], r["dof"], r["reference"])


def test_records_open_with_plain_xarray(tmp_path):
    path = save_records([_record(0), _record(1)], tmp_path / "r.nc")
    tree = xr.open_datatree(path)
    try:
        assert sorted(tree.children) == ["record_0000", "record_0001"]
        np.testing.assert_array_equal(tree["record_0001"]["energy.total"].values, _record(1)["energy"]["total"])
    finally:
        tree.close()


def test_records_errors(tmp_path):
    with pytest.raises(ValueError, match="keys must be strings without"):
        save_records([{"a.b": 1}], tmp_path / "x.nc")
    with pytest.raises(TypeError, match="list of dicts"):
        save_records({"a": 1}, tmp_path / "x.nc")
    other = tmp_path / "other.nc"
    xr.Dataset(attrs={"format": "something"}).to_netcdf(other)
    with pytest.raises(ResultFileError, match="other.nc.*not an ancfdae records file"):
        load_records(other)
    junk = tmp_path / "junk.nc"
    junk.write_text("junk")
    with pytest.raises(ResultFileError, match="junk.nc.*not a readable"):
        load_records(junk)
