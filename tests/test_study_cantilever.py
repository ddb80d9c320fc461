"""The cantilever study (B1) in quick mode, and the command line."""
import numpy as np
import pytest

from ancfdae.cli import main
from ancfdae.studies import cantilever


def test_quick_study_reproduces_table2_be2d(tmp_path):
    res = cantilever.run(elements=["BE2D"], quick=True, out=tmp_path, progress=False)
    rows = {r["n_elements"]: r for r in res["rows"]}
    assert sorted(rows) == [1, 2, 4, 8, 16]
    for n in (2, 4, 8, 16):
        assert rows[n]["error"] == pytest.approx(cantilever.TABLE2["BE2D"][n][1], rel=5e-3)
        assert rows[n]["dof"] == cantilever.TABLE2["BE2D"][n][0]
        assert rows[n]["iterations"] == 49
    assert 4.0 < res["orders"]["BE2D"] < 6.0
    assert (tmp_path / "table2.md").read_text().count("| BE2D |") == 5
    assert (tmp_path / "fig5_convergence.png").stat().st_size > 10_000
    assert (tmp_path / "fig6_performance.png").stat().st_size > 10_000


def test_study_rejects_unknown_element():
    with pytest.raises(ValueError, match="elements"):
        cantilever.run(elements=["XYZ"], quick=True, plots=False, progress=False)


def test_cli_lists_and_runs(tmp_path, capsys):
    assert main(["studies"]) == 0
    assert "cantilever" in capsys.readouterr().out
    assert main(["study", "cantilever", "--quick", "--out", str(tmp_path)]) == 0
    assert "| BE2D | 16 |" in capsys.readouterr().out
    with pytest.raises(SystemExit, match="unknown study"):
        main(["study", "nope"])
