"""The covariance route: Lyapunov variances, filter cascades, mode split, statistical error."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.integrate
import scipy.stats
from threadpoolctl import threadpool_limits

from rt70.errors import Rt70Error
from rt70.linear import covariance as cov
from rt70.testing import assert_close, close
from rt70.wind.gusts import GustFilter, realise


def parts(z: np.ndarray) -> np.ndarray:
    """Real and imaginary parts of ``z`` stacked on a new first axis, for assert_close."""
    z = np.asarray(z)
    return np.stack([z.real, z.imag])


def oscillators(freqs_hz, zetas, gains=None, inputs=("f",), outputs=("y",)):
    """Independent oscillators ẍ_i + 2ζω ẋ_i + ω² x_i = u, y = Σ gain_i x_i (one input)."""
    n = len(freqs_hz)
    gains = np.ones(n) if gains is None else np.asarray(gains, dtype=float)
    A = np.zeros((2 * n, 2 * n))
    B = np.zeros((2 * n, len(inputs)))
    C = np.zeros((len(outputs), 2 * n))
    for i, (f, z) in enumerate(zip(freqs_hz, zetas, strict=True)):
        w = 2 * np.pi * f
        A[2 * i : 2 * i + 2, 2 * i : 2 * i + 2] = [[0, 1], [-(w**2), -2 * z * w]]
        B[2 * i + 1, :] = 1.0
        C[0, 2 * i] = gains[i]
    return control.ss(A, B, C, 0, inputs=list(inputs), outputs=list(outputs))


def first_order(a=1.0):
    return control.ss(-a, 1.0, 1.0, 0.0, inputs=["w"], outputs=["y"])


def test_first_order_closed_forms():
    """ẏ = −a y + w: var = 1/(2a); std of the mean square = √(1/(2a³T))."""
    a, T = 3.0, 40.0
    assert_close(cov.output_covariance(first_order(a))[0, 0], 1 / (2 * a), rel=1e-14)
    error = cov.sample_variance_error(first_order(a), "y", T)
    assert_close(error, np.sqrt(1 / (2 * a**3 * T)), rel=1e-12)
    # sampled records tend to the continuous mean square as dt → 0
    fine = cov.sample_variance_error(first_order(a), "y", T, dt=1e-4)
    assert_close(fine, np.sqrt(1 / (2 * a**3 * T)), rel=1e-3)


def test_output_covariance_vs_frequency_integral():
    """Oscillator (1 Hz, ζ = 0.02) behind a gust filter: C P Cᵀ = (1/π) ∫₀^∞ |G(jω)|² dω."""
    plant = oscillators([1.0], [0.02])
    sys = cov.cascade_with_filter(plant, GustFilter(10.0).system, "f")
    variance = cov.output_covariance(sys)[0, 0]

    def density(ln_w):
        w = np.exp(ln_w)
        return np.abs(sys.horner(1j * w)[0, 0, 0]) ** 2 * w / np.pi

    breaks = np.log(2 * np.pi * np.array([0.99, 1.0, 1.01]))
    edges = [np.log(1e-9), *breaks, np.log(1e5)]
    integral = sum(
        scipy.integrate.quad(density, lo, hi, limit=500, epsabs=0, epsrel=1e-12)[0]
        for lo, hi in zip(edges[:-1], edges[1:], strict=True)
    )
    assert_close(variance, integral, rel=1e-8)


def test_output_covariance_vs_long_simulation():
    """The same cascade sampled exactly over 1e5 s: ŝ² within 4 stated standard errors."""
    plant = oscillators([1.0], [0.05])
    sys = cov.cascade_with_filter(plant, GustFilter(1.0, length=1.0).system, "f")
    T, dt = 1e5, 0.5
    t, y = realise(sys, T, dt, seed=11)
    variance = cov.output_covariance(sys)[0, 0]
    error = cov.sample_variance_error(sys, "y", T=len(t) * dt, dt=dt)
    assert error / variance < 0.02  # the check has teeth: 2 % at most
    assert_close(np.mean(y**2), variance, rel=4.0, scale=error)  # 4 standard errors


def test_intensity_matrix():
    """W scales the variance; a matrix W with correlated inputs adds the cross term."""
    A = -np.diag([1.0, 2.0])
    B = np.eye(2)
    C = np.array([[1.0, 1.0]])
    W = np.array([[2.0, 0.5], [0.5, 1.0]])
    # P_ij = W_ij / (a_i + a_j)
    expected = 2.0 / 2 + 1.0 / 4 + 2 * 0.5 / 3
    assert_close(cov.output_covariance((A, B, C), W)[0, 0], expected, rel=1e-13)
    assert_close(cov.output_covariance((A, B, C), 3.0)[0, 0], 3 * (1 / 2 + 1 / 4), rel=1e-13)


def test_cascade_with_filter():
    """Named series connection = the filter times the plant's column; gains and lists."""
    plant = control.ss(
        [[0, 1], [-4, -0.4]],
        [[0, 0], [1, 2]],
        [[1, 0], [0, 1]],
        0,
        inputs=["wind_x", "wind_y"],
        outputs=["angle", "rate"],
    )
    gust = GustFilter(10.0).system
    sys = cov.cascade_with_filter(plant, gust, "wind_y")
    assert sys.input_labels == ["w"] and sys.output_labels == ["angle", "rate"]
    assert sys.nstates == 6 and sys.state_labels[0] == "filter.gust1"
    s = 2j * np.pi * np.logspace(-4, 1, 30)
    expected = plant.horner(s)[:, 1, :] * gust.horner(s)[0, 0]
    # each frequency response on its own magnitude
    assert_close(parts(sys.horner(s)[:, 0, :]), parts(expected), rel=1e-10, scale=np.abs(expected))
    series = control.series(gust, plant[:, 1]).horner(s)
    assert_close(parts(sys.horner(s)), parts(series), rel=1e-10, scale=np.abs(series))
    both = cov.cascade_with_filter(plant, gust, ["wind_x", "wind_y"], gain=[0.5, -1.0])
    expected = (0.5 * plant.horner(s)[:, 0, :] - plant.horner(s)[:, 1, :]) * gust.horner(s)[0, 0]
    assert_close(parts(both.horner(s)[:, 0, :]), parts(expected), rel=1e-10, scale=np.abs(expected))
    with pytest.raises(Rt70Error, match="no input 'wind_z'"):
        cov.cascade_with_filter(plant, gust, "wind_z")
    with pytest.raises(Rt70Error, match="one output"):
        cov.cascade_with_filter(plant, plant, "wind_x")


