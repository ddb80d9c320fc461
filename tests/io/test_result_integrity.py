"""Result files detect damage: a changed byte or an edited dimension is an error, never other data."""
import json

import numpy as np
import pytest
import xarray as xr

from ancfdae import Material, RectangularSection, Result, ResultFileError
from ancfdae import _filecheck
from ancfdae._resultfile import describe_model
from ancfdae.models import BE2D, Beam

#: bytes flipped per file (a seeded sample of the offsets, the data region included)
N_FLIPS = 240


def _result(n_out=7):
    """A Result with a beam description (BE2D, 2 elements clamped at node 0: n_dof 9), random states and a monitor log."""
    beam = Beam(BE2D(Material(E=1e6, nu=0.3, rho=1000.0), RectangularSection(0.1)), 2, 1.0, supports={0: "clamp"})
    rng = np.random.default_rng(7)
    n = beam.n_dof
    t = np.linspace(0.0, 0.3, n_out)
    return Result(t=t, q=rng.normal(size=(n_out, n)), v=rng.normal(size=(n_out, n)), a=rng.normal(size=(n_out, n)),
                  stats={"steps": 30, "newton_iterations": 61}, method="lobatto3", options={"h": 0.01},
                  monitors={"energy": {"total": rng.normal(size=n_out), "relative_drift": 1e-3, "blow_up": False}},
                  model=describe_model(beam))


def _same(a, b):
    """Bit-for-bit equal fields (what an identical load must give)."""
    for name in ("t", "q", "v", "a"):
        if not np.array_equal(getattr(a, name), getattr(b, name)):
            return False
    m1, m2 = a.monitors["energy"], b.monitors["energy"]
    return ((a.status, a.message, a.method, a.stats, a.options, a.model) ==
            (b.status, b.message, b.method, b.stats, b.options, b.model)
            and np.array_equal(m1["total"], m2["total"]) and m1["relative_drift"] == m2["relative_drift"]
            and m1["blow_up"] == m2["blow_up"])


@pytest.mark.parametrize("engine", ["netcdf4", "h5netcdf"])
def test_no_single_flipped_byte_loads_other_values(tmp_path, engine):
    """Catches a result file without checksums (the audit: 250 of 400 flipped bytes loaded other values)
    and a check that misses a part of the file (data, attributes, dimensions, the text variables)."""
    res = _result()
    path = res.save(tmp_path / "good.nc", engine=engine)
    data = path.read_bytes()
    assert _same(Result.load(path), res)
    rng = np.random.default_rng(23)
    # the arrays' bytes (found by their values) and a sample of the whole file
    q_at = data.find(res.q.tobytes()[:16])
    assert q_at > 0
    offsets = set(rng.integers(0, len(data), N_FLIPS - 40).tolist()) | set(range(q_at, q_at + 40))
    outcome = {"error": 0, "identical": 0}
    bad = tmp_path / "bad.nc"
    for k in sorted(offsets):
        damaged = bytearray(data)
        damaged[k] ^= 1 << int(rng.integers(8))
        bad.write_bytes(bytes(damaged))
        try:
            back = Result.load(bad)
        except ResultFileError as exc:
            assert "bad.nc" in str(exc)
            outcome["error"] += 1
            continue
        assert _same(back, res), f"a flipped bit at offset {k} of {len(data)} loaded different values"
        outcome["identical"] += 1
    assert outcome["error"] >= 40            # at least every flip inside q's data is detected


def test_a_flip_in_the_coordinate_labels_is_an_error(tmp_path):
    """Catches text variables left out of the checksums (HDF5 filters skip variable-length strings; a
    random sample of offsets rarely hits the few bytes of the labels: mutation-checked)."""
    res = _result()
    path = res.save(tmp_path / "run.nc")
    data = path.read_bytes()
    hits = [k for k in range(len(data) - 1) if data[k:k + 2] == b"y'"]
    assert hits
    for k in hits:
        damaged = bytearray(data)
        damaged[k + 1] = ord('"')                         # y' -> y"
        path.write_bytes(bytes(damaged))
        try:
            back = Result.load(path)
        except ResultFileError:
            continue
        assert _same(back, res), f"a changed label at offset {k} loaded"


def test_a_flip_inside_the_data_names_the_variable(tmp_path):
    res = _result()
    path = res.save(tmp_path / "run.nc")
    data = bytearray(path.read_bytes())
    at = bytes(data).find(res.v.tobytes()[:16])
    data[at + 3] ^= 0x10
    path.write_bytes(bytes(data))
    with pytest.raises(ResultFileError, match=r"run.nc: damaged ancfdae result file: variable 'v' cannot be read"):
        Result.load(path)


def test_a_dimension_cut_against_the_beam_description_is_an_error(tmp_path):
    """Catches the audit's file whose dof dimension was cut to 5 of the beam's 9 coordinates and loaded."""
    path = _result().save(tmp_path / "run.nc")
    with xr.open_dataset(path) as ds:
        ds.load()
    cut = ds.isel(dof=slice(0, 5))
    cut.to_netcdf(tmp_path / "cut.nc", encoding=_filecheck.encoding(cut))
    with pytest.raises(ResultFileError, match="cut.nc.*variable 'a' does not match its stored checksum"):
        Result.load(tmp_path / "cut.nc")
    cut.attrs[_filecheck.CHECKSUM_ATTR] = json.dumps(_filecheck.checksums(cut))     # a consistent forgery
    cut.to_netcdf(tmp_path / "cut2.nc", encoding=_filecheck.encoding(cut))
    with pytest.raises(ResultFileError, match="cut2.nc.*'q' has 5 coordinates.*n_dof = 9"):
        Result.load(tmp_path / "cut2.nc")


def test_a_file_without_checksums_claiming_the_new_format_is_an_error(tmp_path):
    path = _result().save(tmp_path / "run.nc")
    with xr.open_dataset(path) as ds:
        ds.load()
    plain = ds.copy()
    del plain.attrs[_filecheck.CHECKSUM_ATTR]
    plain.to_netcdf(tmp_path / "plain.nc")
    with pytest.raises(ResultFileError, match="plain.nc.*attribute 'checksums'.*is missing"):
        Result.load(tmp_path / "plain.nc")
    ds.to_netcdf(tmp_path / "nofilter.nc", encoding={k: {"fletcher32": False} for k in ds.data_vars})
    with pytest.raises(ResultFileError, match="nofilter.nc.*carries no Fletcher-32 checksum"):
        Result.load(tmp_path / "nofilter.nc")


def test_save_is_atomic_and_names_a_missing_folder(tmp_path):
    res = _result()
    with pytest.raises(ValueError, match=r"`path` must be in an existing folder.*nowhere.*does not exist"):
        res.save(tmp_path / "nowhere" / "run.nc")
    path = res.save(tmp_path / "run.nc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]        # no temporary file left
    assert _same(Result.load(res.save(path)), res)                          # over an existing file
    (tmp_path / "folder.nc").mkdir()
    with pytest.raises(ValueError, match="folder.nc.*which is a folder"):
        res.save(tmp_path / "folder.nc")
    assert _same(Result.load(path), res)
