"""Reduced RT-70 plants: H∞ error against order for modal and balanced truncation.

The control object of issue 10, ``rt70_servo`` at elevation 45°, azimuth 0
(:mod:`rt70.linear.reduce`):

- **locked**: both axes locked by the drives; inputs a wind-like force on the main
  mirror along ground y and x (kN), outputs the focal offset (mm) and the pointing
  corrections Δα, Δβ (arcsec) — 80 states;
- **free**: the axes free; inputs the axis torques (MN·m), outputs the axis angles
  (arcsec), the focal offset and the pointing corrections — 84 states, the azimuth a
  rigid mode, the elevation a 0.036 Hz pendulum with ζ = 4e-5.

For each plant and order: ``‖G − G_r‖∞`` of modal truncation with static correction
(order 2r for r modes) and of balanced truncation (stable part; the rigid azimuth kept
whole), the bound ``2 Σ`` of the discarded Hankel singular values and ``σ_{k+1}``.
Writes validation/results/plant_reduction.{csv,png} (atomically).
Run: ``python validation/plant_reduction.py`` (about two minutes).
"""

from __future__ import annotations

import argparse
import csv
import io
import sys
import time
from pathlib import Path

import numpy as np

from rt70.errors import Rt70Error
from rt70.guards.atomic import atomic_write_all
from rt70.linear import reduce as rd
from rt70.linear.responses import frequency_response
from rt70.linear.state_space import StateSpace
from rt70.reports.reduction_plants import reduction_plants

OUT = Path(__file__).resolve().parent / "results"
ELEVATION, AZIMUTH = 45.0, 0.0
UNITS = {"locked": "mm or arcsec per kN", "free": "arcsec or mm per MN·m"}
LABELS = {"modal": "modal truncation + static correction", "balanced": "balanced truncation"}
BODE = ("locked", "wind_y", "pointing_correction:1", 8, 16)  # plant, in, out, r, order


def plants() -> dict[str, StateSpace]:
    """The locked and the free plant, in the units of the module docstring."""
    return reduction_plants(ELEVATION, AZIMUTH)


def sweep(name: str, ss: StateSpace, say) -> list[dict]:
    """H∞ errors of both methods over the orders."""
    rows = []
    n_modes = ss.nstates // 2
    for r in [*range(1, 21), *range(22, n_modes, 4)]:
        try:
            red = rd.modal_truncation(ss, r)
        except Rt70Error:
            continue  # fewer modes than the rigid ones
        err = rd.hinf_error(ss, red.ss)
        rows.append(_row(name, red, err, np.nan, np.nan))
    hsv, n_u = rd.hankel_singular_values(ss)
    significant = int(np.sum(hsv > np.finfo(float).eps * hsv[0]))
    for order in range(max(2, n_u), min(ss.nstates, n_u + significant) + 1, 2):
        red = rd.balanced_truncation(ss, order)
        err = rd.hinf_error(ss, red.ss)
        rows.append(_row(name, red, err, red.bound, hsv[order - n_u]))
    say(f"{name}: {len(rows)} reduced plants")
    return rows


def split_floor(ss: StateSpace) -> rd.HinfError:
    """``‖G − (G_s + G_u)‖∞`` of the additive split alone, nothing truncated: the
    numerical floor of the state-space route (Schur form, Sylvester equation)."""
    split = rd.additive_split(ss)
    n_s, n_u = split.A_s.shape[0], split.A_u.shape[0]
    A = np.block([[split.A_s, np.zeros((n_s, n_u))], [np.zeros((n_u, n_s)), split.A_u]])
    whole = StateSpace(
        A,
        np.vstack([split.B_s, split.B_u]),
        np.hstack([split.C_s, split.C_u]),
        split.D,
        states=[f"x{i + 1}" for i in range(A.shape[0])],
        inputs=ss.input_labels,
        outputs=ss.output_labels,
    )
    return rd.hinf_error(ss, whole)


def _row(plant: str, red: rd.Reduction, err: rd.HinfError, bound: float, nxt: float) -> dict:
    return {
        "plant": plant,
        "method": red.method,
        "order": red.order,
        "hinf_error": err.peak,
        "relative": err.relative,
        "peak_hz": err.freq_hz,
        "bound_2sum": bound,
        "hsv_next": nxt,
        "units": UNITS[plant],
    }


def _csv(rows: list[dict]) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: f"{v:.6g}" if isinstance(v, float) else v for k, v in row.items()})
    return buf.getvalue()


