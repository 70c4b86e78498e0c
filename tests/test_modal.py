"""Modal analysis, principal coordinates, state space and responses, and their figures.

(rt70.linear.modal, rt70.linear.responses, rt70.plotting.modal)
"""

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
from matplotlib.figure import Figure

from rt70.errors import Rt70Error
from rt70.linear import modal, responses
from rt70.plotting import modal as plots

# --- the RT-70 elevation model of chapter 2 (rt70-data.md §B), built here with numpy ---

I_ELEV = np.array([0.7500e7, 0.3000e7, 0.1420e8, 0.2700e7, 0.6906e7, 0.3122e4])
C_ELEV = np.array([0.2861e11, 0.4760e10, 0.1960e10, 0.4672e10, 0.6480e7])
GAMMA_ELEV = np.array(
    [
        [-1, 1, 0, 0, 0, 0],
        [-1, 0, 1, 0, 0, 0],
        [0, -1, 0, 1, 0, 0],
        [0, -1, 0, 0, 1, 0],
        [0, 0, 0, -1, 0, 1],
    ],
    dtype=float,
)
PRINTED_HZ = np.array([0.0, 3.2700, 4.2424, 6.3041, 7.2579, 19.6420])
NAMES = ["counterweight", "base", "mirror", "rigel", "mirror base", "counterreflector"]


def elevation():
    M = np.diag(I_ELEV)
    K = GAMMA_ELEV.T @ np.diag(C_ELEV) @ GAMMA_ELEV
    return M, K


def oscillator(omega=2.0 * np.pi * 1.5, zeta=0.05, m=3.0):
    """1-DOF: m q̈ + 2ξΩm q̇ + mΩ² q = u, output q."""
    return np.array([[m]]), np.array([[m * omega**2]]), np.array([[2 * zeta * omega * m]])


def assert_eigen_solution(M, K, md, tol=1e-12):
    res = modal.residuals(M, K, md)
    assert res["eigen"] < tol, res
    assert res["orthonormality"] < 1e-12, res
    assert res["stiffness_diagonal"] < 1e-12, res
    # independent of residuals(): each column by hand
    V = md.shapes
    for i in range(md.n):
        v = V[:, i]
        r = K @ v - md.omega2[i] * (M @ v)
        assert np.linalg.norm(r) <= tol * np.linalg.norm(K, 2) * np.linalg.norm(v)
    np.testing.assert_allclose(V.T @ M @ V, np.eye(md.n), atol=1e-12)


# ------------------------------------------------------------------------------- modes


def test_two_dof_analytic():
    m1, m2, k1, k2 = 2.0, 1.0, 300.0, 100.0  # ground–1 (k1), 1–2 (k2)
    M = np.diag([m1, m2])
    K = np.array([[k1 + k2, -k2], [-k2, k2]])
    md = modal.modes(M, K)
    # det(K − λM) = m1 m2 λ² − (m1 k2 + m2 (k1 + k2)) λ + k1 k2 = 0
    b = m1 * k2 + m2 * (k1 + k2)
    disc = np.sqrt(b * b - 4 * m1 * m2 * k1 * k2)
    lam = np.array([(b - disc), (b + disc)]) / (2 * m1 * m2)
    np.testing.assert_allclose(md.omega2, lam, rtol=1e-13)
    np.testing.assert_allclose(md.freq_hz, np.sqrt(lam) / (2 * np.pi), rtol=1e-13)
    assert not md.rigid.any() and not md.negative.any() and md.stable
    assert md.modal_damping is None and md.zeta is None
    assert_eigen_solution(M, K, md)


def test_rt70_elevation_spectrum():
    M, K = elevation()
    md = modal.modes(M, K)
    assert_eigen_solution(M, K, md)
    np.testing.assert_array_equal(np.round(md.freq_hz, 4), PRINTED_HZ)
    assert md.rigid.tolist() == [True, False, False, False, False, False]
    assert not md.negative.any()
    assert md.omega[0] == 0.0 and md.freq_hz[0] == 0.0  # rounding residue clipped
    # the rigid mode is the rotation of the whole swinging part: v ∝ (1, ..., 1)
    v = md.shapes[:, 0]
    np.testing.assert_allclose(v, np.full(6, 1 / np.sqrt(I_ELEV.sum())), rtol=1e-10)


