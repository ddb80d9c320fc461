"""A user's error gets one line naming the argument: no traceback, no blame on the wrong file, no exit 0."""
import importlib

import numpy as np
import pytest

from ancfdae import Gravity, Material, RectangularSection, constant, simulate
from ancfdae.cli import main
from ancfdae.models import BE2D, Beam
from ancfdae.studies import _cli
from support import study_toy


@pytest.fixture(scope="module")
def run_file(tmp_path_factory):
    """A short BE2D run saved with its beam description (what export and animate read)."""
    beam = Beam(BE2D(Material(E=1e6, nu=0.3, rho=1000.0), RectangularSection(0.1)), 2, 1.0,
                supports={0: "clamp"}, loads=[Gravity((0.0, -9.81))])
    res = simulate(beam, (0.0, 0.01), h=0.005)
    assert res.success, res.message
    return res.save(tmp_path_factory.mktemp("cli") / "run.nc")


def _exit_text(argv):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code not in (0, None)
    return str(info.value.code)


def test_export_and_animate_name_the_bad_output_argument(run_file, tmp_path):
    """Catches the audit's raw tracebacks (FileExistsError, FileNotFoundError) and messages blaming the
    input file ("run.nc: unknown file extension") for a bad output path."""
    (tmp_path / "afile").touch()
    cases = [(["export", "vtk", str(run_file), str(tmp_path / "afile")], "`directory` must be a folder"),
             (["export", "vtk", str(run_file), str(tmp_path), "--name", "a/b"], "`name` must be a plain file name"),
             (["export", "vtk", str(run_file), str(tmp_path), "--name", ""], "`name` must be a plain file name"),
             (["animate", str(run_file), str(tmp_path)], "`path` must end in .gif"),
             (["animate", str(run_file), str(tmp_path / "x.txt")], "`path` must end in .gif"),
             (["animate", str(run_file), str(tmp_path / "no" / "x.gif")], "the folder"),
             (["export", "vtk", str(tmp_path / "missing.nc"), str(tmp_path)], "missing.nc: no such result file")]
    for argv, words in cases:
        text = _exit_text(argv)
        assert words in text and "Traceback" not in text, (argv, text)
        assert "run.nc" not in text, text              # the input file is not blamed for the output's fault


def test_a_positive_integer_option_names_the_text_given(run_file, tmp_path, capsys):
    with pytest.raises(SystemExit):
        main(["export", "vtk", str(run_file), str(tmp_path), "--every", "x"])
    assert "must be a positive integer, got 'x'" in capsys.readouterr().err


STUDIES = {"cantilever": [["--n-elements", "0"], ["--repeats", "0"], ["--n-elements", "2", "-1"]],
           "energy": [["--n", "0"], ["--h", "-1"], ["--t-end-b2", "0"]],
           "flying2d": [["--n-elements", "0"], ["--n-ref", "-2"], ["--h", "0"], ["--t-end", "nan"]],
           "flying3d": [["--be-meshes", "0"], ["--t-end", "-1"], ["--h", "0"]],
           "integrators": [["--steps", "0"], ["--n", "0"], ["--t-end", "-1"], ["--rtols", "-0.5"]]}


@pytest.mark.parametrize("name", sorted(STUDIES))
def test_each_study_refuses_a_zero_or_negative_size_before_any_work(name, tmp_path, capsys):
    """Catches the audit's studies that printed per-case errors, empty tables, "results written" and exit 0
    (--repeats 0: UnboundLocalError in every case; --steps 0: ZeroDivisionError)."""
    study = importlib.import_module(f"ancfdae.studies.{name}")
    for args in STUDIES[name]:
        out = tmp_path / "out"
        code = _cli.main(study, ["--quick", "--out", str(out), *args])
        err = capsys.readouterr().err.strip()
        option = args[0][2:].replace("-", "_")
        assert code == 2 and f"`{option}` ({args[0]}) must be" in err and len(err.splitlines()) == 1, (args, err)
        assert not out.exists()                       # refused before the output folder was made


def test_jobs_is_accepted_by_every_study_and_more_than_one_refused_with_the_reason(capsys):
    """Catches `--jobs` refused by cantilever although the README's synopsis lists it."""
    cantilever = importlib.import_module("ancfdae.studies.cantilever")
    assert _cli.main(cantilever, ["--jobs", "1", "--repeats", "0"]) == 2          # --jobs 1 parsed
    assert "`repeats`" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        _cli.main(cantilever, ["--jobs", "2"])
    assert "--jobs must be 1 for this study, got 2: it runs its cases serially" in capsys.readouterr().err


def test_a_study_with_a_failed_case_exits_1(tmp_path, capsys):
    assert _cli.main(study_toy, ["--out", str(tmp_path), "--fail", "1"]) == 1
    assert "1 case(s) failed: case 1" in capsys.readouterr().err
    assert _cli.main(study_toy, ["--out", str(tmp_path)]) == 0


def test_times_given_as_text_are_refused_naming_the_argument():
    """Catches float("1") accepting text times silently (t_span "01" ran over [0, 1])."""
    beam = Beam(BE2D(Material(E=1e6, nu=0.3, rho=1000.0), RectangularSection(0.1)), 2, 1.0, supports={0: "clamp"})
    with pytest.raises(ValueError, match="`t_span` must be a pair"):
        simulate(beam, ("0", "0.01"), h=0.005)
    with pytest.raises(ValueError, match="`t_span` must be a pair"):
        simulate(beam, "01", h=0.005)
    with pytest.raises(ValueError, match="`t_eval` must be an array of numbers, got text"):
        simulate(beam, (0.0, 0.01), h=0.005, t_eval=["0", "0.01"])
    with pytest.raises(ValueError, match="`value` must be a finite real number, got '1'"):
        constant("1")
    with pytest.raises(ValueError, match="`q0` must be an array of numbers, got text"):
        simulate(beam, (0.0, 0.01), h=0.005, q0=np.array(["1"] * beam.n_dof))
