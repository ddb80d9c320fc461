"""Every joint's derivatives against finite differences, through System (the contract the integrators use).

Per joint type, planar (BE2D) and spatial (SQ3D: two directors per node; Cable3D: one slope): G against
FD of g (catches a wrong sign or a transposed block), d(G^T lam)/dq against FD of G^T lam (catches a
quadratic row whose A_i is not symmetrised, or H(lam) missing), g_t against FD in t, G a - gamma
against the second derivative of g along a curve (catches a wrong G_t or g_tt) and Z(v) + G_t against FD
of G v + g_t, at a random state off the reference configuration.
"""
import numpy as np
import pytest

from ancfdae import Material, RectangularSection, System
from ancfdae.joints import Distance, Prescribed, Prismatic, Revolute, Rigid, Spherical
from ancfdae.models import BE2D, SQ3D, Beam, Cable3D
from support.numerics import fd_gradient, rel_err

MAT = Material(E=1e7, nu=0.3, rho=1000.0)
SEC = RectangularSection(0.05)


def _drive2(t):
    return np.array([1.5 + 0.1 * np.sin(2 * t), 0.05 * t * t]), np.array([0.2 * np.cos(2 * t), 0.1 * t]), \
        np.array([-0.4 * np.sin(2 * t), 0.1])


def _drive3(t):
    p, dp, ddp = _drive2(t)
    return np.r_[p, 0.1 * t ** 3], np.r_[dp, 0.3 * t ** 2], np.r_[ddp, 0.6 * t]


def _angle(t):
    return 0.3 * np.sin(t) + 0.1, 0.3 * np.cos(t), -0.3 * np.sin(t)


def planar(kind):
    b1 = Beam(BE2D(MAT, SEC), 2, 1.0)
    b2 = Beam(BE2D(MAT, SEC), 2, 1.0, start=(1.0, 0.2), direction=(1.0, 1.0), supports={-1: "pin"})
    joints = {
        "spherical": [Spherical("ground", (b1, 0)), Spherical((b1, 0.75), (b2, {"s": 0.3}))],
        "rigid": [Rigid((b1, 0.4), (b2, 0)), Rigid("ground", (b1, -1))],
        "prismatic": [Prismatic((b2, 0), "ground", direction=(1.0, 2.0)), Prismatic((b1, -1), (b2, 0.5))],
        "distance": [Distance((b1, 0.2), (b2, -2)), Distance((b2, 0.1), "ground", at=(0.3, -0.4))],
        "prescribed": [Prescribed((b1, 1), position=_drive2, angle=_angle), Prescribed((b2, 0.5), angle=_angle)],
    }[kind]
    return System([b1, b2], joints)


def spatial(kind):
    s1 = Beam(SQ3D(MAT, SEC), 2, 1.0)
    s2 = Beam(SQ3D(MAT, SEC), 2, 1.0, start=(1.0, 0.2, 0.1), direction=(1.0, 1.0, 0.5))
    c = Beam(Cable3D(MAT, SEC), 2, 1.0, start=(0.0, 0.0, 1.0), direction=(0.0, 1.0, 0.0))
    joints = {
        "spherical": [Spherical("ground", (c, 0)), Spherical((s1, 0.75), (s2, {"s": 0.3}))],
        "revolute": [Revolute((s1, 0), "ground"), Revolute((c, -1), (s2, 1), normals=(0, 1))],
        # side a's directors (e_y, e_z of s1) span c's slope (e_y): a weld at a right angle
        "rigid": [Rigid((s1, 0.4), (c, 0.5)), Rigid("ground", (s2, 0), fix_lengths=True)],
        "prismatic": [Prismatic((c, -1), "ground", direction=(1.0, 2.0, 0.5)),
                      Prismatic((s1, -1), (s2, 0.5), normals=(0, 1))],
        "distance": [Distance((s1, 0.2), (c, -2)), Distance((s2, 0.1), "ground", at=(0.3, -0.4, 0.2))],
        "prescribed": [Prescribed((s1, 1), position=_drive3)],
    }[kind]
    return System([s1, s2, c], joints)


CASES = [("2d", k) for k in ("spherical", "rigid", "prismatic", "distance", "prescribed")] + \
        [("3d", k) for k in ("spherical", "revolute", "rigid", "prismatic", "distance", "prescribed")]