def test_rigid_body_mode_of_free_chain():
    m = np.array([1.0, 4.0, 2.0])
    M = np.diag(m)
    G = np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]])
    K = G.T @ np.diag([50.0, 80.0]) @ G
    md = modal.modes(M, K)
    assert md.rigid.tolist() == [True, False, False]
    assert abs(md.omega2[0]) <= md.rigid_tol
    np.testing.assert_allclose(md.shapes[:, 0], 1 / np.sqrt(m.sum()), rtol=1e-12)
    assert_eigen_solution(M, K, md)
    # grounding the chain removes the rigid mode
    md_g = modal.modes(M, K + np.diag([10.0, 0, 0]))
    assert not md_g.rigid.any()
    # an explicit tolerance is honoured
    assert modal.modes(M, K, rigid_tol=md.omega2[1] * 1.01).rigid.tolist() == [True, True, False]


def test_two_rigid_modes_cluster():
    # two unconnected free pairs: two rigid modes (a cluster at ω² = 0)
    M = np.diag([1.0, 2.0, 3.0, 4.0])
    K = np.zeros((4, 4))
    K[:2, :2] = 10.0 * np.array([[1, -1], [-1, 1]])
    K[2:, 2:] = 20.0 * np.array([[1, -1], [-1, 1]])
    md = modal.modes(M, K, D=0.01 * K)
    assert md.rigid.sum() == 2
    assert np.isnan(md.zeta[md.rigid]).all()
    assert md.proportional
    assert_eigen_solution(M, K, md)


def test_negative_stiffness_is_flagged_not_clipped():
    # inverted pendulum on a torsion spring too weak for gravity: k − m g l < 0
    M = np.diag([1.0, 1.0])
    K = np.array([[-2.0, 0.5], [0.5, 3.0]])
    md = modal.modes(M, K)
    assert md.negative.tolist() == [True, False]
    assert not md.rigid.any() and not md.stable
    assert md.omega2[0] < 0 and np.isnan(md.omega[0]) and np.isnan(md.freq_hz[0])
    assert np.isfinite(md.omega[1])
    assert_eigen_solution(M, K, md)


def test_dense_mass_matrix():
    rng = np.random.default_rng(7)
    n = 8
    A = rng.standard_normal((n, n))
    M = A @ A.T + n * np.eye(n)
    B = rng.standard_normal((n, n))
    K = B @ B.T
    md = modal.modes(M, K)
    assert_eigen_solution(M, K, md, tol=1e-13)
    assert (np.diff(md.omega2) >= 0).all()


# ------------------------------------------------------------------------------ damping


def test_proportional_damping_gives_book_ratios():
    M, K = elevation()
    md0 = modal.modes(M, K)
    D, delta = modal.stiffness_proportional_damping(K, md0)  # D = δ ΓᵀCΓ = Γᵀ(δC)Γ
    Omega1 = md0.omega[1]
    assert delta == pytest.approx(0.1 / Omega1, rel=1e-15)
    np.testing.assert_allclose(D, GAMMA_ELEV.T @ np.diag(delta * C_ELEV) @ GAMMA_ELEV)
    md = modal.modes(M, K, D)
    assert md.proportional and md.damping_offdiag < 1e-12
    assert np.isnan(md.zeta[0])
    assert md.zeta[1] == pytest.approx(0.05, rel=1e-12)
    np.testing.assert_allclose(md.zeta[1:], 0.05 * md.omega[1:] / Omega1, rtol=1e-10)
    # principal coordinates (2.21): VᵀDV = δ Ω²
    Omega2, Z = modal.principal_coordinates(M, K, D, md)
    np.testing.assert_allclose(Omega2, np.diag(md.omega2))
    np.testing.assert_allclose(Z, delta * Omega2, atol=1e-10 * np.abs(Z).max())
    np.testing.assert_allclose(np.diag(Z)[1:], 2 * md.zeta[1:] * md.omega[1:], rtol=1e-10)


