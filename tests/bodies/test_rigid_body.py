"""RigidBody (ancfdae.bodies): mass matrix, loads, constraints and their exact derivatives."""
import numpy as np
import pytest

from ancfdae import DistributedLoad, Gravity, PointForce, PointMoment
from ancfdae.bodies import RigidBody
from ancfdae.problem import Model, capabilities
from support.numerics import fd_gradient, rel_err

RNG = np.random.default_rng(19)


def _rot3(a, b, c):
    Rz = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    Ry = np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])
    Rx = np.array([[1, 0, 0], [0, np.cos(c), -np.sin(c)], [0, np.sin(c), np.cos(c)]])
    return Rz @ Ry @ Rx


def _box_quadrature(sides, centre, axes, dim):
    """Gauss points (2 per side: exact for the quadratic kinetic energy) and weights of a homogeneous box."""
    g = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    grid = np.stack(np.meshgrid(*[g] * dim, indexing="ij"), -1).reshape(-1, dim)
    Y = grid * (np.asarray(sides) / 2)
    return centre + Y @ axes.T, np.full(len(Y), 1.0 / len(Y))


def _box_body_3d():
    """A homogeneous box (sides 0.3, 0.2, 0.5; mass 4) with its centre off the reference point and its axes
    turned in the body frame: a full inertia tensor."""
    m, sides, Xc, Rb = 4.0, np.array([0.3, 0.2, 0.5]), np.array([0.1, -0.05, 0.2]), _rot3(0.3, -0.4, 0.7)
    a, b, c = sides
    theta = Rb @ np.diag(m / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])) @ Rb.T
    return m, sides, Xc, Rb, theta


def test_mass_matrix_is_the_kinetic_energy_of_a_box_for_any_director_rates():
    # Catches: J_c = Theta instead of tr/2 I - Theta, a missing m X_c X_c^T or m X_c block, the kron order.
    m, sides, Xc, Rb, theta = _box_body_3d()
    body = RigidBody(m, theta, [0.2, 0.1, -0.3], _rot3(0.2, 0.5, -1.0), com=Xc)
    X, w = _box_quadrature(sides, Xc, Rb, 3)
    M = body.mass().toarray()
    for _ in range(3):
        v = RNG.standard_normal(12)          # not a rigid velocity: M is int rho S^T S for every v
        rdot = v[:3] + X @ v[3:].reshape(3, 3)
        assert rel_err(0.5 * v @ M @ v, 0.5 * m * np.sum(w * np.sum(rdot ** 2, axis=1))) < 1e-13


def test_planar_mass_gives_the_kinetic_energy_of_rigid_motions():
    # 2D keeps only I_zz; on rigid motions the energy of a rectangle is exact. Catches a wrong I_zz / 2 split.
    m, sides, Xc, Rb = 3.0, np.array([0.4, 0.1]), np.array([0.15, -0.05]), np.array([[0.8, -0.6], [0.6, 0.8]])
    Izz = m * (sides @ sides) / 12
    body = RigidBody(m, Izz, [1.0, 2.0], 0.7, com=Xc, velocity=[0.3, -0.2], angular_velocity=2.5)
    q, v = body.initial_state()
    X, w = _box_quadrature(sides, Xc, Rb, 2)
    rdot = v[:2] + X @ v[2:].reshape(2, 2)
    assert rel_err(body.energy(0.0, q, v).kinetic, 0.5 * m * np.sum(w * np.sum(rdot ** 2, axis=1))) < 1e-13
    assert body.angular_velocity(q, v) == pytest.approx(2.5, rel=1e-14)


