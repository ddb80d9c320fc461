"""The flying3d study (B3, chapter Sect. 5.3) in quick mode: SQ3D keeps its energy, BE3D's director update does not."""
import numpy as np
import pytest

from ancfdae.studies import flying3d
from conftest import check_panel, saved_figures, series, visible_axes


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("flying3d")
    with saved_figures() as figs:
        res = flying3d.run(quick=True, out=out, jobs=2, progress=False)
    return dict(res, figures=figs)


def _rows(quick, element):
    return sorted((r for r in quick["rows"] if r["element"] == element), key=lambda r: -r["h"])


def test_sq3d_energy_balance_holds_after_the_load_to_the_integrators_accuracy(quick):
    coarse, fine = _rows(quick, "SQ3D")
    assert (coarse["h"], fine["h"]) == (4e-3, 2e-3)
    for r in (coarse, fine):
        assert r["status"] == "success" and r["t_blow_up"] is None
    energy = fine["energy_at_load_end"]
    # regression value: the energy put in by the B3 load, measured with this code (SQ3D 2 el, h = 2e-3)
    assert energy == pytest.approx(5.628, rel=1e-3)
    # free flight after the load: drift 1.0e-6 J of 5.6 J at h = 2e-3
    assert fine["drift_max"] < 1e-6 * energy
    # the balance error is Lobatto IIIA's own: order 4 in h (measured 4.03 at the load end, 3.8 after it)
    p_load = np.log2(abs(coarse["balance_at_load_end"]) / abs(fine["balance_at_load_end"]))
    p_free = np.log2(coarse["drift_max"] / fine["drift_max"])
    assert 3.5 < p_load < 4.5
    assert 3.0 < p_free < 4.5


def test_be3d_energy_error_is_the_director_update(quick):
    (be,) = _rows(quick, "BE3D")
    (sq,) = [r for r in _rows(quick, "SQ3D") if r["h"] == be["h"]]
    assert be["director_update"] == "projected"
    # BE3D's balance is off by 3 % of the energy put in, 4 orders of magnitude more than SQ3D's ...
    assert abs(be["balance_at_load_end"]) > 1e4 * abs(sq["balance_at_load_end"])
    # ... and the jumps of T + U at the director updates account for it (0.173 of 0.176 J)
    assert be["update_net_load"] == pytest.approx(be["balance_at_load_end"], rel=0.05)
    assert be["drift_max"] > 1e5 * sq["drift_max"]


def test_quick_mode_writes_figures(quick):
    md = (quick["path"] / "flying3d.md").read_text()
    assert md.count("| SQ3D |") == 2 and md.count("| BE3D |") == 1
    figs = quick["figures"]
    # Fig. 11: T + U of every run over the whole time span, settling at the table's energy after the
    # load (SQ3D); the balance error on a log scale, SQ3D's far below BE3D's.
    energy, balance = visible_axes(figs["fig11_energy.png"])
    check_panel(energy, min_lines=3)
    check_panel(balance, min_lines=3)
    assert balance.get_yscale() == "log"
    for r in quick["rows"]:
        label = next(k for k in series(energy) if k.startswith(f"{r['element']} {r['n']} el")
                     and f"h {r['h']:g}" in k)
        t, total = series(energy)[label]
        assert t[0] == 0.0 and t[-1] == pytest.approx(r["t_end_reached"])
        if r["element"] == "SQ3D":
            assert total[-1] == pytest.approx(r["energy_at_load_end"], rel=1e-3)
        _, err = series(balance)[label]
        at_load = np.argmin(np.abs(t - r["t_load"]))
        assert err[at_load] == pytest.approx(abs(r["balance_at_load_end"]), rel=1e-6, abs=1e-15)
    # Fig. 12: u_x, u_y, u_z of B for each element type, starting at zero.
    panels = visible_axes(figs["fig12_displacement.png"])
    assert len(panels) == 3 * 2
    for ax in panels:
        assert ax.get_ylabel() in ("u_x (m)", "u_y (m)", "u_z (m)")
        for t, u in series(ax).values():
            assert t[0] == 0.0 and t[-1] == pytest.approx(1.5) and u[0] == 0.0 and np.all(np.isfinite(u))
    moving = [np.abs(u).max() for ax in panels for _, u in series(ax).values()]
    assert max(moving) > 0.1                              # the beam flies: B moves by decimetres