def test_non_proportional_damping_is_flagged():
    M, K = elevation()
    D = np.zeros((6, 6))
    D[5, 5] = 1e5  # a single damper on the counterreflector
    md = modal.modes(M, K, D)
    assert md.proportional is False and md.damping_offdiag > 1e-3
    assert_eigen_solution(M, K, md)


def test_clustered_eigenvalues_are_rotated_to_diagonalise_damping():
    # ω² = 1 twice: any basis of that plane is a valid pair of modes; a damping that
    # commutes with K there must still come out diagonal.
    M = np.eye(3)
    K = np.diag([1.0, 1.0, 4.0])
    D = np.array([[0.3, 0.1, 0.0], [0.1, 0.2, 0.0], [0.0, 0.0, 0.5]])
    md = modal.modes(M, K, D)
    assert md.proportional, md.damping_offdiag
    assert_eigen_solution(M, K, md)
    np.testing.assert_allclose(
        np.sort(np.diag(md.modal_damping)[:2]), np.linalg.eigvalsh(D[:2, :2])
    )


def test_principal_coordinates_reject_foreign_modes():
    M, K = elevation()
    md = modal.modes(M, K)
    with pytest.raises(Rt70Error, match="do not diagonalise"):
        modal.principal_coordinates(2 * M, K, None, md)
    Omega2, Z = modal.principal_coordinates(M, K, None, md)
    assert not Z.any()
    # the book's V⁻¹ I⁻¹ equals Vᵀ for mass-normalised V
    V = md.shapes
    np.testing.assert_allclose(np.linalg.inv(V) @ np.linalg.inv(M), V.T, atol=1e-14)


# -------------------------------------------------------------------------- state space


def test_state_space_matrices():
    M, K = elevation()
    D, _ = modal.stiffness_proportional_damping(K, modal.modes(M, K))
    B_in = np.eye(6)[:, [0]]
    ss = responses.state_space(M, K, D, B_in, np.eye(6)[[2, 5]], output_names=["mirror", "cr"])
    Minv = np.diag(1 / I_ELEV)
    np.testing.assert_allclose(ss.A[6:, :6], -Minv @ K, rtol=1e-14)
    np.testing.assert_allclose(ss.A[6:, 6:], -Minv @ D, rtol=1e-14)
    np.testing.assert_array_equal(ss.A[:6, 6:], np.eye(6))
    np.testing.assert_allclose(ss.B[6:], Minv @ B_in, rtol=1e-14)
    assert ss.D.shape == (2, 1) and not ss.D.any()
    assert ss.state_names[0] == "q1" and ss.state_names[6] == "q1_dot"
    assert ss.output_names == ("mirror", "cr") and ss.input_names == ("u1",)
    # eigenvalues of A: ±jω for the undamped model
    ss0 = responses.state_space(M, K, None, B_in, np.eye(6)[0])
    lam = np.sort(np.abs(np.linalg.eigvals(ss0.A).imag))[::2]
    np.testing.assert_allclose(lam[1:], modal.modes(M, K).omega[1:], rtol=1e-9)


def test_second_and_first_order_responses_agree():
    M, K = elevation()
    D, _ = modal.stiffness_proportional_damping(K, modal.modes(M, K))
    D = D + np.diag([0, 0, 0, 0, 0, 30.0])  # and some non-proportional damping
    B_in = np.eye(6)[:, [0, 2]]
    C_out, C_vel = np.eye(6)[[2, 5]], np.eye(6)[[5, 0]]
    ss = responses.state_space(M, K, D, B_in, C_out, C_vel)
    f = np.geomspace(0.1, 40.0, 300)
    fr2 = responses.frequency_response(ss, f)
    fr1 = responses.frequency_response(ss, f, method="state_space")
    assert fr2.method == "second_order" and fr1.method == "state_space"
    assert fr2.H.shape == (300, 2, 2)
    np.testing.assert_allclose(fr1.H, fr2.H, rtol=1e-8, atol=1e-8 * np.abs(fr2.H).max())