def _loaded_body(dim):
    if dim == 2:
        loads = [Gravity([0.0, -9.81]), PointMoment(1.7, node=0, time=lambda t: np.cos(t)),
                 (PointForce([2.0, -1.0], node=0, time=lambda t: 1 + t), (0.3, 0.1)), PointForce([0.5, 0.2], node=0)]
        return RigidBody(2.0, 0.2, [0.1, 0.2], 0.4, com=[0.1, 0.05], angular_velocity=1.3, loads=loads)
    loads = [Gravity([0.0, 0.0, -9.81]), PointMoment([1.0, -2.0, 0.5], node=0, time=lambda t: np.cos(t)),
             (PointForce([2.0, -1.0, 0.3], node=0, time=lambda t: 1 + t), (0.3, 0.1, -0.2))]
    return RigidBody(2.0, [0.3, 0.4, 0.5], [0.1, 0.2, 0.3], _rot3(0.1, 0.2, 0.3), com=[0.1, 0.0, -0.1],
                     angular_velocity=[1.0, -2.0, 0.5], loads=loads)


@pytest.mark.parametrize("dim", [2, 3])
def test_jacobian_blocks_against_finite_differences(dim):
    # Catches: the moment's tangent missing or with the wrong sign (K = -C), a wrong mass block.
    body = _loaded_body(dim)
    n = body.n_dof
    q, v, a = (RNG.standard_normal(n) for _ in range(3))   # off the manifold: the maps are global
    t = 0.37
    r, jac = body.residual_jacobian(t, q, v, a)
    assert np.array_equal(r, body.residual(t, q, v, a))
    assert jac.same_pattern and np.abs(jac.K.toarray()).max() > 0
    assert rel_err(jac.K.toarray(), fd_gradient(lambda x: body.residual(t, x, v, a), q)) < 1e-8
    assert np.abs(fd_gradient(lambda x: body.residual(t, q, x, a), v)).max() == 0.0 == np.abs(jac.D.toarray()).max()
    assert rel_err(jac.M.toarray(), fd_gradient(lambda x: body.residual(t, q, v, x), a)) < 1e-8
    assert np.allclose(jac.combine(1.0, 2.0, 3.0).toarray(), jac.K.toarray() + 3.0 * jac.M.toarray(), atol=1e-14)


@pytest.mark.parametrize("dim", [2, 3])
def test_constraint_derivatives_against_finite_differences(dim):
    # Catches: a wrong entry of G (the off-diagonal rows need both directors), H(lambda) missing a
    # transposed block or the diagonal rows' factor, gamma without the factor 2 of the cross terms.
    body = _loaded_body(dim)
    n, m = body.n_dof, body.n_constraints
    assert m == dim * (dim + 1) // 2
    q, v, lam = RNG.standard_normal(n), RNG.standard_normal(n), RNG.standard_normal(m)
    G = body.constraint_jacobian(0.0, q)
    assert rel_err(G.toarray(), fd_gradient(lambda x: body.constraints(0.0, x), q)) < 1e-9
    H = body.constraint_force_jacobian(0.0, q, lam).toarray()
    assert rel_err(H, fd_gradient(lambda x: body.constraint_jacobian(0.0, x).T @ lam, q)) < 1e-9
    # The fast path G^T lam without G (a cross row adding to one director only, or the wrong director).
    assert rel_err(body.constraint_force(0.0, q, lam), G.T @ lam) < 1e-14
    # The pattern is fixed: the same indices at any state.
    G2 = body.constraint_jacobian(0.0, RNG.standard_normal(n))
    assert np.array_equal(G.indices, G2.indices) and np.array_equal(G.indptr, G2.indptr)
    Z = body.constraint_velocity_jacobian(0.0, q, v)
    assert rel_err(Z.toarray(), fd_gradient(lambda x: body.constraint_jacobian(0.0, x) @ v, q)) < 1e-9
    assert np.array_equal(Z.indices, G.indices)
    g_t, gamma = body.constraint_rates(0.0, q, v)
    e = 1e-3   # g is quadratic: the central second difference along v is exact up to rounding
    second = (body.constraints(0.0, q + e * v) - 2 * body.constraints(0.0, q) + body.constraints(0.0, q - e * v)) / e**2
    assert np.all(g_t == 0.0)
    assert rel_err(gamma, -second) < 1e-7
    q0, v0 = body.initial_state()
    assert np.abs(body.constraints(0.0, q0)).max() < 1e-15
    assert np.abs(body.constraint_jacobian(0.0, q0) @ v0).max() < 1e-15   # v0 satisfies G v = 0


