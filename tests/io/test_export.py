"""ParaView export: files read back with meshio match the beam's kinematics."""
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from ancfdae import Material, PointForce, RectangularSection, CircularSection, Result, simulate
from ancfdae.export import beam_of, vtk
from ancfdae.models import BE2D, BE3D, SQ2D, SQ3D, Beam, Cable3D

SOFT = Material(E=1e6, nu=0.3, rho=1000.0)


def _run(element, force, t_end=0.02):
    beam = Beam(element, 3, 1.0, supports={0: "clamp"}, loads=[PointForce(force, node=-1)])
    res = simulate(beam, (0, t_end), "lobatto3", h=0.005)
    assert res.success, res.message
    if element.name == "BE3D":    # the driver records the nodal directors at every output
        assert res.model_state["directors"].shape == (res.t.size, beam.n_nodes, 3)
    return beam, res


CASES = [
    (lambda: BE2D(SOFT, RectangularSection(0.1)), [0.0, -50.0]),
    (lambda: SQ2D(SOFT, RectangularSection(0.1)), [0.0, -50.0]),
    (lambda: Cable3D(SOFT, CircularSection(0.1)), [0.0, -20.0, 30.0]),
    (lambda: BE3D(SOFT, RectangularSection(0.1, 0.05)), [0.0, -20.0, 30.0]),
    (lambda: SQ3D(SOFT, RectangularSection(0.1), formulation="continuum"), [0.0, -20.0, 30.0]),
]


@pytest.mark.parametrize("make, force", CASES, ids=["BE2D", "SQ2D", "Cable3D", "BE3D", "SQ3D"])
def test_vtk_reads_back_and_matches_the_beam(tmp_path, make, force):
    el = make()
    beam, res = _run(el, force)
    pvd = vtk(res, beam, tmp_path / "out")
    entries = ET.parse(pvd).getroot().findall("./Collection/DataSet")
    assert [float(e.get("timestep")) for e in entries] == res.t.tolist()
    n_outline = 4 if isinstance(el.section, RectangularSection) else 16
    stride = 1 + n_outline
    for i, entry in enumerate(entries):
        mesh = meshio.read(pvd.parent / entry.get("file"))
        axis = mesh.points[::stride]
        r = beam.position(res.q[i], beam.s_nodes)          # the nodes, from the element's interpolation
        np.testing.assert_allclose(axis[:, :el.dim], r, rtol=0, atol=1e-12)
        # the velocity of an axis point is exact: positions are affine in q (chapter Eq. 54)
        v_axis = beam.position(res.q[i] + res.v[i], beam.s_nodes) - r
        np.testing.assert_allclose(mesh.point_data["velocity"][::stride, :el.dim], v_axis, rtol=0,
                                   atol=1e-7 * max(np.abs(v_axis).max(), 1e-3))
        assert mesh.cells[0].type == "wedge" and mesh.cells[0].data.shape == ((beam.n_nodes - 1) * n_outline, 6)
        if i == 0:   # the initial state is the reference: every drawn point (section too) undisplaced
            np.testing.assert_allclose(mesh.point_data["displacement"], 0.0, atol=1e-12)
    last = meshio.read(pvd.parent / entries[-1].get("file"))
    assert np.abs(last.point_data["displacement"]).max() > 1e-4    # the load moved it


def test_sections_follow_the_element_kinematics(tmp_path):
    """SQ3D draws r + eta r_eta + zeta r_zeta (its cross-section deformation), BE3D its rotated frame."""
    beam, res = _run(SQ3D(SOFT, RectangularSection(0.1), formulation="continuum"), [0.0, -4e2, 6e2])
    pvd = vtk(res, beam, tmp_path / "sq")
    mesh = meshio.read(pvd.parent / f"beam_{res.t.size - 1:06d}.vtu")
    Q = beam.nodal(res.q[-1])
    corner = Q[:, :3] + 0.05 * Q[:, 3:6] - 0.05 * Q[:, 6:9]      # outline point (eta, zeta) = (h/2, -b/2)
    np.testing.assert_allclose(mesh.points[2::5], corner, atol=1e-12)
    assert np.abs(mesh.point_data["section_stretch_eta"]).max() > 0    # a deformable section

    beam, res = _run(BE3D(SOFT, RectangularSection(0.1, 0.05)), [0.0, -20.0, 30.0])
    pvd = vtk(res, beam, tmp_path / "be3d")
    mesh = meshio.read(pvd.parent / f"beam_{res.t.size - 1:06d}.vtu")
    P = mesh.points.reshape(beam.n_nodes, 5, 3)
    e2 = (P[:, 2] - P[:, 1]) / 0.1            # corners (h/2, -b/2) - (-h/2, -b/2) = h e2
    e3 = (P[:, 3] - P[:, 2]) / 0.05
    slope = beam.nodal(res.q[-1])[:, 3:6]
    np.testing.assert_allclose(np.einsum("ni,ni->n", e2, slope), 0, atol=1e-12)   # frame normal to r'
    np.testing.assert_allclose(np.linalg.norm(np.cross(e2, e3), axis=1), 1, atol=1e-12)
    assert np.abs(e2 - beam.frames[:, :, 1]).max() > 1e-4                       # and it turned


def test_vtk_without_beam_rebuilds_it_from_the_result_file(tmp_path):
    beam, res = _run(BE2D(SOFT, RectangularSection(0.1)), [0.0, -50.0])
    back = Result.load(res.save(tmp_path / "r.nc"))
    rebuilt = beam_of(back)
    np.testing.assert_array_equal(rebuilt.q_ref, beam.q_ref)
    pvd = vtk(back, directory=tmp_path / "vtk", every=2)
    assert len(ET.parse(pvd).getroot().findall("./Collection/DataSet")) == (res.t.size + 1) // 2


def test_vtk_errors(tmp_path):
    beam, res = _run(BE3D(SOFT, RectangularSection(0.1)), [0.0, -20.0, 30.0])
    no_state = Result(t=res.t, q=res.q, v=res.v, a=res.a, model=res.model)   # directors not recorded
    with pytest.raises(ValueError, match="model_state\\['directors'\\]"):
        vtk(no_state, beam, tmp_path)
    bare = Result(t=res.t, q=res.q, v=res.v, a=res.a)
    with pytest.raises(ValueError, match="no beam description"):
        vtk(bare, None, tmp_path)
    with pytest.raises(ValueError, match="`every` must be a positive integer"):
        vtk(res, beam, tmp_path, every=0)