def test_modal_state_space_matches_full_and_truncates():
    M, K = elevation()
    md0 = modal.modes(M, K)
    D, _ = modal.stiffness_proportional_damping(K, md0)
    md = modal.modes(M, K, D)
    B_in, C_out = np.eye(6)[:, [0]], np.eye(6)[[2]]
    f = np.geomspace(0.5, 30.0, 200)
    full = responses.frequency_response(responses.state_space(M, K, D, B_in, C_out), f)
    ms = responses.modal_state_space(md, B_in, C_out)
    assert ms.n_states == 12 and ms.state_names[0] == "z1"
    mod = responses.frequency_response(ms, f)
    np.testing.assert_allclose(mod.H, full.H, rtol=1e-9)
    mod1 = responses.frequency_response(ms, f, method="state_space")
    np.testing.assert_allclose(mod1.H, full.H, rtol=1e-9)
    # truncation to the lowest 4 modes (rigid, 3.27, 4.24, 6.30 Hz) keeps the response
    # below 5 Hz to 0.5 %; 3 modes do not (mode 4 carries 8 % at 3 Hz)
    tr = responses.modal_state_space(md, B_in, C_out, n_modes=4)
    assert tr.n_states == 8
    low = f < 5.0
    np.testing.assert_allclose(responses.frequency_response(tr, f[low]).H, full.H[low], rtol=5e-3)
    with pytest.raises(Rt70Error):
        responses.modal_state_space(md, B_in, C_out, n_modes=0)


# ---------------------------------------------------------------------------- responses


def test_oscillator_resonance_peak_is_20_db():
    """ξ = 0.05: |H(jΩ)|/H(0) = 1/(2ξ) = +20 dB exactly at ω = Ω; the true maximum
    1/(2ξ√(1−ξ²)) = +20.011 dB lies at Ω√(1−2ξ²). Both are within ±0.05 dB of the
    book's "+20 dB at the first resonance"; both are checked on the computed response."""
    zeta, Omega = 0.05, 2.0 * np.pi * 1.5
    M, K, D = oscillator(Omega, zeta)
    ss = responses.state_space(M, K, D, [1.0], [1.0])
    f_res = Omega / (2 * np.pi)
    f = np.concatenate([[0.0], np.linspace(0.9 * f_res, 1.1 * f_res, 20001), [f_res]])
    for method in ("second_order", "state_space"):
        db = responses.frequency_response(ss, f, method=method).magnitude_db[:, 0, 0]
        static = db[0]
        assert static == pytest.approx(20 * np.log10(1 / K[0, 0]), abs=1e-12)
        assert db[-1] - static == pytest.approx(20 * np.log10(1 / (2 * zeta)), abs=1e-9)
        peak = db[1:-1].max() - static
        exact = 20 * np.log10(1 / (2 * zeta * np.sqrt(1 - zeta**2)))
        assert peak == pytest.approx(exact, abs=1e-6)
        assert abs(peak - 20.0) <= 0.05
        f_peak = f[1:-1][db[1:-1].argmax()]
        assert f_peak == pytest.approx(f_res * np.sqrt(1 - 2 * zeta**2), abs=2e-5 * f_res)
    fr = responses.frequency_response(ss, [0.0, f_res, 100 * f_res])
    np.testing.assert_allclose(fr.phase_deg[:, 0, 0], [0.0, -90.0, -180.0], atol=0.1)


def test_rt70_first_resonance_with_book_damping():
    """RT-70 elevation, D = δC: mode 1 in isolation peaks +20 dB over its static part."""
    M, K = elevation()
    D, _ = modal.stiffness_proportional_damping(K, modal.modes(M, K))
    md = modal.modes(M, K, D)
    assert md.zeta[1] == pytest.approx(0.05, rel=1e-12)
    # principal coordinate z_1 alone: z̈_1 + (VᵀDV)_11 ż_1 + Ω1² z_1 = u
    Omega2, Z = modal.principal_coordinates(M, K, D, md)
    ss = responses.state_space([[1.0]], Omega2[1:2, 1:2], Z[1:2, 1:2], [1.0], [1.0])
    db = responses.frequency_response(ss, [0.0, md.freq_hz[1]]).magnitude_db[:, 0, 0]
    assert db[1] - db[0] == pytest.approx(20.0, abs=1e-9)


