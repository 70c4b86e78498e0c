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
from rt70.linear.damped import damped_modes
from rt70.linear.state_space import StateSpace
from rt70.plotting import modal as plots
from rt70.testing import MIN_REL, assert_close

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
#: The book prints its frequencies to four decimals (Hz).
PRINTED_DIGIT_HZ = 1e-4
#: dB per unit relative change of a magnitude, 20/ln 10: the scale of a level's rounding
#: (a relative error ε of |H| moves 20 log₁₀|H| by ε · 8.7 dB, whatever the level).
DB = 20.0 / np.log(10.0)


def elevation():
    M = np.diag(I_ELEV)
    K = GAMMA_ELEV.T @ np.diag(C_ELEV) @ GAMMA_ELEV
    return M, K


def oscillator(omega=2.0 * np.pi * 1.5, zeta=0.05, m=3.0):
    """1-DOF: m q̈ + 2ξΩm q̇ + mΩ² q = u, output q."""
    return np.array([[m]]), np.array([[m * omega**2]]), np.array([[2 * zeta * omega * m]])


def assert_close_complex(actual, expected, *, rel, scale=None):
    """:func:`assert_close` of complex arrays: real and imaginary parts, on the scale of
    ``|expected|`` (its max-norm, or the entries' own moduli if ``scale`` is given so)."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    scale = np.abs(expected).max() if scale is None else scale
    assert_close(actual.real, expected.real, rel=rel, scale=scale)
    assert_close(actual.imag, expected.imag, rel=rel, scale=scale)


def assert_eigen_solution(M, K, md, tol=1e-12):
    res = modal.residuals(M, K, md)
    # residuals() are relative (to ‖K‖ ‖v‖, to 1, to max ω²): their own scale is 1
    for name in ("eigen", "orthonormality", "stiffness_diagonal"):
        assert_close(res[name], 0.0, rel=1e-12 if name != "eigen" else tol, scale=1.0, what=name)
    # independent of residuals(): each column by hand
    V = md.shapes
    for i in range(md.n):
        v = V[:, i]
        scale = np.linalg.norm(K, 2) * np.linalg.norm(v)
        assert_close(K @ v, md.omega2[i] * (M @ v), rel=tol, scale=scale)
    assert_close(V.T @ M @ V, np.eye(md.n), rel=1e-12)


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
    assert_close(md.omega2, lam, rel=1e-13)
    assert_close(md.freq_hz, np.sqrt(lam) / (2 * np.pi), rel=1e-13)
    assert not md.rigid.any() and not md.negative.any() and md.stable
    assert md.modal_damping is None and md.zeta is None
    assert_eigen_solution(M, K, md)


def test_rt70_elevation_spectrum():
    M, K = elevation()
    md = modal.modes(M, K)
    assert_eigen_solution(M, K, md)
    # to half a unit of the book's last printed digit
    assert_close(md.freq_hz, PRINTED_HZ, rel=0.5, scale=PRINTED_DIGIT_HZ)
    assert md.rigid.tolist() == [True, False, False, False, False, False]
    assert not md.negative.any()
    assert md.omega[0] == 0.0 and md.freq_hz[0] == 0.0  # rounding residue clipped
    # the rigid mode is the rotation of the whole swinging part: v ∝ (1, ..., 1)
    v = md.shapes[:, 0]
    assert_close(v, np.full(6, 1 / np.sqrt(I_ELEV.sum())), rel=1e-10)


def test_rigid_body_mode_of_free_chain():
    m = np.array([1.0, 4.0, 2.0])
    M = np.diag(m)
    G = np.array([[-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]])
    K = G.T @ np.diag([50.0, 80.0]) @ G
    md = modal.modes(M, K)
    assert md.rigid.tolist() == [True, False, False]
    assert_close(md.omega2[0], 0.0, rel=1.0, scale=md.rigid_tol)  # the rigid threshold
    assert_close(md.shapes[:, 0], np.full(3, 1 / np.sqrt(m.sum())), rel=1e-12)
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
    assert_close(delta, 0.1 / Omega1, rel=MIN_REL)
    assert_close(D, GAMMA_ELEV.T @ np.diag(delta * C_ELEV) @ GAMMA_ELEV, rel=1e-12)
    md = modal.modes(M, K, D)
    assert md.proportional
    assert_close(md.damping_offdiag, 0.0, rel=1e-12, scale=1.0)  # relative to the diagonal
    assert np.isnan(md.zeta[0])
    assert_close(md.zeta[1], 0.05, rel=1e-12)
    assert_close(md.zeta[1:], 0.05 * md.omega[1:] / Omega1, rel=1e-10)
    # principal coordinates (2.21): VᵀDV = δ Ω²
    Omega2, Z = modal.principal_coordinates(M, K, D, md)
    assert_close(Omega2, np.diag(md.omega2), rel=1e-12)
    assert_close(Z, delta * Omega2, rel=1e-10)
    assert_close(np.diag(Z)[1:], 2 * md.zeta[1:] * md.omega[1:], rel=1e-10)


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
    assert_close(np.sort(np.diag(md.modal_damping)[:2]), np.linalg.eigvalsh(D[:2, :2]), rel=1e-12)


def test_principal_coordinates_reject_foreign_modes():
    M, K = elevation()
    md = modal.modes(M, K)
    with pytest.raises(Rt70Error, match="do not diagonalise"):
        modal.principal_coordinates(2 * M, K, None, md)
    Omega2, Z = modal.principal_coordinates(M, K, None, md)
    assert not Z.any()
    # the book's V⁻¹ I⁻¹ equals Vᵀ for mass-normalised V
    V = md.shapes
    assert_close(np.linalg.inv(V) @ np.linalg.inv(M), V.T, rel=1e-12)


# -------------------------------------------------------------------------- state space


def test_state_space_matrices():
    M, K = elevation()
    D, _ = modal.stiffness_proportional_damping(K, modal.modes(M, K))
    B_in = np.eye(6)[:, [0]]
    ss = responses.state_space(M, K, D, B_in, np.eye(6)[[2, 5]], output_names=["mirror", "cr"])
    Minv = np.diag(1 / I_ELEV)
    assert_close(ss.A[6:, :6], -Minv @ K, rel=1e-14)
    assert_close(ss.A[6:, 6:], -Minv @ D, rel=1e-14)
    np.testing.assert_array_equal(ss.A[:6, 6:], np.eye(6))  # the identity block, placed
    assert_close(ss.B[6:], Minv @ B_in, rel=1e-14)
    assert ss.D.shape == (2, 1) and not ss.D.any()
    assert ss.state_labels[0] == "q1" and ss.state_labels[6] == "q1_dot"
    assert ss.output_labels == ["mirror", "cr"] and ss.input_labels == ["u1"]
    # eigenvalues of A: ±jω for the undamped model
    ss0 = responses.state_space(M, K, None, B_in, np.eye(6)[0])
    lam = np.sort(np.abs(np.linalg.eigvals(ss0.A).imag))[::2]
    assert_close(lam[1:], modal.modes(M, K).omega[1:], rel=1e-9)


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
    assert_close_complex(fr1.H, fr2.H, rel=1e-8)


def test_modal_state_space_matches_full_and_truncates():
    M, K = elevation()
    md0 = modal.modes(M, K)
    D, _ = modal.stiffness_proportional_damping(K, md0)
    md = modal.modes(M, K, D)
    B_in, C_out = np.eye(6)[:, [0]], np.eye(6)[[2]]
    f = np.geomspace(0.5, 30.0, 200)
    full = responses.frequency_response(responses.state_space(M, K, D, B_in, C_out), f)
    ms = responses.modal_state_space(md, B_in, C_out)
    assert ms.nstates == 12 and ms.state_labels[0] == "z1"
    mod = responses.frequency_response(ms, f)
    # entry by entry: each frequency on its own |H| (which spans decades)
    assert_close_complex(mod.H, full.H, rel=1e-9, scale=np.abs(full.H))
    mod1 = responses.frequency_response(ms, f, method="state_space")
    assert_close_complex(mod1.H, full.H, rel=1e-9, scale=np.abs(full.H))
    # truncation to the lowest 4 modes (rigid, 3.27, 4.24, 6.30 Hz) keeps the response
    # below 5 Hz to 0.5 %; 3 modes do not (mode 4 carries 8 % at 3 Hz)
    tr = responses.modal_state_space(md, B_in, C_out, n_modes=4)
    assert tr.nstates == 8
    low = f < 5.0
    truncated = responses.frequency_response(tr, f[low]).H
    assert_close_complex(truncated, full.H[low], rel=5e-3, scale=np.abs(full.H[low]))
    with pytest.raises(Rt70Error):
        responses.modal_state_space(md, B_in, C_out, n_modes=0)


# ---------------------------------------------------------------------------- responses


@pytest.mark.slow
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
        # levels in dB on the scale DB: rel is then the relative error of the magnitude
        assert_close(static, 20 * np.log10(1 / K[0, 0]), rel=1e-13, scale=DB)
        assert_close(db[-1] - static, 20 * np.log10(1 / (2 * zeta)), rel=1e-10, scale=DB)
        peak = db[1:-1].max() - static
        exact = 20 * np.log10(1 / (2 * zeta * np.sqrt(1 - zeta**2)))
        assert_close(peak, exact, rel=1e-7, scale=DB)  # the grid's step
        assert_close(peak, 20.0, rel=0.05 / 20.0)  # the book's +20 dB, to ±0.05 dB
        f_peak = f[1:-1][db[1:-1].argmax()]
        assert_close(f_peak, f_res * np.sqrt(1 - 2 * zeta**2), rel=2e-5, scale=f_res)
    fr = responses.frequency_response(ss, [0.0, f_res, 100 * f_res])
    # to 0.1° of the half turn: at 100 f_res the phase is still 0.06° short of −180°
    assert_close(fr.phase_deg[:, 0, 0], [0.0, -90.0, -180.0], rel=0.1 / 180.0)


def test_rt70_first_resonance_with_book_damping():
    """RT-70 elevation, D = δC: mode 1 in isolation peaks +20 dB over its static part."""
    M, K = elevation()
    D, _ = modal.stiffness_proportional_damping(K, modal.modes(M, K))
    md = modal.modes(M, K, D)
    assert_close(md.zeta[1], 0.05, rel=1e-12)
    # principal coordinate z_1 alone: z̈_1 + (VᵀDV)_11 ż_1 + Ω1² z_1 = u
    Omega2, Z = modal.principal_coordinates(M, K, D, md)
    ss = responses.state_space([[1.0]], Omega2[1:2, 1:2], Z[1:2, 1:2], [1.0], [1.0])
    db = responses.frequency_response(ss, [0.0, md.freq_hz[1]]).magnitude_db[:, 0, 0]
    assert_close(db[1] - db[0], 20.0, rel=1e-10, scale=DB)


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
    static = 1.0 / K[0, 0]  # the step's final deflection
    assert_close(y[:, 0, 0], exact, rel=1e-12, scale=static)
    # non-uniform times give the same samples
    tn = np.concatenate([t[:500], t[500::7]])
    _, yn = responses.step_response(ss, tn)
    assert_close(yn[:, 0, 0], exact[np.isin(t, tn)], rel=1e-12, scale=static)


def test_step_response_rigid_body_is_exact():
    # a free mass: q = t²/(2m) under a unit force; A is singular, expm still exact
    ss = responses.state_space([[2.0]], [[0.0]], None, [1.0], [1.0])
    t = np.linspace(0, 3, 31)
    _, y = responses.step_response(ss, t)
    assert_close(y[:, 0, 0], t**2 / 4, rel=1e-12)


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
        bare = StateSpace(
            ss.A, ss.B, ss.C, ss.D, states=ss.state_labels, inputs=["u"], outputs=["y"]
        )
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
    d = damped_modes(M, K, 0.1 * K)
    assert_close(d.frequencies_hz, und.freq_hz, rel=1e-12)
    assert_close(d.zeta, und.zeta, rel=1e-12)
    assert d.real.size == 0 and d.eigenvalues.size == 4
    # one mass, ζ = 2: λ = ω(−ζ ± √(ζ² − 1)), both real
    omega, zeta = 3.0, 2.0
    d1 = damped_modes(np.eye(1), np.eye(1) * omega**2, np.eye(1) * 2 * zeta * omega)
    expected = np.sort(omega * (-zeta + np.array([-1.0, 1.0]) * np.sqrt(zeta**2 - 1)))
    assert d1.oscillatory.size == 0
    assert_close(d1.real, expected, rel=1e-12)