@pytest.mark.parametrize("dim", [2, 3])
def test_loads_do_the_virtual_work_of_forces_and_moments(dim):
    # Catches: the moment acting with the wrong sign or twice (the 1/2 of delta phi), a force applied at the
    # centre of mass instead of its point.
    body = _loaded_body(dim)
    q, _ = body.initial_state()
    t = 0.2
    f, C = body.nonconservative_force(t, q)
    R = body.orientation(q)
    Xp = np.array([0.3, 0.1] if dim == 2 else [0.3, 0.1, -0.2])
    F = (np.array([2.0, -1.0] if dim == 2 else [2.0, -1.0, 0.3])) * (1 + t)
    Mom = np.array([0.0, 0.0, 1.7]) if dim == 2 else np.array([1.0, -2.0, 0.5])
    Mom = Mom * np.cos(t)
    F_com = np.array([0.5, 0.2]) if dim == 2 else np.zeros(3)
    for w in (np.eye(3)[2:] if dim == 2 else np.eye(3)):
        W = np.cross(w, np.eye(3))[:dim, :dim].T if dim == 3 else np.array([[0.0, -1.0], [1.0, 0.0]])
        dq = np.concatenate([np.zeros(dim)] + [W @ R[:, k] for k in range(dim)])   # rotation about the point x
        arm = R @ Xp
        work_F = F @ (W @ arm) + F_com @ (W @ (R @ body.com))
        assert f @ dq == pytest.approx(Mom @ w + work_F, rel=1e-13)
    for k in range(dim):       # a translation: only the forces work
        dq = np.zeros(body.n_dof)
        dq[k] = 1.0
        assert f @ dq == pytest.approx(F[k] + F_com[k], rel=1e-13, abs=1e-13)
    assert body.external_power(t, q, q * 0 + 1.0) == pytest.approx(f.sum(), rel=1e-14)


@pytest.mark.parametrize("dim", [2, 3])
def test_potential_is_gravity_and_its_gradient(dim):
    # Catches: gravity applied at the reference point instead of the centre of mass; P and dP/dq out of step.
    body = _loaded_body(dim)
    q = RNG.standard_normal(body.n_dof)
    gP, K = body.potential_gradient(0.0, q)
    assert rel_err(gP, fd_gradient(lambda x: np.array(body.potential(0.0, x)), q)) < 1e-9
    assert K.nnz == 0 or np.abs(K.toarray()).max() == 0.0
    q0, _ = body.initial_state()
    g = np.zeros(dim)
    g[-1] = -9.81
    dz = RNG.standard_normal(dim)
    qs = q0.copy()
    qs[:dim] += dz
    assert body.potential(0.0, qs) == pytest.approx(-2.0 * g @ dz, rel=1e-13)
    assert body.energy(0.0, qs, qs).potential == body.potential(0.0, qs)
    assert body.residual(0.0, q, q, 0 * q) @ np.ones(body.n_dof) == pytest.approx(
        (gP - body.nonconservative_force(0.0, q, False)[0]).sum(), rel=1e-13)