def test_step_response_of_oscillator_matches_analytic():
    zeta, Omega, m = 0.05, 2.0 * np.pi * 1.5, 3.0
    M, K, D = oscillator(Omega, zeta, m)
    ss = responses.state_space(M, K, D, [1.0], [[1.0]], C_vel=[[0.0]])
    t = np.linspace(0.0, 10.0, 2001)
    t_out, y = responses.step_response(ss, t)
    assert y.shape == (2001, 1, 1)
    wd = Omega * np.sqrt(1 - zeta**2)
    exact = (
        1
        - np.exp(-zeta * Omega * t)
        * (np.cos(wd * t) + zeta / np.sqrt(1 - zeta**2) * np.sin(wd * t))
    ) / K[0, 0]
    np.testing.assert_allclose(y[:, 0, 0], exact, rtol=0, atol=1e-12 / K[0, 0])
    # non-uniform times give the same samples
    tn = np.concatenate([t[:500], t[500::7]])
    _, yn = responses.step_response(ss, tn)
    np.testing.assert_allclose(yn[:, 0, 0], exact[np.isin(t, tn)], atol=1e-12 / K[0, 0])


def test_step_response_rigid_body_is_exact():
    # a free mass: q = t²/(2m) under a unit force; A is singular, expm still exact
    ss = responses.state_space([[2.0]], [[0.0]], None, [1.0], [1.0])
    t = np.linspace(0, 3, 31)
    _, y = responses.step_response(ss, t)
    np.testing.assert_allclose(y[:, 0, 0], t**2 / 4, rtol=1e-12, atol=1e-15)


def test_free_structure_at_zero_frequency():
    M, K = elevation()
    ss = responses.state_space(M, K, None, np.eye(6)[:, 0], np.eye(6)[2])
    fr = responses.frequency_response(ss, [0.5, 1.0])  # away from the pole: fine
    assert np.isfinite(fr.H).all()
    ss1 = responses.state_space([[1.0]], [[0.0]], None, [1.0], [1.0])
    with pytest.raises(Rt70Error, match="pole"):
        responses.frequency_response(ss1, [0.0])


# -------------------------------------------------------------------------------- plots


def test_plots_return_figures():
    M, K = elevation()
    md = modal.modes(M, K, modal.stiffness_proportional_damping(K, modal.modes(M, K))[0])
    ss = responses.modal_state_space(md, np.eye(6)[:, 0], np.eye(6)[2])
    fr = responses.frequency_response(ss, np.geomspace(1, 30, 50))
    fig = plots.plot_bode(fr)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    fig2 = Figure()
    axes = fig2.subplots(2, 1)
    assert plots.plot_bode(fr, axes=tuple(axes), label="x") is fig2
    t, y = responses.step_response(ss, np.linspace(0, 1, 11))
    assert isinstance(plots.plot_step(t, y, labels=["mirror"]), Figure)
    fig3 = plots.plot_mode_shapes(md, NAMES, n_modes=3)
    assert len(fig3.axes[0].get_lines()) == 3 + 1  # three modes and the zero line


# ---------------------------------------------------------------------------- bad input


@pytest.mark.parametrize(
    "M, K, match",
    [
        (np.diag([1.0, -1.0]), np.eye(2), "positive definite"),
        (np.diag([1.0, 0.0]), np.eye(2), "positive definite"),
        (np.array([[1.0, np.nan], [np.nan, 1.0]]), np.eye(2), "NaN"),
        (np.eye(2), np.array([[1.0, np.inf], [np.inf, 1.0]]), "NaN"),
        (np.array([[2.0, 1.0], [0.0, 2.0]]), np.eye(2), "not symmetric"),
        (np.eye(2), np.array([[2.0, 1.0], [0.0, 2.0]]), "not symmetric"),
        (np.eye(2), np.eye(3), "matrix"),
        (np.ones((2, 3)), np.eye(2), "square|matrix"),
        (np.ones(3), np.eye(3), "matrix"),
        (np.zeros((0, 0)), np.zeros((0, 0)), "empty"),
        ([["a", "b"], ["c", "d"]], np.eye(2), "numeric"),
    ],
)
def test_bad_matrices_raise(M, K, match):
    with pytest.raises(Rt70Error, match=match):
        modal.modes(M, K)


