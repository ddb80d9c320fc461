"""The energy study in quick mode: drift after the load for each integrator."""
import pytest

from ancfdae.studies import energy


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    out = tmp_path_factory.mktemp("energy")
    return energy.run(quick=True, out=out, jobs=2, progress=False)


def test_drift_after_the_load_per_integrator(quick):
    rows = {r["integrator"]: r for r in quick["rows"]}
    assert set(rows) == set(energy.INTEGRATORS)
    for r in rows.values():
        assert r["status"] == "success" and r["t_blow_up"] is None and r["t_reached"] == pytest.approx(4.0)
        assert r["energy"] == pytest.approx(0.5817, rel=2e-3)      # B2 revision 2 (0.24 N, 0.24 N m)
    # Lobatto IIIA (order 4) keeps the energy to 2e-9 relative; the order-2 methods to 3e-5 .. 7e-5
    assert rows["lobatto3"]["relative"] < 1e-6
    assert rows["lobatto3"]["drift"] < 1e-2 * min(rows[m]["drift"] for m in ("lobatto2", "hht", "generalized-alpha"))
    assert rows["newmark"]["drift"] == pytest.approx(rows["lobatto2"]["drift"], rel=1e-3)   # the same scheme
    for m in ("lobatto2", "hht", "generalized-alpha"):
        assert 1e-5 < rows[m]["relative"] < 1e-2
    assert rows["ida"]["relative"] < 1e-4


def test_writes_table_and_figure(quick):
    md = (quick["path"] / "energy.md").read_text()
    assert md.count("| BE2D 2 el |") == len(energy.INTEGRATORS)
    assert (quick["path"] / "energy_drift.png").is_file() and (quick["path"] / "energy_drift.svg").is_file()
    (ax,) = [a for a in quick["figures"]["energy_drift"].axes if a.get_visible()]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    assert set(lines) == set(energy.INTEGRATORS) and ax.get_yscale() == "log"
    # Newmark and Lobatto IIIA-2 draw the same curve: different line styles keep both visible
    assert lines["newmark"].get_linestyle() != lines["lobatto2"].get_linestyle()


def test_rejects_unknown_integrator():
    with pytest.raises(ValueError, match="integrators"):
        energy.run(integrators=["euler"], quick=True, plots=False, progress=False)
