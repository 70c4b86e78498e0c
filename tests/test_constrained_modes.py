"""Equilibrium, linearisation and modes on a constraint manifold (rt70.linear.manifold,
rt70.linear.constrained_equilibrium, rt70.linear.constrained).

Mechanisms with answers known without the module: a particle hanging by the constraint
x² + y² = l² (ω² = g/l, all of it from the multipliers' geometric stiffness: K = 0 in
(x, y)), the same pendulum inverted (ω² = −g/l), a rod hanging from a pin in (x, y, θ)
(ω² = 3g/2l), and a planar four-bar in its three joint angles closed by hand, against a
minimal-coordinate model built from the closed-form position analysis and differences of
its Lagrangian. Run: ``.venv/bin/pytest -q tests/test_constrained_modes.py``.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.optimize

from rt70.errors import Rt70Error
from rt70.linear import constrained as cm
from rt70.linear import constrained_equilibrium as ce
from rt70.linear import manifold as mf
from rt70.testing import assert_close

G = 9.81


# ------------------------------------------------------------------- particle pendulum


def particle(m: float = 2.0, length: float = 1.5, scale: float = 1.0):
    """A particle of mass m in (x, y) on ``scale · (x² + y² − l²) = 0``, gravity −y."""
    con = mf.Constraints(
        residual=lambda q: np.array([scale * (q @ q - length**2)]),
        jacobian=lambda q: scale * 2.0 * q.reshape(1, 2),
        bias=lambda q, qd: np.array([scale * 2.0 * qd @ qd]),
    )
    force = lambda q: np.array([0.0, -m * G])  # noqa: E731
    return con, force, m * np.eye(2)


def _particle_lin(geometric=True, start=(0.4, -1.0), scale=1.0, D=None):
    con, force, M = particle(scale=scale)
    eq = ce.equilibrium(force, con, np.array(start))
    lin = cm.linearize(con, eq.q, eq.lam, M, np.zeros((2, 2)), D, geometric=geometric)
    return eq, lin, con, force, M


def test_hanging_particle_frequency_is_sqrt_g_over_l():
    eq, lin, con, force, M = _particle_lin()
    m, length = 2.0, 1.5
    assert_close(eq.q, [0.0, -length], rel=1e-12)
    # Q + B_cᵀλ = 0: (0, −mg) + λ (0, −2l) = 0, so λ = −mg/2l (a tension pulls inward)
    assert_close(eq.lam, [-m * G / (2 * length)], rel=1e-12)
    # G = −λ ∇²Φ = −λ · 2·1 = (mg/l)·1 along the circle's tangent
    assert_close(lin.K_geometric, [[m * G / length]], rel=1e-9)
    res = cm.modes(lin)
    assert_close(res.modes.omega2, [G / length], rel=1e-9)
    # the shape in (x, y): the tangent (1, 0), A-normalised: 1/√m
    assert_close(res.shapes[:, 0], [1 / np.sqrt(m), 0.0], rel=1e-12)
    assert_close(res.shapes.T @ M @ res.shapes, [[1.0]], rel=1e-12)


def test_dropping_the_geometric_stiffness_loses_the_pendulum():
    """K = 0 in (x, y): the naive projection Nᵀ K N sees a free (rigid) mode."""
    _, lin, *_ = _particle_lin(geometric=False)
    res = cm.modes(lin, rigid_tol=1e-12)
    assert res.modes.rigid.all()
    # zero on the scale of the pendulum's g/l that the projection loses
    assert_close(res.modes.omega2[0], 0.0, rel=1e-12, scale=G / 1.5)


def test_inverted_particle_is_unstable_with_the_right_rate():
    """Above the pivot λ changes sign (the rod pushes): ω² = −g/l, flagged."""
    eq, lin, *_ = _particle_lin(start=(0.1, 1.2))
    assert_close(eq.q, [0.0, 1.5], rel=1e-12)
    assert eq.lam[0] > 0
    res = cm.modes(lin)
    assert_close(res.modes.omega2, [-G / 1.5], rel=1e-9)
    assert res.modes.negative.all() and not res.modes.stable


def test_scaled_and_redundant_constraints_give_the_same_frequency():
    """Φ → 5Φ scales λ by 1/5, not G; a repeated row (rank 1) splits λ, not G."""
    _, lin5, *_ = _particle_lin(scale=5.0)
    assert_close(cm.modes(lin5).modes.omega2, [G / 1.5], rel=1e-9)
    con, force, M = particle()
    twice = mf.combine(
        con, mf.Constraints(lambda q: 2 * con.residual(q), lambda q: 2 * con.jacobian(q))
    )
    eq = ce.equilibrium(force, twice, np.array([0.4, -1.0]))
    lin = cm.linearize(twice, eq.q, eq.lam, M, np.zeros((2, 2)))
    assert lin.rank == 1 and eq.lam.size == 2
    assert_close(eq.lam, -2.0 * G / 3.0 * np.array([1, 2]) / 5, rel=1e-12)
    assert_close(cm.modes(lin).modes.omega2, [G / 1.5], rel=1e-9)


def test_particle_partition_agrees():
    eq, lin, con, force, M = _particle_lin()
    part = cm.partition_linearize(force, con, eq.q, M)
    assert part.K_geometric is None
    assert_close(cm.modes(part).modes.omega2, [G / 1.5], rel=1e-8)
    assert_close(cm.modes(part).shapes, cm.modes(lin).shapes, rel=1e-10)


def test_damping_projects_to_the_tangent():
    c = 0.3
    _, lin, *_ = _particle_lin(D=c * np.eye(2))
    res = cm.modes(lin)
    omega = np.sqrt(G / 1.5)
    assert_close(res.modes.zeta, [c / (2 * 2.0 * omega)], rel=1e-9)


# ------------------------------------------------------------------------ rod pendulum


ROD_M, ROD_L = 3.0, 0.8


def rod():
    """A rod (m, l) in (x, y, θ) of its centre, its end pinned at the origin."""
    h = ROD_L / 2
    con = mf.Constraints(
        residual=lambda q: np.array([q[0] - h * np.sin(q[2]), q[1] + h * np.cos(q[2])]),
        jacobian=lambda q: np.array([[1.0, 0.0, -h * np.cos(q[2])], [0.0, 1.0, -h * np.sin(q[2])]]),
    )
    force = lambda q: np.array([0.0, -ROD_M * G, 0.0])  # noqa: E731
    M = np.diag([ROD_M, ROD_M, ROD_M * ROD_L**2 / 12])
    eq = ce.equilibrium(force, con, np.array([0.1, -0.3, 0.2]))
    return con, force, M, eq


def test_rod_on_a_pin_in_body_coordinates():
    """ω² = m g (l/2) / (m l²/12 + m l²/4) = 3g/2l; K = 0 in (x, y, θ): all from G."""
    con, force, M, eq = rod()
    assert_close(eq.q, [0.0, -ROD_L / 2, 0.0], rel=1e-12)
    K = np.zeros((3, 3))
    null = cm.modes(cm.linearize(con, eq.q, eq.lam, M, K))
    part = cm.modes(cm.partition_linearize(force, con, eq.q, M))
    assert_close(null.modes.omega2, [1.5 * G / ROD_L], rel=1e-9)
    assert_close(part.modes.omega2, [1.5 * G / ROD_L], rel=1e-8)
    assert_close(part.shapes, null.shapes, rel=1e-9)
    naive = cm.modes(cm.linearize(con, eq.q, eq.lam, M, K, geometric=False), rigid_tol=1e-12)
    assert naive.modes.rigid.all()


# ---------------------------------------------------------------------------- four-bar

#: Crank a, coupler b, rocker c, ground d (Grashof crank-rocker); uniform rods.
A, B, C, D = 0.3, 0.8, 0.6, 0.7
LENGTHS = np.array([A, B, C])
MASSES = np.array([1.0, 2.0, 1.5])
INERTIAS = MASSES * LENGTHS**2 / 12
SPRING, REST = 5.0, 1.0  # a torsional spring on the crank joint, N·m/rad and rad
PIVOT = np.array([D, 0.0])


def _chain(theta):
    """Joint positions o_1..o_4 and absolute angles of the open chain (relative θ)."""
    psi = np.cumsum(theta)
    o = [np.zeros(2)]
    for L, p in zip(LENGTHS, psi, strict=True):
        o.append(o[-1] + L * np.array([np.cos(p), np.sin(p)]))
    return o, psi


def _coms(o, psi):
    return [o[i] + 0.5 * LENGTHS[i] * np.array([np.cos(psi[i]), np.sin(psi[i])]) for i in range(3)]


def _cross(p, o):
    """ẑ × (p − o) in the plane: the velocity of p per unit rotation about o."""
    d = p - o
    return np.array([-d[1], d[0]])


def fourbar_full():
    """The chain in its three joint angles, closed by hand: the rocker's end at the pivot."""

    def mass(theta):
        o, psi = _chain(theta)
        A_ = np.zeros((3, 3))
        for i, p in enumerate(_coms(o, psi)):
            Jv = np.zeros((2, 3))
            Jw = np.zeros(3)
            for k in range(i + 1):
                Jv[:, k] = _cross(p, o[k])
                Jw[k] = 1.0
            A_ += MASSES[i] * Jv.T @ Jv + INERTIAS[i] * np.outer(Jw, Jw)
        return A_

    def force(theta):
        o, psi = _chain(theta)
        Q = np.zeros(3)
        for i, p in enumerate(_coms(o, psi)):
            for k in range(i + 1):
                Q[k] += _cross(p, o[k]) @ np.array([0.0, -MASSES[i] * G])
        Q[0] -= SPRING * (theta[0] - REST)
        return Q

    def residual(theta):
        return _chain(theta)[0][3] - PIVOT

    def jacobian(theta):
        o, _ = _chain(theta)
        return np.column_stack([_cross(o[3], o[k]) for k in range(3)])

    def bias(theta, rate):
        """Ḃ_c θ̇: the tip's acceleration at θ̈ = 0, −Σ L_i ψ̇_i² (cos ψ_i, sin ψ_i)."""
        psi = np.cumsum(theta)
        w = np.cumsum(rate)
        return -sum(
            L * wi**2 * np.array([np.cos(p), np.sin(p)])
            for L, p, wi in zip(LENGTHS, psi, w, strict=True)
        )

    return mf.Constraints(residual, jacobian, bias), force, mass