def test_bad_inputs_elsewhere_raise():
    M, K = elevation()
    with pytest.raises(Rt70Error, match="D"):
        modal.modes(M, K, D=np.eye(5))
    with pytest.raises(Rt70Error, match="rigid_tol"):
        modal.modes(M, K, rigid_tol=np.nan)
    with pytest.raises(Rt70Error, match="positive definite"):
        responses.state_space(-M, K, None, np.eye(6)[:, 0], np.eye(6)[0])
    with pytest.raises(Rt70Error, match="B_in"):
        responses.state_space(M, K, None, np.eye(5)[:, 0], np.eye(6)[0])
    with pytest.raises(Rt70Error, match="C_out"):
        responses.state_space(M, K, None, np.eye(6)[:, 0], np.eye(5)[0])
    with pytest.raises(Rt70Error, match="C_vel"):
        responses.state_space(M, K, None, np.eye(6)[:, 0], np.eye(6)[0], C_vel=np.eye(6)[:2])
    with pytest.raises(Rt70Error, match="D_ff"):
        responses.state_space(M, K, None, np.eye(6)[:, 0], np.eye(6)[0], D_ff=np.ones((2, 2)))
    with pytest.raises(Rt70Error, match="names"):
        responses.state_space(M, K, None, np.eye(6)[:, 0], np.eye(6)[0], output_names=["a", "b"])
    ss = responses.state_space(M, K, None, np.eye(6)[:, 0], np.eye(6)[0])
    with pytest.raises(Rt70Error, match="freq_hz"):
        responses.frequency_response(ss, [1.0, np.nan])
    with pytest.raises(Rt70Error, match="method"):
        responses.frequency_response(ss, [1.0], method="magic")
    with pytest.raises(Rt70Error, match="increasing"):
        responses.step_response(ss, [0.0, 1.0, 1.0])
    with pytest.raises(Rt70Error, match="second_order|M, K, D"):
        bare = responses.StateSpace(ss.A, ss.B, ss.C, ss.D, ss.state_names, ("u",), ("y",))
        responses.frequency_response(bare, [1.0], method="second_order")
    with pytest.raises(Rt70Error, match="elastic"):
        modal.stiffness_proportional_damping(
            np.zeros((2, 2)), modal.modes(np.eye(2), np.zeros((2, 2)))
        )


def test_damped_modes_proportional_pairs_and_overdamped_reals():
    """λ = −ζω ± iω√(1−ζ²) for proportional damping; real λ for an overdamped mode."""
    M = np.diag([1.0, 2.0])
    K = np.array([[3.0, -1.0], [-1.0, 2.0]])
    und = modal.modes(M, K, 0.1 * K)
    d = modal.damped_modes(M, K, 0.1 * K)
    assert np.allclose(d.frequencies_hz, und.freq_hz, rtol=1e-12)
    assert np.allclose(d.zeta, und.zeta, rtol=1e-12)
    assert d.real.size == 0 and d.eigenvalues.size == 4
    # one mass, ζ = 2: λ = ω(−ζ ± √(ζ² − 1)), both real
    omega, zeta = 3.0, 2.0
    d1 = modal.damped_modes(np.eye(1), np.eye(1) * omega**2, np.eye(1) * 2 * zeta * omega)
    expected = np.sort(omega * (-zeta + np.array([-1.0, 1.0]) * np.sqrt(zeta**2 - 1)))
    assert d1.oscillatory.size == 0 and np.allclose(d1.real, expected, rtol=1e-12)