def test_attachment_maps_points_and_directors():
    # Catches: an attachment whose maps disagree with the body's own points or directors.
    body = _loaded_body(3)
    q = RNG.standard_normal(12)
    X = np.array([0.2, -0.1, 0.4])
    att = body.attachment(tuple(X))
    assert att.dim == 3 and att.n_dof == 12 and len(att.axes) == 3
    assert np.allclose(att.position @ q, body.points(q, X)[0], rtol=0, atol=1e-15)
    R = body.orientation(q)
    for k in range(3):
        assert np.array_equal(att.axes[k] @ q, R[:, k])
    assert np.array_equal(body.attachment().position @ q, q[:3])
    Q = RNG.standard_normal((5, 12))          # many states at once
    assert body.points(Q, [X, -X]).shape == (5, 2, 3)
    assert np.allclose(body.centre_of_mass(Q)[2], body.points(Q[2], body.com)[0])


def test_model_contract_capabilities_and_description():
    # Catches: a capability declared without its methods; a description that rebuilds another body.
    for dim in (2, 3):
        body = _loaded_body(dim)
        assert isinstance(body, Model)
        assert capabilities(body) == {"residual_jacobian", "potential", "constraints"}
        again = RigidBody.from_description(body.describe())
        for a, b in zip(body.initial_state(), again.initial_state()):
            assert np.allclose(a, b, rtol=0, atol=1e-15)
        assert np.array_equal(body.mass().toarray(), again.mass().toarray())
        node, names = body.dof_labels()
        assert names.size == body.n_dof and names[dim] == "d1x"
    with pytest.raises(ValueError, match="format"):
        RigidBody.from_description({"element": "BE2D"})


@pytest.mark.parametrize("kwargs, match", [
    (dict(mass=1.0, inertia=[1.0, 1.0, 2.0 + 1e-9], position=[0, 0, 0]), "sum of the other two"),
    (dict(mass=1.0, inertia=[[1, 0.1, 0], [0, 1, 0], [0, 0, 1]], position=[0, 0, 0]), "symmetric"),
    (dict(mass=-1.0, inertia=1.0, position=[0, 0]), "`mass`"),
    (dict(mass=1.0, inertia=0.0, position=[0, 0]), "`inertia`"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0, 0, 0]), "2 or 3 components"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0], orientation=[[1, 0], [0, -1]]), "proper rotation"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0], orientation=[[1, 0.1], [0, 1]]), "proper rotation"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0], com=[0, 0, 0]), "`com`"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0], loads=[PointForce([1, 0], node=3)]), "node=0"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0], loads=[PointForce([1, 0, 0], node=0)]), "2 components"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0], loads=[PointMoment([1, 0, 0], node=0)]), "scalar"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0], loads=[DistributedLoad([1, 0])]), "resultant"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0], loads=[Gravity([0, 0, -9.81])]), "2 components"),
    (dict(mass=1.0, inertia=1.0, position=[0, 0], angular_velocity=[1, 2]), "finite number"),
])
def test_bad_input_names_the_argument(kwargs, match):
    with pytest.raises(ValueError, match=match):
        RigidBody(**kwargs)


def test_a_thin_disk_is_a_body_whose_mass_is_regular_on_rigid_motions():
    # Catches: a lamina (I_axial = I_1 + I_2) rejected, or its kinetic energy wrong on rigid motions.
    m, r = 1.0, 0.1
    disk = RigidBody(m, [m * r * r / 4, m * r * r / 4, m * r * r / 2], [0, 0, 0], angular_velocity=[1.0, 2.0, 3.0])
    q, v = disk.initial_state()
    assert disk.energy(0.0, q, v).kinetic == pytest.approx(0.5 * m * r * r * (1 / 4 + 4 / 4 + 9 / 2), rel=1e-14)
    assert np.linalg.matrix_rank(disk.mass().toarray()) == 9      # d3 carries no mass: a lamina


def test_wrong_state_length_is_a_clear_error():
    body = _loaded_body(2)
    with pytest.raises(ValueError, match="n_dof = 6"):
        body.residual(0.0, np.zeros(5), np.zeros(6), np.zeros(6))
    with pytest.raises(TypeError, match="Gravity, PointForce or PointMoment"):
        RigidBody(1.0, 1.0, [0, 0], loads=["gravity"])