def _closed_form(phi):
    """Joint angles of the closed four-bar for crank angle φ (circle intersection)."""
    a_pt = A * np.array([np.cos(phi), np.sin(phi)])
    e = PIVOT - a_pt
    d2 = e @ e
    along = (B * B - C * C + d2) / (2 * d2)
    across = np.sqrt(B * B / d2 - along * along)
    b_pt = a_pt + along * e + across * np.array([-e[1], e[0]])  # the upper branch
    psi2 = np.arctan2(*(b_pt - a_pt)[::-1])
    psi3 = np.arctan2(*(PIVOT - b_pt)[::-1])
    return np.array([phi, psi2 - phi, psi3 - psi2]), a_pt, b_pt, (phi, psi2, psi3)


def _lagrangian_parts(phi):
    """Potential V(φ) and the COM positions and angles the kinetic energy needs."""
    _, a_pt, b_pt, psi = _closed_form(phi)
    unit = [np.array([np.cos(p), np.sin(p)]) for p in psi]
    coms = [0.5 * A * unit[0], a_pt + 0.5 * B * unit[1], b_pt + 0.5 * C * unit[2]]
    V = sum(MASSES[i] * G * coms[i][1] for i in range(3)) + 0.5 * SPRING * (phi - REST) ** 2
    return V, np.concatenate([*coms, np.unwrap(np.array(psi))])


