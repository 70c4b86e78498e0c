"""Davenport gusts: the spectrum, its shaping filter and exact realisations (rt70.wind.gusts)."""

from __future__ import annotations

import control
import numpy as np
import pytest
import scipy.integrate
import scipy.interpolate
import scipy.linalg
import scipy.signal
from threadpoolctl import threadpool_limits

from rt70.errors import Rt70Error
from rt70.linear.covariance import output_covariance, sample_variance_error
from rt70.testing import MIN_REL, assert_close, close
from rt70.wind import gusts

KAPPA = gusts.DAVENPORT_KAPPA


@pytest.mark.parametrize("speed", [5.0, 15.0])
def test_davenport_variance_is_six_kappa_u_squared(speed):
    """∫ S_u dn = 6 κ U² (σ_u/U = √0.03 = 0.173), integrated numerically in ln n."""
    integral, _ = scipy.integrate.quad(
        lambda ln_n: gusts.davenport_spectrum(np.exp(ln_n), speed) * np.exp(ln_n),
        np.log(1e-9),
        np.log(1e13),
        limit=400,
        epsabs=0.0,
        epsrel=1e-11,
    )
    # the tails beyond the limits hold ≈ 6κU²·(1200e13/U)^(−2/3) < 1e-9 relative, and less
    assert_close(integral, 6 * KAPPA * speed**2, rel=1e-6)
    assert_close(np.sqrt(integral) / speed, 0.1732, rel=3e-4)  # the printed four digits


def test_davenport_form():
    """n·S_u peaks at x = √3 with the value 4κU²·3/4^(4/3); S_u(0) = 0; x = L n/U."""
    U = 10.0
    n_peak = np.sqrt(3) * U / gusts.DAVENPORT_LENGTH
    n = n_peak * np.array([0.99, 1.0, 1.01])
    nS = n * gusts.davenport_spectrum(n, U)
    assert nS[1] > nS[0] and nS[1] > nS[2]
    assert_close(nS[1], 4 * KAPPA * U**2 * 3 / 4 ** (4 / 3), rel=1e-12)
    assert gusts.davenport_spectrum(0.0, U) == 0.0
    # self-similar: n S_u / (κ U²) depends on x = L n / U only
    x = np.logspace(-2, 2, 9)
    n5, n20 = x * 5 / 1200, x * 20 / 600
    a = n5 * gusts.davenport_spectrum(n5, 5.0) / (KAPPA * 25)
    b = n20 * gusts.davenport_spectrum(n20, 20.0, length=600.0) / (KAPPA * 400)
    # each point of the spectrum (four decades) on its own value
    closed = 4 * x**2 / (1 + x**2) ** (4 / 3)
    assert_close(a, closed, rel=1e-13, scale=closed)
    assert_close(a, b, rel=1e-13, scale=np.abs(b))


def test_stored_filter_is_the_fit():
    """Refitting from scratch gives the stored constants (a converged least-squares fit)."""
    gain, zeros, poles, cost = gusts.fit_dimensionless_filter()
    assert_close(gain, gusts.FILTER_GAIN, rel=1e-7)
    # each constant to its own five digits
    assert_close(zeros, gusts.FILTER_ZEROS, rel=1e-5, scale=np.abs(gusts.FILTER_ZEROS))
    assert_close(poles, gusts.FILTER_POLES, rel=1e-5, scale=np.abs(gusts.FILTER_POLES))
    assert_close(cost, 1.4345777808, rel=1e-8)


def test_filter_fit_error():
    """Measured: max |log10 ratio| 0.118 over x ∈ [1e-2, 1e2]; variance −1.41 % (target 5 %)."""
    max_log, variance_error = gusts.filter_fit_errors()
    # the measured values to their printed digits
    assert_close(max_log, 0.11805, rel=4e-4)
    assert_close(variance_error, -0.01408, rel=3.5e-3)
    assert abs(variance_error) <= 0.05
    wide, _ = gusts.filter_fit_errors((1e-3, 1e3))
    assert_close(wide, 0.2071, rel=4.8e-4)