def _transformed(sys, seed=0):
    """The same system in scrambled state coordinates x = T x̃ (shares do not depend on them)."""
    rng = np.random.default_rng(seed)
    T = rng.standard_normal((sys.nstates, sys.nstates)) + 3 * np.eye(sys.nstates)
    Ti = np.linalg.inv(T)
    return control.ss(Ti @ sys.A @ T, Ti @ sys.B, sys.C @ T, 0, outputs=sys.output_labels)


def test_mode_contributions_two_separated_modes():
    """0.5 Hz and 5 Hz, ζ = 0.02: mode i's variance is its own variance plus half the cross
    term (1e-10), the cross term is small, and the variances sum to the total (1e-12)."""
    sys = _transformed(oscillators([0.5, 5.0], [0.02, 0.02], gains=[1.0, 30.0]))
    modes = cov.mode_contributions(sys, "y")
    total = cov.output_covariance(sys)[0, 0]
    own = [
        cov.output_covariance(oscillators([f], [0.02], gains=[g]))[0, 0]
        for f, g in ((0.5, 1.0), (5.0, 30.0))
    ]
    cross = (total - sum(own)) / 2  # E[y₁ y₂]
    assert_close(cross, 0.0, rel=0.01, scale=total)  # small beside the variance
    assert len(modes) == 2
    for mode, f, v in zip(modes, (0.5, 5.0), own, strict=True):
        assert_close(mode.frequency_hz, f * np.sqrt(1), rel=1e-9)  # |λ| = ω_n
        assert_close(mode.damping, 0.02, rel=1e-9)
        assert_close(mode.variance, v + cross, rel=1e-10)
        assert mode.eigenvalue.imag > 0 and mode.eigenvector.shape == (4,)
    assert_close(sum(m.variance for m in modes), total, rel=1e-12)
    shares = [m.share for m in modes]
    assert_close(sum(shares), 1.0, rel=1e-12, scale=np.abs(shares).sum())
    # to the cross term's share, a fraction of the unit total
    assert_close(modes[1].share, own[1] / total, rel=0.01, scale=1.0)