def _d1(f, x, h):
    """Five-point first derivative (error O(h⁴))."""
    return (f(x - 2 * h) - 8 * f(x - h) + 8 * f(x + h) - f(x + 2 * h)) / (12 * h)


def _d2(f, x, h):
    """Five-point second derivative (error O(h⁴))."""
    return (-f(x - 2 * h) + 16 * f(x - h) - 30 * f(x) + 16 * f(x + h) - f(x + 2 * h)) / (12 * h * h)


def minimal_fourbar():
    """Equilibrium φ*, ω² and dθ/dφ of the one-coordinate model (no rt70 code)."""
    V = lambda p: _lagrangian_parts(p)[0]  # noqa: E731
    dV = lambda p: _d1(V, p, 1e-3)  # noqa: E731
    grid = np.linspace(-np.pi, np.pi, 721)
    start = grid[np.argmin([V(p) for p in grid])]
    phi = scipy.optimize.brentq(dV, start - 0.02, start + 0.02, xtol=1e-15, rtol=1e-15)
    velocity = _d1(lambda p: _lagrangian_parts(p)[1], phi, 1e-3)  # d(com, ψ)/dφ
    m_r = sum(
        MASSES[i] * velocity[2 * i : 2 * i + 2] @ velocity[2 * i : 2 * i + 2] for i in range(3)
    )
    m_r += INERTIAS @ velocity[6:] ** 2
    k_r = _d2(V, phi, 1e-3)
    dtheta = _d1(lambda p: _closed_form(p)[0], phi, 1e-3)
    return phi, k_r / m_r, dtheta / np.sqrt(m_r)