@pytest.mark.parametrize(("speed", "length"), [(5.0, 1200.0), (15.0, 1200.0), (20.0, 600.0)])
def test_filter_scaling(speed, length):
    """The state space (a A₀, √a B₀, √κ U C₀) is √(κUL)·H₀(sL/U): evaluated vs 2|H₀|²."""
    f = gusts.GustFilter(speed, length=length)
    sys = f.system
    assert sys.ninputs == 1 and sys.noutputs == 1 and sys.nstates == 4
    assert np.all(sys.D == 0) and np.all(np.linalg.eigvals(sys.A).real < 0)
    n = np.logspace(-5, 2, 50)
    H = sys.horner(2j * np.pi * n)[0, 0]
    spectrum = f.spectrum(n)  # seven decades of n: each on its own value
    assert_close(2 * np.abs(H) ** 2, spectrum, rel=1e-9, scale=spectrum)
    # the spectrum follows Davenport's within the fit error, at this U and L
    x = length * n / speed
    inside = (x >= 1e-2) & (x <= 1e2)
    ratio = f.spectrum(n[inside]) / gusts.davenport_spectrum(n[inside], speed, length=length)
    assert np.max(np.abs(np.log10(ratio))) <= 0.1181
    assert np.shape(f.spectrum(1.0)) == () and f.spectrum(0.0) == 0.0
    # a zero at s = 0: |H| ∝ ω at low frequency
    h1, h2 = np.abs(sys.horner(2j * np.pi * np.array([1e-9, 1e-8]))[0, 0])
    assert_close(h2 / h1, 10.0, rel=1e-4)
    # variance scales as U² exactly and equals 6κU² within the fit's variance error
    _, variance_error = gusts.filter_fit_errors()
    assert_close(f.variance(), 6 * KAPPA * speed**2 * (1 + variance_error), rel=1e-10)
    assert_close(output_covariance(sys)[0, 0], f.variance(), rel=1e-12)


def test_realise_is_reproducible():
    f = gusts.GustFilter(10.0)
    a = gusts.realise(f, 100.0, 0.1, seed=7)
    b = gusts.realise(f, 100.0, 0.1, seed=7)
    c = gusts.realise(f, 100.0, 0.1, seed=8)
    t, v = a
    np.testing.assert_array_equal(a.v, b.v)  # one seed, one code: the same numbers
    assert not close(a.v, c.v, rel=1e-5)
    assert t.shape == v.shape == (1001,)
    assert_close(t[0] == 0.0 and t[-1], 100.0, rel=1e-14)


@pytest.mark.parametrize("speed", [10.0, 1200.0])
def test_discretisation_is_exact(speed):
    """Φ = e^{AΔt} and Q_d = P − Φ P Φᵀ (stationarity kept), also for Δt ≫ the fastest time
    constant (|λ|Δt up to 5.6e4 at 1200 m/s: plain Van Loan's e^{−AΔt} would overflow)."""
    A, B, C = gusts.GustFilter(speed).matrices()
    P = output_covariance((A, B, np.eye(4)))
    for dt in (0.001, 0.01, 1.0, 100.0):
        Phi, Qd = gusts.discretise(A, B, dt)
        assert_close(Phi, scipy.linalg.expm(A * dt), rel=1e-12, what=f"Φ, Δt = {dt}")
        # P − Φ P Φᵀ cancels: on the scale of P
        assert_close(Qd, P - Phi @ P @ Phi.T, rel=1e-8, scale=np.max(P), what=f"Δt = {dt}")
        assert np.min(np.linalg.eigvalsh(Qd)) >= -1e-12 * np.max(P)
    # small steps: Q_d = B Bᵀ h + (A B Bᵀ + B Bᵀ Aᵀ) h²/2 + (A² B Bᵀ + 2 A B Bᵀ Aᵀ
    # + B Bᵀ Aᵀ²) h³/6 + O(h⁴): entry by entry on the size of its terms, to the next
    # term's relative size ‖A‖h (many entries start at h³: B has one nonzero entry)
    h, BB = 1e-9, B @ B.T
    _, Qd = gusts.discretise(A, B, h)
    series = BB * h + (A @ BB + BB @ A.T) * h**2 / 2
    series = series + (A @ A @ BB + 2 * A @ BB @ A.T + BB @ A.T @ A.T) * h**3 / 6
    a, bb = np.abs(A), np.abs(BB)
    terms = bb * h + (a @ bb + bb @ a.T) * h**2 / 2
    terms = terms + (a @ a @ bb + 2 * a @ bb @ a.T + bb @ a.T @ a.T) * h**3 / 6
    assert_close(Qd, series, rel=4 * np.linalg.norm(A, 2) * h, scale=terms)


def test_realisation_is_stationary_from_the_start():
    """v(0) over 500 seeds: its mean square is the Lyapunov variance within 4σ (x₀ is drawn
    from the stationary P). Single-threaded BLAS: 4 × 4 matrices, 500 calls."""
    f = gusts.GustFilter(1.0, length=1.0)
    with threadpool_limits(limits=1):
        v0 = np.array([gusts.realise(f, 1.0, 1.0, seed=k).v[0] for k in range(500)])
    sigma2 = f.variance()
    # the mean square of 500 independent N(0, σ²) samples has standard deviation σ²·√(2/500)
    assert_close(np.mean(v0**2), sigma2, rel=4 * np.sqrt(2 / 500))  # 4 standard deviations