def test_mode_contributions_can_be_negative():
    """Two close modes whose outputs cancel: the cross term is large and a share is < 0."""
    sys = oscillators([1.0, 1.02], [0.05, 0.05], gains=[1.0, -1.2])
    modes = cov.mode_contributions(sys, 0)
    shares = [m.share for m in modes]
    assert min(shares) < 0 < max(shares)
    # the shares cancel: their sum is 1 on the scale of their sizes
    assert_close(sum(shares), 1.0, rel=1e-12, scale=np.abs(shares).sum())
    total = cov.output_covariance(sys)[0, 0]
    assert_close(sum(m.variance for m in modes), total, rel=1e-10)


def test_mode_contributions_with_real_modes():
    """A gust filter (four real poles) before an oscillator: 5 modes, real ones with ζ = 1."""
    sys = cov.cascade_with_filter(oscillators([1.0], [0.02]), GustFilter(10.0).system, "f")
    modes = cov.mode_contributions(sys, "y")
    assert len(modes) == 5
    assert sum(close(m.damping, 1.0, rel=1e-12) for m in modes) == 4
    assert_close(sum(m.variance for m in modes), cov.output_covariance(sys)[0, 0], rel=1e-10)


def test_sample_variance_error_vs_independent_records():
    """ẏ = −y + w sampled every 0.05 over T = 50 (1000 samples), 1000 independent records
    (20 realisations of 50 independent copies): the sample std of their mean squares
    matches the formula within 4 of its standard errors."""
    T, dt, copies = 50.0, 0.05, 50
    many = (-np.eye(copies), np.eye(copies), np.eye(copies))
    mean_squares = []
    with threadpool_limits(limits=1):
        for seed in range(20):
            t, y = realise(many, T - dt, dt, seed=seed)
            mean_squares.extend(np.mean(y**2, axis=0))
    mean_squares = np.array(mean_squares)
    records = len(mean_squares)
    assert len(t) == 1000 and records == 1000
    predicted = cov.sample_variance_error(first_order(1.0), "y", T=T, dt=dt)
    measured = np.std(mean_squares, ddof=1)
    # standard error of a sample std: s·√((k − 1)/(4M)), k the (sample) kurtosis
    kurtosis = scipy.stats.kurtosis(mean_squares, fisher=False)
    se = measured * np.sqrt((kurtosis - 1) / (4 * records))
    assert_close(measured, predicted, rel=4.0, scale=se)  # 4 standard errors
    assert se / predicted < 0.03  # the check has teeth
    # and the mean of the mean squares is the variance 1/2 (within its standard error)
    assert_close(np.mean(mean_squares), 0.5, rel=4.0, scale=measured / np.sqrt(records))


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: cov.output_covariance(control.ss(-1, 1, 1, 1)), "feedthrough"),
        (lambda: cov.output_covariance(control.ss(0.5, 1, 1, 0)), "not asymptotically"),
        (lambda: cov.output_covariance(oscillators([1.0], [0.0])), "not asymptotically"),
        (lambda: cov.output_covariance(first_order(), W=-1.0), "positive semi-definite"),
        (lambda: cov.output_covariance((-np.eye(2), np.eye(2), np.eye(2)), [[1, 0], [1, 1]]), "W"),
        (lambda: cov.output_covariance((np.eye(2), np.eye(3), np.eye(2))), "B must be"),
        (lambda: cov.output_covariance("plant"), "not a state-space"),
        (lambda: cov.mode_contributions(first_order(), "z"), "no output named 'z'"),
        (lambda: cov.mode_contributions(first_order(), 3), "out of range"),
        (lambda: cov.sample_variance_error(first_order(), "y", -1.0), "record length"),
        (lambda: cov.sample_variance_error(first_order(), "y", 1.0, dt=2.0), "dt"),
        (
            lambda: cov.mode_contributions(
                control.ss([[-1, 1], [0, -1]], [[0], [1]], [[1, 0]], 0), 0
            ),
            "defective",
        ),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(Rt70Error, match=match):
        call()