@pytest.fixture(scope="module")
def fourbar():
    con, force, mass = fourbar_full()
    phi, omega2, shape = minimal_fourbar()
    start = _closed_form(phi + 0.05)[0] + np.array([0.0, 0.01, -0.02])  # off the manifold
    eq = ce.equilibrium(force, con, start, tol=1e-12)
    return con, force, mass, eq, phi, omega2, shape


def test_fourbar_equilibrium_is_the_minimum_of_the_minimal_model(fourbar):
    con, force, mass, eq, phi, *_ = fourbar
    assert_close(eq.q, _closed_form(phi)[0], rel=1e-10)
    # the residuals on the loop's length and on the forces (max|Q| ≈ 30 N·m)
    assert_close(eq.constraint_residual, 0.0, rel=1e-12, scale=LENGTHS.sum())
    assert_close(eq.force_residual, 0.0, rel=1e-12, scale=np.abs(force(eq.q)).max())


def test_fourbar_modes_both_ways_against_the_minimal_model(fourbar):
    con, force, mass, eq, phi, omega2, shape = fourbar
    M = mass(eq.q)
    K = mf.force_stiffness(force, eq.q)
    null = cm.modes(cm.linearize(con, eq.q, eq.lam, M, K))
    part = cm.modes(cm.partition_linearize(force, con, eq.q, M))
    assert null.modes.n == part.modes.n == 1
    assert_close(null.modes.omega2, [omega2], rel=1e-8)
    assert_close(part.modes.omega2, [omega2], rel=1e-8)
    assert_close(null.modes.omega2, part.modes.omega2, rel=1e-8)
    sign = np.sign(shape[np.argmax(np.abs(shape))])
    assert_close(null.shapes[:, 0], sign * shape, rel=1e-8)
    assert_close(part.shapes[:, 0], null.shapes[:, 0], rel=1e-8)
    # without the multipliers' stiffness the frequency is wrong by far more than that
    naive = cm.modes(cm.linearize(con, eq.q, eq.lam, M, K, geometric=False))
    assert abs(naive.modes.omega2[0] / omega2 - 1) > 0.05


def test_geometric_stiffness_exact_from_the_bias_and_by_differences(fourbar):
    """G by polarisation of C = Ḃ_c q̇ (exact) and by differences of B_cᵀλ agree."""
    con, force, mass, eq, phi, omega2, shape = fourbar
    differenced = mf.Constraints(con.residual, con.jacobian)
    G_exact = mf.geometric_stiffness(con, eq.q, eq.lam)
    G_diff = mf.geometric_stiffness(differenced, eq.q, eq.lam)
    assert np.abs(G_exact).max() > 1.0  # the loop's reactions are tens of newtons
    assert_close(G_diff, G_exact, rel=1e-8)
    M, K = mass(eq.q), mf.force_stiffness(force, eq.q)
    exact = cm.modes(cm.linearize(con, eq.q, eq.lam, M, K))
    assert_close(exact.modes.omega2, [omega2], rel=1e-8)
    # the bias's check of its shape
    bad = mf.Constraints(con.residual, con.jacobian, lambda q, qd: np.zeros(3))
    with pytest.raises(Rt70Error, match="bias has shape"):
        mf.geometric_stiffness(bad, eq.q, eq.lam)


# ------------------------------------------------------------------------------ refusals


def test_a_rigid_mechanism_has_no_modes():
    con, force, M = particle()
    both = mf.combine(con, mf.fixed(2, [0], [0.0]))
    eq = ce.equilibrium(force, both, np.array([0.2, -1.0]))
    with pytest.raises(Rt70Error, match="leave no motion"):
        cm.linearize(both, eq.q, eq.lam, M, np.zeros((2, 2)))


