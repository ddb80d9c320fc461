"""The flying3d study (B3 revision 2, chapter Sect. 5.3), quick: SQ3D keeps its energy, BE3D's director update not."""
import numpy as np
import pytest

from ancfdae.studies import flying3d


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("flying3d")
    return flying3d.run(quick=True, out=out, jobs=2, progress=False)


def _rows(quick, element, method="lobatto3"):
    return sorted((r for r in quick["rows"] if r["element"] == element and r["method"] == method),
                  key=lambda r: -r["h"])


def test_sq3d_energy_balance_holds_after_the_load_to_the_integrators_accuracy(quick):
    coarse, fine = _rows(quick, "SQ3D")
    assert (coarse["h"], fine["h"]) == (4e-3, 2e-3)
    for r in (coarse, fine):
        assert r["status"] == "success" and r["t_blow_up"] is None
    energy = fine["energy_at_load_end"]
    assert energy == pytest.approx(0.5777, rel=1e-3)           # revision 2: moment (0.1, 0.05, 0.2) N m
    # free flight after the load: drift 1.2e-10 J of 0.58 J at h = 2e-3
    assert fine["drift_max"] < 1e-8 * energy
    # the balance error is Lobatto IIIA's own: order 4 in h (measured 4.06 at the load end, 4.7 after it)
    p_load = np.log2(abs(coarse["balance_at_load_end"]) / abs(fine["balance_at_load_end"]))
    p_free = np.log2(coarse["drift_max"] / fine["drift_max"])
    assert 3.5 < p_load < 4.5
    assert 3.0 < p_free < 5.5


def test_sq3d_energy_momentum_balance_exact_after_the_load(quick):
    """SQ3D with the energy-momentum method (constant mass): after the load the balance stays at round-off.

    Catches: the study running it with the Lobatto IIIA Newton tolerance 1e-8 (drift ~1e-9 J), or not at all.
    """
    (em,) = _rows(quick, "SQ3D", "energy-momentum")
    (lob,) = [r for r in _rows(quick, "SQ3D") if r["h"] == em["h"]]
    assert (em["n"], em["h"], em["status"]) == (2, 4e-3, "success")
    energy = em["energy_at_load_end"]
    assert energy == pytest.approx(lob["energy_at_load_end"], rel=1e-3)
    assert em["drift_max"] < 1e-12 * energy
    assert em["drift_max"] < 1e-2 * lob["drift_max"]


def test_be3d_energy_error_is_the_director_update(quick):
    """Catches: a stale acceleration after the updates (the step part was 5 % of the balance), an audit that
    misses updates, a study that stops splitting the balance."""
    (be,) = _rows(quick, "BE3D")
    (sq,) = [r for r in _rows(quick, "SQ3D") if r["h"] == be["h"]]
    assert be["director_update"] == "projected" and be["method"] == "lobatto3"
    # BE3D's balance is off by 2 % of the energy put in, 6 orders of magnitude more than SQ3D's ...
    assert abs(be["balance_at_load_end"]) > 1e5 * abs(sq["balance_at_load_end"])
    # ... and the jumps of T + U at the director updates account for it: 1.11e-2 J of 1.11e-2 J, the step
    # part (Lobatto IIIA's own error) -1.4e-12 J during the load and -4.2e-11 J after it
    assert abs(be["step_part_load"]) < 1e-9 and abs(be["step_part_free"]) < 1e-9
    assert be["update_net_load"] == pytest.approx(be["balance_at_load_end"], rel=1e-6)
    assert be["update_count"] == 750                         # one update per step (1.5 s at h = 2e-3)
    assert be["update_mean"] == pytest.approx((be["update_net_load"] + be["update_net_free"]) / 750)
    assert be["drift_max"] > 1e5 * sq["drift_max"]


def test_be3dsr_keeps_its_energy_and_the_geometry_is_logged(quick):
    """BE3DSR (transported frames) conserves energy like SQ3D; the director geometry is logged for BE3D.

    Catches: BE3DSR missing from the study, a BE3D run without the geometry monitor.
    """
    (sr,) = _rows(quick, "BE3DSR")
    (be,) = _rows(quick, "BE3D")
    assert sr["status"] == "success" and sr["update_below"] == 0.5
    assert abs(sr["balance_at_load_end"]) < 1e-9 and sr["drift_max"] < 1e-9     # -1.3e-10 J, 1.0e-10 J
    assert 30 < be["max_angle"] < 50 and 0.9 < be["min_projection"] < 0.95          # 40.4 deg, 0.938
    assert be["eps_T"] > 1e-3 and sr["eps_T"] > 1e-3         # 2 thin elements against 2 SQ3D: 1.3e-2, 1.1e-2 m


def test_quick_mode_writes_table_and_figures(quick):
    md = (quick["path"] / "flying3d.md").read_text()
    assert md.count("| SQ3D |") == 3 and md.count("| BE3D |") == 1 and md.count("| energy-momentum |") == 1
    assert md.count("| BE3DSR |") == 1 and (quick["path"] / "mechanism.png").is_file()
    for stem in ("fig11_energy", "fig12_displacement"):
        assert (quick["path"] / f"{stem}.png").is_file() and (quick["path"] / f"{stem}.svg").is_file()
    energy_ax = quick["figures"]["fig11_energy"].axes[0]
    labels = [ln.get_label() for ln in energy_ax.get_lines()]
    assert sum(lab.startswith("SQ3D 2 el") for lab in labels) == 3
    assert sum("energy-momentum" in lab for lab in labels) == 1
    assert sum(lab.startswith("BE3D ") for lab in labels) == 1 and sum(lab.startswith("BE3DSR") for lab in labels) == 1
    # the displacement figure: one column per type, u_x, u_y, u_z rows
    assert len(quick["figures"]["fig12_displacement"].axes) == 9


def test_chapter_failure_times_in_the_full_table():
    assert flying3d.CHAPTER_FAILURES == {8: 8.0, 16: 9.0, 32: 12.0}
    assert flying3d.FULL["be_meshes"] == (8, 16, 32) and flying3d.FULL["sq_meshes"] == (32, 64, 128)


def test_options_documented_as_none_by_zero_accept_zero():
    """``--sr-meshes 0``, ``--be-steps 0``, ``--update-below 0`` mean "none" (the CLI help says so).

    Catches the option check rejecting the zero that the help offers (it did: "must be positive").
    """
    out = flying3d.run(quick=True, be_meshes=(2,), sq_meshes=(), em_run=(0, 0), sr_meshes=(0,), be_steps=(0,),
                       update_below=(0,), t_end=0.02, plots=False, progress=False)
    assert [(r["element"], r["n"]) for r in out["rows"]] == [("BE3D", 2)]
