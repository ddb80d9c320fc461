"""The assembly pattern from node pairs equals the one from every element-matrix entry.

:func:`~ancfdae.models.beam.assembly.node_pattern` (what every beam builds) and the reference
:func:`~ancfdae.models.beam.assembly.entry_pattern` must give the same ``indptr``, ``indices`` and slot of
every element-matrix entry, for every element type (2, 3 nodes; 4 to 9 coordinates per node) with
clamps, pins and single fixed coordinates, on straight and curved meshes. Catches: a slot off by a
column (wrong offset of a neighbour node, a fixed column counted), a row of a node with fixed
coordinates given the wrong start, the fixed bin not at ``nnz``, unsorted columns, a wrong diagonal slot.
"""
import numpy as np
import pytest

from ancfdae import Material, RectangularSection
from ancfdae.models import BE2D, BE3D, BE3DSR, SQ2D, SQ3D, Beam, Cable3D
from ancfdae.models.beam.assembly import Assembler, element_nodes_of, entry_pattern, node_pattern

MAT = Material(2.1e11, 0.3, 7800.0)
SEC = RectangularSection(0.1)


def _free_of_full(beam):
    f = np.full(beam.q_ref.size, -1)
    f[beam.free] = np.arange(beam.n_dof)
    return f


def _check(beam):
    el = beam.element
    fof = _free_of_full(beam)
    nodes = element_nodes_of(beam.edofs, fof.size, el.n_node_dof)
    assert nodes is not None and np.array_equal(nodes, beam.element_nodes)
    new = node_pattern(nodes, fof, el.n_node_dof)
    ref = entry_pattern(fof[beam.edofs], beam.n_dof)
    for a, b in zip(new, ref):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    asm = beam._asm
    assert np.array_equal(asm._slot_all, ref[2])
    # diagonal slots point at the diagonal
    rows = np.repeat(np.arange(beam.n_dof), np.diff(asm.indptr))
    assert np.array_equal(rows[asm.diag_slot], np.arange(beam.n_dof))
    assert np.array_equal(asm.indices[asm.diag_slot], np.arange(beam.n_dof))


CASES = [(BE2D, {0: "clamp", -1: "pin"}), (Cable3D, {0: "clamp"}), (BE3D, {0: "clamp", 3: "pin"}),
         (BE3DSR, {0: "clamp"}), (SQ2D, {0: "clamp", -1: "pin"}), (SQ3D, {0: "clamp", 2: "pin"}),
         (SQ3D, None), (BE2D, {2: ("y",)})]


@pytest.mark.parametrize("cls, supports", CASES, ids=[f"{c.__name__}-{s}" for c, s in CASES])
def test_node_pattern_equals_entry_pattern(cls, supports):
    _check(Beam(cls(MAT, SEC), 5, 2.0, supports=supports))


@pytest.mark.parametrize("cls", [SQ3D, BE3D])
def test_node_pattern_curved_mesh(cls):
    npe = 3 if cls is SQ3D else 2
    s = np.linspace(0.0, 1.0, 4 * (npe - 1) + 1)
    nodes = np.column_stack([np.cos(s), np.sin(s), 0.3 * s])
    _check(Beam(cls(MAT, SEC), nodes=nodes, supports={0: "clamp"}))


def test_assembled_matrix_equals_dense_sum():
    """The assembled K is the dense sum of scattered element matrices (independent of either pattern code)."""
    beam = Beam(SQ3D(MAT, SEC), 3, 1.0, supports={0: "clamp", 4: "pin"})
    rng = np.random.default_rng(0)
    ke = rng.standard_normal((3, 27, 27))
    K = beam._asm.matrix(ke).toarray()
    full = np.zeros((beam.q_ref.size,) * 2)
    for e in range(3):
        full[np.ix_(beam.edofs[e], beam.edofs[e])] += ke[e]
    assert np.allclose(K, full[np.ix_(beam.free, beam.free)], rtol=1e-14, atol=1e-14)


def test_other_layouts_take_the_entry_pattern():
    """Coordinates not in node blocks: no node structure is claimed, the reference pattern is used."""
    edofs = np.array([[0, 2, 1, 3], [2, 4, 3, 5]])
    assert element_nodes_of(edofs, 6, 2) is None
    asm = Assembler(edofs, np.arange(6), 6, node_dof=2)
    ref = entry_pattern(edofs, 6)
    assert np.array_equal(asm.indptr, ref[0]) and np.array_equal(asm._slot_all, ref[2])