def test_a_free_direction_is_neutral_without_a_force_and_refused_with_one():
    """No gravity: every point of the circle is an equilibrium (the start is closed onto
    it, a rigid mode). A force along a direction nothing holds: no equilibrium."""
    con, _, M = particle()
    eq = ce.equilibrium(lambda q: np.zeros(2), con, np.array([0.4, -1.0]))
    # closed to the equilibrium's default tol: |Φ| = |q·q − l²| ≤ 1e-10 max|q|
    assert_close(np.hypot(*eq.q), 1.5, rel=1e-10)
    lin = cm.linearize(con, eq.q, eq.lam, M, np.zeros((2, 2)))
    assert cm.modes(lin).modes.rigid.all()
    on_a_line = mf.Constraints(lambda q: q[1:], lambda q: np.array([[0.0, 1.0]]))
    with pytest.raises(Rt70Error, match="singular.*a force acts along it"):
        ce.equilibrium(lambda q: np.array([1.0, 0.0]), on_a_line, np.array([0.4, -1.0]))


def test_wrong_shapes_are_refused():
    con = mf.Constraints(lambda q: np.zeros(1), lambda q: np.zeros((1, 3)))
    with pytest.raises(Rt70Error, match="3 columns, q has 2"):
        ce.equilibrium(lambda q: np.zeros(2), con, np.zeros(2))
    con, _, M = particle()
    with pytest.raises(Rt70Error, match="force has shape"):
        ce.equilibrium(lambda q: np.zeros(3), con, np.array([0.4, -1.0]))
    with pytest.raises(Rt70Error, match="M must be 2 × 2"):
        cm.linearize(con, np.array([0.0, -1.5]), np.ones(1), np.eye(3), np.zeros((2, 2)))


# ---------------------------------------------------------------------------- the report


def report() -> list[tuple[str, float, float, float, float]]:
    """(case, exact ω², null space, partition, naive projection) for docs/constrained-modes.md."""
    rows = []
    _, lin, con, force, M = _particle_lin()
    part = cm.partition_linearize(force, con, lin.q0, M)
    naive = cm.linearize(con, lin.q0, lin.lam, M, np.zeros((2, 2)), geometric=False)
    rows.append(("particle on x²+y²=l², g/l", G / 1.5, lin, part, naive))
    _, lin, *_ = _particle_lin(start=(0.1, 1.2))
    rows.append(("the same inverted, −g/l", -G / 1.5, lin, None, None))
    con, force, M, eq = rod()
    K = np.zeros((3, 3))
    rows.append(
        (
            "rod on a pin (x, y, θ), 3g/2l",
            1.5 * G / ROD_L,
            cm.linearize(con, eq.q, eq.lam, M, K),
            cm.partition_linearize(force, con, eq.q, M),
            cm.linearize(con, eq.q, eq.lam, M, K, geometric=False),
        )
    )
    con, force, mass = fourbar_full()
    phi, omega2, _ = minimal_fourbar()
    eq = ce.equilibrium(
        force, con, _closed_form(phi + 0.05)[0] + np.array([0, 0.01, -0.02]), tol=1e-12
    )
    M, K = mass(eq.q), mf.force_stiffness(force, eq.q)
    rows.append(
        (
            "four-bar vs minimal model",
            omega2,
            cm.linearize(con, eq.q, eq.lam, M, K),
            cm.partition_linearize(force, con, eq.q, M),
            cm.linearize(con, eq.q, eq.lam, M, K, geometric=False),
        )
    )
    out = []
    for name, exact, *lins in rows:
        values = [
            np.nan if x is None else cm.modes(x, rigid_tol=1e-12).modes.omega2[0] for x in lins
        ]
        out.append((name, exact, *values))
    return out


if __name__ == "__main__":  # python tests/test_constrained_modes.py
    print(f"{'case':<28} {'exact ω²':>12} {'null space':>11} {'partition':>11} {'naive':>11}")
    for name, exact, *values in report():
        errs = " ".join(f"{abs(v / exact - 1):11.1e}" for v in values)
        print(f"{name:<28} {exact:12.8g} {errs}")
    print("columns 3-5: |ω²/exact − 1| (naive: G dropped)")