def figure(rows: list[dict], full: dict[str, StateSpace], floors: dict[str, rd.HinfError]):
    """Two H∞-vs-order panels and a Bode magnitude overlay."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 3, figsize=(17, 5.2))
    for ax, name in zip(axes[:2], ("locked", "free"), strict=True):
        for method, style in (("modal", "o-"), ("balanced", "s-")):
            sel = [r for r in rows if r["plant"] == name and r["method"] == method]
            ax.semilogy(
                [r["order"] for r in sel],
                [r["hinf_error"] for r in sel],
                style,
                ms=3,
                label=f"{method} truncation"
                + (" + static correction" if method == "modal" else ""),
            )
        sel = [r for r in rows if r["plant"] == name and r["method"] == "balanced"]
        orders = [r["order"] for r in sel]
        ax.semilogy(
            orders,
            [r["bound_2sum"] for r in sel],
            "k--",
            lw=1,
            label=r"bound $2\sum_{i>k}\sigma_i$",
        )
        ax.semilogy(
            orders, [r["hsv_next"] for r in sel], "k:", lw=1, label=r"$\sigma_{k+1}$ (lower bound)"
        )
        ax.axhline(
            floors[name].peak,
            color="grey",
            lw=0.8,
            ls="-.",
            label="numerical floor (split, no truncation)",
        )
        ax.set_xlabel("order of the reduced plant (states)")
        ax.set_ylabel(f"‖G − G_r‖∞ ({UNITS[name]})")
        n = full[name].nstates
        what = "axes locked, wind in" if name == "locked" else "axes free, axis torques in"
        ax.set_title(f"rt70_servo, {what}: {n} states")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    plant, u, y, r, order = BODE
    ss = full[plant]
    j, i = ss.input_labels.index(u), ss.output_labels.index(y)
    f = np.geomspace(0.05, 50.0, 1500)
    ax = axes[2]
    curves = [
        (ss, f"full ({ss.nstates} states)", "k-"),
        (rd.modal_truncation(ss, r).ss, f"modal, {r} modes ({2 * r} states)", "C0--"),
        (rd.balanced_truncation(ss, order).ss, f"balanced, {order} states", "C1:"),
    ]
    for sys_, label, style in curves:
        H = frequency_response(sys_, f).H[:, i, j]
        ax.semilogx(f, 20 * np.log10(np.abs(H)), style, lw=1.3, label=label)
    ax.set_xlabel("frequency (Hz)")
    ax.set_ylabel(f"|{y} / {u}| (dB re 1 arcsec/kN)")
    ax.set_title(f"Bode magnitude, axes locked: {u} → {y}")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.suptitle(
        f"Reduced plants of the RT-70 (rt70_servo, elevation {ELEVATION:g}°, azimuth "
        f"{AZIMUTH:g}°): H∞ error against order"
    )
    fig.tight_layout()
    return fig


def main(argv: list[str] | None = None) -> int:
    """Compute, print a summary and write the CSV and the figure."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    start = time.perf_counter()

    def say(msg: str) -> None:
        print(f"  [{time.perf_counter() - start:6.1f} s] {msg}", file=sys.stderr, flush=True)

    full = plants()
    rows = [row for name, ss in full.items() for row in sweep(name, ss, say)]
    for name in full:
        for method in ("modal", "balanced"):
            sel = [r for r in rows if r["plant"] == name and r["method"] == method]
            for r in sel:
                if r["order"] in (4, 8, 16, 24, 32, 40):
                    print(
                        f"{name:6s} {method:8s} order {r['order']:3d}: ‖G−G_r‖∞ = "
                        f"{r['hinf_error']:.3g} ({r['relative']:.2e} of ‖G‖∞) at "
                        f"{r['peak_hz']:.3g} Hz; bound {r['bound_2sum']:.3g}, "
                        f"σ_k+1 {r['hsv_next']:.3g} [{UNITS[name]}]"
                    )
    floors = {name: split_floor(ss) for name, ss in full.items()}
    for name, fl in floors.items():
        print(
            f"{name:6s} numerical floor (additive split, nothing truncated): {fl.peak:.3g} "
            f"({fl.relative:.2e} of ‖G‖∞) at {fl.freq_hz:.3g} Hz [{UNITS[name]}]"
        )
    fig = figure(rows, full, floors)
    OUT.mkdir(parents=True, exist_ok=True)
    paths = atomic_write_all(
        {
            OUT / "plant_reduction.csv": lambda tmp: tmp.write_text(_csv(rows)),
            OUT / "plant_reduction.png": lambda tmp: fig.savefig(tmp, dpi=110, format="png"),
        }
    )
    for path in paths:
        print(f"wrote {path}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
