"""The flying2d study (B2 revision 2, chapter Sect. 5.2) in quick mode: eps_T of Eq. 115 over [0, 10] s at order 4."""
import numpy as np
import pytest

from ancfdae.studies import flying2d
from ancfdae.studies._flying import eps_T, output_times, regress_order


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("flying2d")
    return flying2d.run(quick=True, out=out, jobs=2, progress=False)


def test_be2d_converges_at_order_4_over_the_whole_span(quick):
    """Catches a chaotic benchmark (revision 1: order 0.5-0.8 over [0, 10] s) or a wrong reference/eps_T."""
    rows = sorted((r for r in quick["rows"] if r["element"] == "BE2D"), key=lambda r: r["n"])
    assert [r["n"] for r in rows] == [4, 8, 16]
    assert all(r["status"] == "success" and r["t_reached"] == pytest.approx(10.0) for r in rows)
    assert quick["orders"]["BE2D"] >= 3.5                   # measured 4.22 (4, 8, 16 against 32)
    eps = {r["n"]: r["eps_T"] for r in rows}
    # measured against 32 elements; against 128 (the full study) 7.30e-2, 4.27e-3, 2.21e-4
    assert eps[4] == pytest.approx(7.296e-2, rel=1e-2)
    assert eps[8] == pytest.approx(4.260e-3, rel=1e-2)
    assert eps[16] == pytest.approx(2.087e-4, rel=2e-2)


def test_energy_is_kept_after_the_pulse_and_work_is_counted(quick):
    for r in quick["rows"]:
        assert r["steps"] == 10_000                          # 10 s at h = 1e-3
        assert r["newton_iterations"] >= r["steps"]
        assert 1 <= r["factorizations"] <= r["jacobian_evals"]
        assert r["drift"] < 1e-9 * r["energy"]               # measured 1.6e-11 .. 3.9e-11 J of 0.53 J
    assert set(quick["references"]) == {"BE"}


def test_outputs_table_and_figures(quick):
    md = (quick["path"] / "flying2d.md").read_text()
    assert md.count("| BE2D |") == 4 and "reference" in md
    for stem in ("fig8_convergence", "fig9_performance", "b2_tip_energy"):
        assert (quick["path"] / f"{stem}.png").is_file() and (quick["path"] / f"{stem}.svg").is_file()
    left, right = quick["figures"]["fig8_convergence"].axes[:2]
    lines = {ln.get_label(): ln for ln in left.get_lines()}
    assert list(lines["BE2D"].get_xdata()) == [4, 8, 16]
    np.testing.assert_allclose(lines["BE2D"].get_ydata(), [r["eps_T"] for r in quick["rows"]], rtol=1e-12)
    guide = [k for k in lines if "fitted order" in k]
    assert guide == [f"BE2D fitted order {quick['orders']['BE2D']:.2f} (x 0.5)"]   # the fitted value, not "4"
    assert left.get_xscale() == "log" and left.get_yscale() == "log"
    assert [ln.get_label() for ln in right.get_lines()] == ["BE2D"]


def test_rerun_reuses_the_stored_cases(quick):
    again = flying2d.run(quick=True, out=quick["path"], progress=False)
    assert again["reused"] == 4                              # 3 meshes + the reference, nothing recomputed
    assert [r["eps_T"] for r in again["rows"]] == [r["eps_T"] for r in quick["rows"]]


def test_eps_T_is_eq_115():
    t = np.linspace(0.0, 2.0, 201)
    ref = np.zeros((t.size, 2))
    tip = np.column_stack([np.full(t.size, 0.3), np.full(t.size, 0.4)])    # |u_ref - u| = 0.5
    assert eps_T(t, tip, t, ref) == pytest.approx(0.5 * np.sqrt(2.0), rel=1e-12)
    assert eps_T(t[::2], tip[::2], t, ref) == pytest.approx(0.5 * np.sqrt(2.0), rel=1e-12)
    with pytest.raises(ValueError, match="reference"):
        eps_T(t + 0.005, tip, t, ref)
    assert regress_order([2, 4, 8], [1.0, 1 / 16, 1 / 256]) == pytest.approx(4.0)


def test_output_times_never_pass_the_end():
    """140 * 0.01 > 1.4 in floating point: the integrators rejected that output time."""
    t = output_times(1.4, 0.01)
    assert t[-1] == 1.4 and t.size == 141 and np.all(np.diff(t) > 0)
    t = output_times(1.45, 0.02)
    assert t[-1] == 1.45 and t[-2] == pytest.approx(1.44)
    with pytest.raises(ValueError, match="dt_out"):
        output_times(1.0, 0.0)


def test_rejects_unknown_element():
    with pytest.raises(ValueError, match="elements"):
        flying2d.run(elements=["XYZ"], quick=True, plots=False, progress=False)
