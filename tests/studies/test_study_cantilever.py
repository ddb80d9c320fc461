"""The cantilever study (B1) in quick mode, and the command line."""
import numpy as np
import pytest

from ancfdae.cli import main
from ancfdae.studies import cantilever


def test_quick_study_reproduces_table2_be2d(tmp_path):
    res = cantilever.run(elements=["BE2D", "BE3D"], quick=True, out=tmp_path, progress=False)
    rows = {(r["element"], r["n_elements"]): r for r in res["rows"]}
    assert sorted(n for e, n in rows if e == "BE2D") == [1, 2, 4, 8, 16]
    for n in (2, 4, 8, 16):
        assert rows["BE2D", n]["error"] == pytest.approx(cantilever.TABLE2["BE2D"][n][1], rel=5e-3)
        assert rows["BE2D", n]["dof"] == cantilever.TABLE2["BE2D"][n][0]
        assert rows["BE2D", n]["iterations"] == 49
    assert 4.0 < res["orders"]["BE2D"] < 6.0
    assert (tmp_path / "table2.md").read_text().count("| BE2D |") == 5
    for stem in ("fig5_convergence", "fig6_performance"):
        assert (tmp_path / f"{stem}.png").is_file() and (tmp_path / f"{stem}.svg").is_file()
    # Fig. 5: ours beside the chapter's Table 2; the 3D twin drawn open and larger, visible on its 2D twin
    ax = res["figures"]["fig5_convergence"].axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    chapter = lines["chapter Table 2, BE2D (= BE3D)"]
    np.testing.assert_allclose(chapter.get_ydata(), [cantilever.TABLE2["BE2D"][n][1] for n in sorted(
        cantilever.TABLE2["BE2D"])])
    assert lines["BE3D"].get_markersize() > lines["BE2D"].get_markersize()
    assert lines["BE3D"].get_markerfacecolor() == "none"
    assert f"BE2D fitted order {res['orders']['BE2D']:.2f} (x 0.5)" in lines
    # Fig. 6: the legend sits outside the axes (it covered points inside them)
    fig6 = res["figures"]["fig6_performance"]
    assert fig6.legends and not fig6.axes[0].get_legend()
    assert res["reused"] == 0 and cantilever.run(elements=["BE2D", "BE3D"], quick=True, out=tmp_path,
                                                progress=False)["reused"] == 10


def test_study_rejects_unknown_element():
    with pytest.raises(ValueError, match="elements"):
        cantilever.run(elements=["XYZ"], quick=True, plots=False, progress=False)


def test_cli_lists_and_runs(tmp_path, capsys):
    assert main(["studies"]) == 0
    assert "cantilever" in capsys.readouterr().out
    assert main(["study", "cantilever", "--quick", "--elements", "BE2D", "--n-elements", "2", "4",
                 "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "| BE2D | 4 |" in out and "| BE2D | 8 |" not in out
    with pytest.raises(SystemExit, match="unknown study"):
        main(["study", "nope"])
    # a bad option is a usage error, said at once in one line: exit status 2
    assert main(["study", "cantilever", "--elements", "XYZ"]) == 2
    assert "`elements` must name types" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:
        main(["study", "cantilever", "--help"])
    assert exc.value.code == 0
    assert "(default: 1 2 4 8 16 32 64; with --quick: 1 2 4 8 16)" in " ".join(capsys.readouterr().out.split())