def test_long_realisation_variance():
    """A 1e5-long record (dimensionless, 1e5 samples): ŝ² vs Lyapunov within 4σ, σ stated."""
    f = gusts.GustFilter(1.0, length=1.0)
    T, dt = 1e5, 1.0
    t, v = gusts.realise(f, T, dt, seed=3)
    sigma2 = f.variance()
    error = sample_variance_error(f.system, "v", T=len(t) * dt, dt=dt)
    assert_close(error / sigma2, 0.004475, rel=1e-3)  # the statistical error: 0.45 %
    assert_close(np.mean(v**2), sigma2, rel=4.0, scale=error)  # 4 standard errors


def test_series_interpolates_like_lsim_and_forced_response():
    """An oscillator driven by a gust record: lsim, forced_response and solve_ivp reading
    GustSeries(t) agree (all interpolate linearly between the samples)."""
    series = gusts.realise(gusts.GustFilter(10.0), 10.0, 0.1, seed=1)
    t, v = series
    w, zeta = 2 * np.pi * 1.0, 0.05
    A = np.array([[0.0, 1.0], [-(w**2), -2 * zeta * w]])
    B = np.array([[0.0], [1.0]])
    C = np.array([[1.0, 0.0]])
    _, y_lsim, _ = scipy.signal.lsim((A, B, C, np.zeros((1, 1))), v, t)
    y_ct = control.forced_response(control.ss(A, B, C, 0), t, v).outputs
    sol = scipy.integrate.solve_ivp(
        lambda time, x: A @ x + B[:, 0] * series(time),
        (t[0], t[-1]),
        np.zeros(2),
        t_eval=t,
        rtol=1e-11,
        atol=1e-13,
        max_step=0.05,
    )
    scale = np.max(np.abs(y_lsim))
    assert_close(y_ct, y_lsim, rel=1e-9)
    assert_close(sol.y[0], y_lsim, rel=1e-7)
    # the check can fail: a zero-order hold between samples is another response
    _, y_zoh, _ = scipy.signal.lsim((A, B, C, np.zeros((1, 1))), v, t, interp=False)
    assert np.max(np.abs(y_zoh - y_lsim)) > 1e-2 * scale
    # between samples: the midpoint is the average; at samples: the samples
    assert_close(series(t[3] + 0.05), 0.5 * (v[3] + v[4]), rel=1e-12, scale=abs(v[3]) + abs(v[4]))
    np.testing.assert_array_equal(series(t[:5]), v[:5])  # at the knots: the samples, copied


def test_smooth_gust_is_the_cubic_spline_through_the_samples():
    """SmoothGust: the samples at the knots, scipy's spline between them (the scalar path in
    plain floats and the array path agree), C² across a knot, one column per output."""
    series = gusts.realise(gusts.GustFilter(10.0), 20.0, 0.1, seed=2)
    gust = series.smooth()
    t, v = series
    scale = np.max(np.abs(v))
    assert_close([gust(float(x)) for x in t], v, rel=MIN_REL, scale=scale)
    inside = np.linspace(0.0, 20.0, 1237)
    assert_close([gust(float(x)) for x in inside], gust(inside), rel=MIN_REL, scale=scale)
    assert_close(gust(inside), scipy.interpolate.CubicSpline(t, v)(inside), rel=MIN_REL,
                 scale=scale)  # fmt: skip
    # between the samples it is not the linear interpolant (the check can fail)
    assert np.max(np.abs(gust(inside) - series(inside))) > 1e-3 * scale
    knot, h = t[57], 1e-7
    for order in (1, 2):
        left, right = gust.spline(knot - h, order), gust.spline(knot + h, order)
        assert_close(left, right, rel=1e-4, scale=np.max(np.abs(gust.spline(inside, order))))
    two = gusts.realise((-np.diag([1.0, 2.0]), np.eye(2), np.eye(2)), 5.0, 0.5, seed=0).smooth()
    assert_close(two(1.3), two(np.array([1.3]))[0], rel=MIN_REL, scale=np.abs(two.series.v).max())
    with pytest.raises(Rt70Error, match="outside the record"):
        gust(20.5)
    with pytest.raises(Rt70Error, match="outside the record"):
        gust(np.array([-1.0, 3.0]))


