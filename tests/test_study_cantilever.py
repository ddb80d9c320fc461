"""The cantilever study (B1) in quick mode, and the command line."""
import numpy as np
import pytest

from ancfdae.cli import main
from ancfdae.studies import cantilever
from conftest import check_panel, saved_figures, series, visible_axes


def test_quick_study_reproduces_table2_be2d(tmp_path):
    with saved_figures() as figs:
        res = cantilever.run(elements=["BE2D"], quick=True, out=tmp_path, progress=False)
    rows = {r["n_elements"]: r for r in res["rows"]}
    assert sorted(rows) == [1, 2, 4, 8, 16]
    for n in (2, 4, 8, 16):
        assert rows[n]["error"] == pytest.approx(cantilever.TABLE2["BE2D"][n][1], rel=5e-3)
        assert rows[n]["dof"] == cantilever.TABLE2["BE2D"][n][0]
        assert rows[n]["iterations"] == 49
    assert 4.0 < res["orders"]["BE2D"] < 6.0
    assert (tmp_path / "table2.md").read_text().count("| BE2D |") == 5
    # The figures show the rows: Fig. 5 error against elements and DOF, Fig. 6 CPU time against error.
    assert {"fig5_convergence.png", "fig6_performance.png"} <= set(figs)
    by_elements, by_dof = visible_axes(figs["fig5_convergence.png"])
    ordered = [rows[n] for n in sorted(rows)]
    errors = [r["error"] for r in ordered]
    for ax, key in ((by_elements, "n_elements"), (by_dof, "dof")):
        check_panel(ax)
        assert ax.get_xscale() == ax.get_yscale() == "log"
        x, y = series(ax)["BE2D"]
        assert np.array_equal(x, [r[key] for r in ordered]) and np.array_equal(y, errors)
    (perf,) = visible_axes(figs["fig6_performance.png"])
    check_panel(perf)
    x, y = series(perf)["BE2D"]
    assert np.array_equal(x, errors) and np.array_equal(y, [r["cpu"] for r in ordered]) and np.all(y > 0)


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