def test_rt70_state_space_is_accepted():
    """rt70's own StateSpace (M q̈ + D q̇ + K q = B u) works as python-control's does."""
    from rt70.linear.responses import state_space

    M, K = np.diag([2.0, 1.0]), np.array([[30.0, -10.0], [-10.0, 10.0]])
    D = 0.02 * K
    ss = state_space(
        M,
        K,
        D,
        np.array([[1.0], [0.0]]),
        np.array([[0.0, 1.0]]),
        input_names=["wind"],
        output_names=["tip"],
    )
    plant = control.ss(ss.A, ss.B, ss.C, ss.D, inputs=["wind"], outputs=["tip"])
    assert_close(cov.output_covariance(ss)[0, 0], cov.output_covariance(plant)[0, 0], rel=1e-14)
    gust = GustFilter(10.0).system
    ours, theirs = (cov.cascade_with_filter(p, gust, "wind") for p in (ss, plant))
    assert ours.output_labels == ["tip"]
    np.testing.assert_array_equal(ours.A, theirs.A)  # the same numbers, copied
    modes = cov.mode_contributions(ss, "tip")
    shares = [m.share for m in modes]
    assert len(modes) == 2
    assert_close(sum(shares), 1.0, rel=1e-12, scale=np.abs(shares).sum())


def _two_channels(a=3.0, b=0.7):
    """Two independent first-order channels y1 = 1/(s+a) w1, y2 = 1/(s+b) w2."""
    return control.ss(
        np.diag([-a, -b]), np.eye(2), np.eye(2), 0, inputs=["w1", "w2"], outputs=["y1", "y2"]
    )


def test_vector_output_sample_variance_error():
    """|y|² of independent channels: the variances of their mean squares add."""
    sys, T = _two_channels(), 50.0
    one = [cov.sample_variance_error(sys, y, T) for y in ("y1", "y2")]
    both = cov.sample_variance_error(sys, ["y1", "y2"], T)
    assert_close(both, np.hypot(*one), rel=1e-12)
    sampled = [cov.sample_variance_error(sys, y, T, dt=0.01) for y in ("y1", "y2")]
    both_sampled = cov.sample_variance_error(sys, ["y1", "y2"], T, dt=0.01)
    assert_close(both_sampled, np.hypot(*sampled), rel=1e-12)
    # one channel named twice: |y|² = 2 y1², its standard deviation doubles
    assert_close(cov.sample_variance_error(sys, ["y1", "y1"], T), 2 * one[0], rel=1e-12)


def test_vector_output_mode_contributions_add():
    """The split of E|y|² is the sum of the components' splits, mode by mode."""
    sys = _transformed(oscillators([0.5, 5.0], [0.02, 0.05], gains=[1.0, 3.0]))
    sys = control.ss(sys.A, sys.B, np.vstack([sys.C, 2.0 * sys.C[::-1] + 0.1]), 0,
                     outputs=["y", "z"])  # fmt: skip
    y, z, yz = (cov.mode_contributions(sys, o) for o in ("y", "z", ["y", "z"]))
    for a, b, c in zip(y, z, yz, strict=True):
        assert_close(c.variance, a.variance + b.variance, rel=1e-10)
    total = np.trace(cov.output_covariance(sys))
    assert_close(sum(m.variance for m in yz), total, rel=1e-12)