def test_a_smooth_gust_takes_fewer_steps():
    """An oscillator driven by a record: the implicit method needs fewer evaluations through
    the spline than through the kinks of the linear interpolant (why SmoothGust exists)."""
    series = gusts.realise(gusts.GustFilter(10.0), 30.0, 0.1, seed=1)
    gust = series.smooth()
    w, zeta = 2 * np.pi * 1.0, 0.02
    A = np.array([[0.0, 1.0], [-(w**2), -2 * zeta * w]])
    counts = {}
    for name, u in (("linear", series), ("smooth", gust)):
        rhs = lambda time, x, u=u: A @ x + [0.0, u(time)]  # noqa: E731
        sol = scipy.integrate.solve_ivp(rhs, (0.0, 30.0), np.zeros(2), method="LSODA",
                                        rtol=1e-6, atol=1e-9)  # fmt: skip
        assert sol.success
        counts[name] = sol.nfev
    assert counts["smooth"] < 0.8 * counts["linear"], counts  # measured: 10 038 against 14 517


def test_modal_recursion_equals_steps():
    """The modal lfilter recursion is the plain step-by-step one; a Jordan block (defective
    Φ) takes the plain one and still has the Lyapunov variance."""
    rng = np.random.default_rng(0)
    A, B, _ = gusts_plus_oscillator()
    Phi, _ = gusts.discretise(A, B, 0.1)
    x0, e = rng.standard_normal(6), rng.standard_normal((500, 6))
    modal = gusts._propagate(Phi, x0, e)
    assert_close(modal, gusts._propagate_steps(Phi, x0, e), rel=1e-9)
    jordan = (np.array([[-1.0, 1.0], [0.0, -1.0]]), np.array([[0.0], [1.0]]), np.eye(2))
    t, v = gusts.realise(jordan, 2e4, 0.2, seed=5)
    P = output_covariance(jordan)
    assert_close(np.cov(v.T, bias=True), P, rel=0.05, scale=np.max(P))  # a sample covariance


def gusts_plus_oscillator():
    """A gust filter (U = 10 m/s) before a 1 Hz oscillator: six real and complex modes."""
    A, B, C = gusts.GustFilter(10.0).matrices()
    w = 2 * np.pi
    Ao = np.array([[0.0, 1.0], [-(w**2), -0.2 * w]])
    At = np.block([[A, np.zeros((4, 2))], [np.array([[0.0], [1.0]]) @ C, Ao]])
    return At, np.vstack([B, np.zeros((2, 1))]), np.array([[0, 0, 0, 0, 1.0, 0]])


def test_multi_output_series():
    A = -np.diag([1.0, 2.0])
    series = gusts.realise((A, np.eye(2), np.eye(2)), 5.0, 0.5, seed=0)
    assert series.v.shape == (11, 2)
    assert series(np.array([0.25, 0.75])).shape == (2, 2)
    v0, v1 = series.v[0], series.v[1]
    assert_close(series(0.25), 0.5 * (v0 + v1), rel=MIN_REL, scale=np.abs(v0) + np.abs(v1))


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: gusts.GustFilter(0.0), "wind speed must be positive"),
        (lambda: gusts.GustFilter(float("nan")), "wind speed must be a finite number"),
        (lambda: gusts.GustFilter(10.0, kappa=-1.0), "kappa must be positive"),
        (lambda: gusts.GustFilter("10"), "wind speed must be a finite number"),
        (lambda: gusts.davenport_spectrum(-1.0, 10.0), "frequencies must be finite"),
        (lambda: gusts.GustFilter(10.0).spectrum([np.nan]), "frequencies must be finite"),
        (lambda: gusts.GustFilter(True), "wind speed must be a finite number"),
        (lambda: gusts.realise(gusts.GustFilter(10.0), 10.0, 20.0, 1), "need 0 < dt ≤ t_end"),
        (lambda: gusts.realise(gusts.GustFilter(10.0), 10.0, 0.0, 1), "need 0 < dt ≤ t_end"),
        (lambda: gusts.realise(gusts.GustFilter(10.0), 10.0, 0.1, None), "seed"),
        (lambda: gusts.realise(gusts.GustFilter(10.0), 10.0, 0.1, -3), "seed"),
        (lambda: gusts.realise(control.ss(-1.0, 1.0, 1.0, 1.0), 10.0, 0.1, 0), "feedthrough"),
        (lambda: gusts.realise(control.ss(1.0, 1.0, 1.0, 0.0), 10.0, 0.1, 0), "not asymptot"),
        (lambda: gusts.realise(gusts.GustFilter(10.0), 1.0, 0.5, 0)(1.5), "outside the record"),
    ],
)
def test_bad_input(call, match):
    with pytest.raises(Rt70Error, match=match):
        call()