@pytest.mark.parametrize("dim, kind", CASES, ids=[f"{d}-{k}" for d, k in CASES])
def test_joint_derivatives_match_finite_differences(dim, kind):
    sysm = planar(kind) if dim == "2d" else spatial(kind)
    rng = np.random.default_rng(3)
    q0, _ = sysm.initial_state()
    q = q0 + 0.05 * rng.standard_normal(q0.size)
    v = rng.standard_normal(q0.size)
    a = rng.standard_normal(q0.size)
    lam = rng.standard_normal(sysm.n_constraints)
    t = 0.7
    G = sysm.constraint_jacobian(t, q)
    assert rel_err(G.toarray(), fd_gradient(lambda x: sysm.constraints(t, x), q)) < 1e-7
    H = sysm.constraint_force_jacobian(t, q, lam).toarray()
    Hfd = fd_gradient(lambda x: sysm.constraint_jacobian(t, x).T @ lam, q)
    if np.abs(Hfd).max() > 0:
        assert rel_err(H, Hfd) < 1e-7
    else:
        assert np.abs(H).max() == 0.0
    assert np.allclose(H, H.T, rtol=0, atol=1e-14 * max(1.0, np.abs(H).max()))
    g_t, gamma = sysm.constraint_rates(t, q, v)
    eps = 1e-6
    g_t_fd = (sysm.constraints(t + eps, q) - sysm.constraints(t - eps, q)) / (2 * eps)
    assert np.abs(g_t - g_t_fd).max() < 1e-7 * max(1.0, np.abs(g_t_fd).max())
    if kind == "prescribed":
        assert np.abs(g_t).max() > 0.01       # the test sees the rheonomic terms

    def along(s):
        return sysm.constraints(t + s, q + s * v + 0.5 * s * s * a)
    hs = 1e-4
    d2 = (along(hs) - 2 * along(0.0) + along(-hs)) / hs ** 2
    assert np.abs(G @ a - gamma - d2).max() < 1e-5 * max(1.0, np.abs(d2).max())
    Zt = sysm.constraint_velocity_jacobian(t, q, v).toarray()
    Zfd = fd_gradient(lambda x: sysm.constraint_jacobian(t, x) @ v + sysm.constraint_rates(t, x, v)[0], q)
    assert np.abs(Zt - Zfd).max() < 1e-7 * max(1.0, np.abs(Zfd).max())
    # fixed pattern: the structure does not depend on the state
    G2 = sysm.constraint_jacobian(t + 0.3, q0)
    assert np.array_equal(G2.indptr, G.indptr) and np.array_equal(G2.indices, G.indices)


@pytest.mark.parametrize("element, supports", [(BE2D, {0: "pin"}), (SQ3D, {0: "clamp"}), (Cable3D, None)])
def test_beam_attachment_is_the_beam_point_and_slope(element, supports):
    """Position at node and arc length equals Beam.position with the supports' offsets (catches a map on
    the full instead of the free coordinates, or a missing offset); the thin elements' slope at s is the
    derivative of the position along the axis (catches a wrong factor 2/L)."""
    dim = 2 if element is BE2D else 3
    beam = Beam(element(MAT, SEC), 3, 1.5, direction=np.ones(dim), supports=supports)
    q = beam.initial_state()[0] + 0.03 * np.random.default_rng(0).standard_normal(beam.n_dof)
    for where, s in ((2, beam.s_nodes[2]), (-1, 1.5), (0.35, 0.35), ({"s": 1.2}, 1.2)):
        att = beam.attachment(where)
        assert np.allclose(att.position @ q + att.offset, beam.position(q, s), atol=1e-14)
    att = beam.attachment(0.8)
    slope = att.axes[0] @ q + att.axes_offset[0]
    if element is not SQ3D:
        ds = 1e-6
        fd = (beam.position(q, 0.8 + ds) - beam.position(q, 0.8 - ds)) / (2 * ds)
        assert np.abs(slope - fd).max() < 1e-8
    else:   # SQ3D: the directors interpolated like the position; at a node they are the nodal coordinates
        node = beam.attachment(1)
        full = beam.expand(q).reshape(beam.n_nodes, -1)
        assert np.allclose(node.axes[0] @ q + node.axes_offset[0], full[1, 3:6], atol=1e-14)
        assert np.allclose(node.axes[1] @ q + node.axes_offset[1], full[1, 6:9], atol=1e-14)
