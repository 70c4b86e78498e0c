"""The Davenport gust model: the numbers docs/wind-gusts.md quotes.

Prints the spectrum's variance (numerical integration), the shaping filter's fit errors,
its poles at a few wind speeds, the statistical error of a record's mean square, and
one realisation's mean square against the Lyapunov variance. Writes
validation/results/gusts.json and validation/results/gusts_spectrum.png. Run:
``python validation/gusts.py`` (a few seconds).
"""

import argparse
import json
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import scipy.integrate  # noqa: E402

from rt70.guards.atomic import atomic_write, atomic_write_text  # noqa: E402
from rt70.linear.covariance import sample_variance_error  # noqa: E402
from rt70.wind import gusts  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
SPEEDS = (5.0, 10.0, 15.0, 20.0)


def spectrum_variance(speed: float) -> float:
    """∫ S_u dn by quad in ln n (the tails beyond 1e-9…1e13 Hz are < 1e-9 relative)."""
    value, _ = scipy.integrate.quad(
        lambda ln_n: gusts.davenport_spectrum(np.exp(ln_n), speed) * np.exp(ln_n),
        np.log(1e-9),
        np.log(1e13),
        limit=400,
        epsabs=0.0,
        epsrel=1e-11,
    )
    return value


def main(argv: list[str] | None = None) -> None:
    """Compute, print and write the numbers."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    results: dict = {}
    kappa = gusts.DAVENPORT_KAPPA
    var10 = spectrum_variance(10.0)
    results["spectrum_variance_over_kappa_U2"] = var10 / (kappa * 100)
    results["sigma_over_U"] = float(np.sqrt(var10) / 10.0)
    print(f"Davenport: ∫S_u dn / (κU²) = {var10 / (kappa * 100):.9f} (exact 6)")
    print(f"           σ_u/U = {np.sqrt(var10) / 10:.4f} (κ = {kappa})")

    gain, zeros, poles, cost = gusts.fit_dimensionless_filter()
    max_log, var_err = gusts.filter_fit_errors()
    max_log_wide, _ = gusts.filter_fit_errors((1e-3, 1e3))
    results["fit"] = {
        "gain": gain,
        "zeros": list(zeros),
        "poles": list(poles),
        "cost": cost,
        "max_abs_log10_ratio_1e-2_1e2": max_log,
        "max_abs_log10_ratio_1e-3_1e3": max_log_wide,
        "variance_error": var_err,
    }
    print(f"filter H0: gain {gain:.6g}, zeros {np.round(zeros, 6)}, poles {np.round(poles, 6)}")
    print(f"  max |log10(2|H0|²/g)| over x∈[1e-2,1e2]: {max_log:.4f} (factor {10**max_log:.3f})")
    print(f"  max |log10(2|H0|²/g)| over x∈[1e-3,1e3]: {max_log_wide:.4f}")
    print(f"  variance error (Lyapunov vs 6κU²): {100 * var_err:+.2f} %")

    results["speeds"] = {}
    print("U m/s  σ_u m/s (filter)  poles Hz                                   err(ŝ²) 1 h   10 h")
    for U in SPEEDS:
        f = gusts.GustFilter(U)
        pole_hz = np.array(poles) * U / gusts.DAVENPORT_LENGTH / (2 * np.pi)
        err1 = sample_variance_error(f.system, "v", 3600.0) / f.variance()
        err10 = sample_variance_error(f.system, "v", 36000.0) / f.variance()
        results["speeds"][str(U)] = {
            "sigma_filter": float(np.sqrt(f.variance())),
            "sigma_davenport": float(np.sqrt(6 * kappa) * U),
            "poles_hz": pole_hz.tolist(),
            "relative_error_of_mean_square_1h": err1,
            "relative_error_of_mean_square_10h": err10,
        }
        print(
            f"{U:5.1f}  {np.sqrt(f.variance()):.4f} ({np.sqrt(6 * kappa) * U:.4f})"
            f"   {np.array2string(pole_hz, precision=4)}"
            f"   {100 * err1:5.1f} %  {100 * err10:5.1f} %"
        )

    hz = np.array([0.1, 0.5, 1.0, 2.0, 5.0, 10.0])
    results["filter_over_davenport"] = {"n_hz": hz.tolist()}
    print(f"filter/Davenport spectrum ratio at n = {hz.tolist()} Hz:")
    for U in SPEEDS:
        ratio = gusts.GustFilter(U).spectrum(hz) / gusts.davenport_spectrum(hz, U)
        results["filter_over_davenport"][str(U)] = ratio.tolist()
        print(f"  U = {U:4.1f} m/s: {np.array2string(ratio, precision=3)}")

    U, T, dt, seed = 10.0, 36000.0, 0.05, 1
    f = gusts.GustFilter(U)
    start = time.perf_counter()
    t, v = gusts.realise(f, T, dt, seed)
    elapsed = time.perf_counter() - start
    err = sample_variance_error(f.system, "v", T=len(t) * dt, dt=dt)
    ms = float(np.mean(v**2))
    results["realisation"] = {
        "speed": U,
        "T": T,
        "dt": dt,
        "seed": seed,
        "samples": len(t),
        "mean_square": ms,
        "lyapunov": f.variance(),
        "standard_error": err,
        "seconds": elapsed,
    }
    print(
        f"realise(U={U}, T={T:g} s, dt={dt}, seed={seed}): {len(t)} samples in {elapsed:.2f} s; "
        f"ŝ² = {ms:.4f}, Lyapunov {f.variance():.4f} ± {err:.4f} "
        f"({(ms - f.variance()) / err:+.2f} σ)"
    )

    OUT.mkdir(exist_ok=True)
    atomic_write_text(OUT / "gusts.json", json.dumps(results, indent=2) + "\n")
    n = np.logspace(-5, 1, 400)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for U in (5.0, 20.0):
        f = gusts.GustFilter(U)
        ax.loglog(n, n * gusts.davenport_spectrum(n, U), label=f"Davenport, U = {U:g} m/s")
        ax.loglog(n, n * f.spectrum(n), "--", label=f"order-4 filter, U = {U:g} m/s")
    ax.set_xlabel("frequency n (Hz)")
    ax.set_ylabel("n·S_u(n) (m²/s²)")
    ax.set_ylim(1e-3, 10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    atomic_write(OUT / "gusts_spectrum.png", lambda p: fig.savefig(p, dpi=110, format="png"))
    print(f"wrote {OUT / 'gusts.json'} and {OUT / 'gusts_spectrum.png'}")


if __name__ == "__main__":
    main()
