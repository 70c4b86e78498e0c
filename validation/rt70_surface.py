"""The RT-70's main mirror surface: gravity homology, wind, Ruze — the numbers and the maps.

The scene ``rt70_mirror`` (the RT-70 control object with its main mirror a 70-m dish,
F = 21 m stated, docs/surface.md) and, on the textbook side only, the same dish with a
finer truss (``--rings``, ``--ribs``; Pinocchio cannot hold its nodes):

- the homology curve: the surface RMS after the best fit against elevation, panels set
  at ``--rigging`` degrees, with its closed-form check (the FE model's own static
  solutions under the weight's components in the dish frame) and Ruze's efficiency at
  22, 86 and 230 GHz;
- the budget: gravity, steady wind and gusts at three elevations and three wind speeds
  (``rt70 pointing``'s surface part, servos closed);
- deformation maps over the aperture after the best fit's removal.

Writes validation/results/rt70_surface.{md,png} and rt70_surface_maps.png.
Run: ``python validation/rt70_surface.py`` (about two minutes).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402

from rt70.guards.atomic import atomic_write_all, atomic_write_text  # noqa: E402
from rt70.model.scene import load_scene  # noqa: E402
from rt70.model.surface_outputs import reflector_surface  # noqa: E402
from rt70.reports.provenance import command_line, headed, run_header  # noqa: E402
from rt70.scenes import rt70_mirror as rm  # noqa: E402
from rt70.surface.best_fit import fit_maps  # noqa: E402
from rt70.telescope.homology import homology  # noqa: E402
from rt70.telescope.pointing import PointingCase, budget_model  # noqa: E402
from rt70.telescope.surface_budget import case_surface  # noqa: E402
from rt70.urdf.modal_file import write_modal_file  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
BANDS_GHZ = (22.0, 86.0, 230.0)
ELEVATIONS = np.arange(10.0, 90.1, 5.0)
BUDGET_ELEVATIONS = (15.0, 45.0, 75.0)
BUDGET_WINDS = (5.0, 10.0, 15.0)


def closed_form(dish, elevations, rigging: float, g: float) -> np.ndarray:
    """The homology RMS (µm) from the FE model's own static solutions, attitude E exactly.

    The weight in the dish frame at elevation E is ``−g (0, cos E, sin E)`` (the RT-70's
    elevation turns the dish about its x axis, z at the zenith at E = 90°); the mirror's
    own sag rotation under gravity (some 0.1° in the listing) is not in it.
    """
    fe = dish.fe
    n = fe.M.shape[0]
    held = np.concatenate([fe.dofs_of(i) for i in dish.hub])
    free = np.setdiff1d(np.arange(n), held)
    lu = spla.splu(fe.K.tocsc()[free][:, free])
    masses = fe.M.diagonal()
    maps = fit_maps(fe.node_xyz[dish.surface], dish.focal_length, dish.weights)
    h = []
    for axis in (1, 2):
        f = np.zeros(n)
        f[axis::3] = -g * masses[axis::3]
        u = np.zeros(n)
        u[free] = lu.solve(f[free])
        h.append(np.sum(maps.H * u.reshape(-1, 3)[dish.surface], axis=1))
    er = np.radians(rigging)
    out = []
    for e in np.radians(elevations):
        r = maps.R @ ((np.cos(e) - np.cos(er)) * h[0] + (np.sin(e) - np.sin(er)) * h[1])
        out.append(1e6 * np.sqrt(maps.weights @ r**2))
    return np.array(out)


def sides_agreement(name: str, states: int = 10) -> tuple[float, float]:
    """Largest relative difference of the surface outputs and of their C between the sides.

    At ``states`` random configurations: rigid coordinates of order 0.1, modal ones of
    0.3 (millimetres at the nodes, as the dish's own weight).
    """
    from rt70.model.outputs import evaluate, output_matrix
    from rt70.model.surface_outputs import surface_outputs

    scene = load_scene(name)
    outs = surface_outputs(reflector_surface(scene))
    rng = np.random.default_rng(20261127)
    worst = 0.0
    for _ in range(states):
        q = rng.normal(0.0, 0.1, scene.textbook.nv)
        for m in scene.textbook.modal:
            q[m.coords] = rng.normal(0.0, 0.3, m.modes)
        a, b = evaluate(scene, q, outs, "textbook"), evaluate(scene, q, outs, "reference")
        worst = max(worst, *(np.abs(a[k] - b[k]).max() / np.abs(a[k]).max() for k in a))
    Ca, Cb = output_matrix(scene, q, outs, "textbook"), output_matrix(scene, q, outs, "reference")
    return worst, float(np.abs(Ca - Cb).max() / np.abs(Ca).max())


def fine_scene(rings: int, ribs: int, directory: Path):
    """The RT-70 mirror scene with a finer dish, written to ``directory`` (textbook side)."""
    body = rm.rt70_mirror_body(rings=rings, ribs=ribs)
    write_modal_file(directory / "fine_dish.npz", body)
    path = directory / "rt70_mirror_fine.urdf"
    atomic_write_text(path, rm.rt70_mirror_scene(body, file="fine_dish.npz"))
    return load_scene(str(path)), rm.rt70_dish(rings=rings, ribs=ribs)


def main(argv: list[str] | None = None) -> int:
    """Compute the curves, the budget and the maps; print and write them."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rigging", type=float, default=45.0, help="rigging elevation, deg")
    parser.add_argument("--rings", type=int, default=4, help="rings of the finer dish")
    parser.add_argument("--ribs", type=int, default=16, help="ribs of the finer dish")
    args = parser.parse_args(argv)
    if not 0.0 <= args.rigging <= 90.0:
        parser.error(f"--rigging {args.rigging}: must lie in [0, 90] degrees")
    if not (1 <= args.rings <= 12 and 3 <= args.ribs <= 64):
        parser.error("--rings must be 1 … 12 and --ribs 3 … 64")
    start = time.perf_counter()
    scene = load_scene("rt70_mirror")
    surface = reflector_surface(scene)
    g = float(np.linalg.norm(scene.description.gravity))
    curves = {"shipped": homology(scene, surface, ELEVATIONS, args.rigging)}
    closed = {"shipped": closed_form(rm.rt70_dish(), ELEVATIONS, args.rigging, g)}
    with tempfile.TemporaryDirectory() as tmp:
        fine, fine_dish = fine_scene(args.rings, args.ribs, Path(tmp))
        curves["fine"] = homology(fine, reflector_surface(fine), ELEVATIONS, args.rigging)
        closed["fine"] = closed_form(fine_dish, ELEVATIONS, args.rigging, g)
        fine_surface = reflector_surface(fine)
    budgets = {}
    for e in BUDGET_ELEVATIONS:
        for v in BUDGET_WINDS:
            model = budget_model(scene, PointingCase(e, 0.0, v))
            budgets[e, v] = case_surface(model, args.rigging, [f * 1e9 for f in BANDS_GHZ])
    names = {
        "shipped": f"shipped dish ({rm.RT70_DISH['rings']} rings × {rm.RT70_DISH['ribs']} "
        f"ribs, {len(surface.nodes)} surface nodes)",
        "fine": f"finer dish ({args.rings} × {args.ribs}, {len(fine_surface.nodes)} surface "
        "nodes, textbook side)",
    }
    lines = [
        f"Panels set at elevation {args.rigging:g}°. Surface RMS (half-path error after the "
        "best-fit paraboloid, area-weighted), µm, and its Ruze efficiency; the closed form "
        "is the FE model's own static solution at the ideal attitude (the difference is "
        "the mirror's own sag rotation in the listing's compliant mount, below).",
        "",
    ]
    for key, curve in curves.items():
        lines += [f"**{names[key]}**", ""]
        lines.append(
            "| elevation, ° | RMS, µm | closed form, µm | ΔF, mm | focus shift y, mm | "
            + " | ".join(f"Ruze {b:g} GHz" for b in BANDS_GHZ)
            + " |"
        )
        lines.append("|---:|---:|---:|---:|---:|" + "---:|" * len(BANDS_GHZ))
        for k, e in enumerate(ELEVATIONS):
            if e % 10 and e != 15.0 and e != 45.0 and e != 75.0:
                continue
            ruze = " | ".join(f"{curve.ruze(b * 1e9)[k]:.3g}" for b in BANDS_GHZ)
            lines.append(
                f"| {e:g} | {curve.rms_um[k]:.1f} | {closed[key][k]:.1f} | "
                f"{curve.focal_change_mm[k]:+.2f} | {curve.focus_shift_mm[k, 1]:+.2f} | {ruze} |"
            )
        diff = np.abs(curve.rms_um - closed[key]) / np.max(closed[key])
        lines += ["", f"Largest |scene − closed form| / max: {diff.max():.2e}.", ""]
    lines += [
        "**Budget of the shipped scene** (servos closed, front wind, gusts by the Davenport "
        "spectrum; `rt70 pointing rt70_mirror --elevation E --wind V --frequency 22 "
        f"--frequency 86 --frequency 230 --rigging-elevation {args.rigging:g}`), µm:",
        "",
        "| elevation, ° | wind, m/s | gravity | steady wind | gust rms | total | "
        + " | ".join(f"Ruze {b:g} GHz" for b in BANDS_GHZ)
        + " |",
        "|---:|---:|---:|---:|---:|---:|" + "---:|" * len(BANDS_GHZ),
    ]
    for (e, v), b in budgets.items():
        ruze = " | ".join(f"{b.ruze[f * 1e9]:.3g}" for f in BANDS_GHZ)
        lines.append(
            f"| {e:g} | {v:g} | {b.gravity_rms_um:.1f} | {b.wind_rms_um:.1f} | "
            f"{b.gust_rms_um:.1f} | {b.total_rms_um:.1f} | {ruze} |"
        )
    lines += [
        "",
        "**Both sides** (10 random states, modal coordinates moving the nodes by mm):",
        "",
    ]
    lines += ["| scene | surface outputs | their C |", "|---|---:|---:|"]
    for name in ("rt70_mirror", "antenna_12m_dish"):
        outputs, rows = sides_agreement(name)
        lines.append(f"| {name} | {outputs:.1e} | {rows:.1e} |")
    table = "\n".join(lines) + "\n"
    print(table)
    fig = curves_figure(curves, closed, names, args.rigging)
    maps = maps_figure(scene, surface, curves["shipped"], budgets, args.rigging)
    page = headed(
        "# The RT-70's main mirror surface\n\nHomology, wind and Ruze of the flexible main "
        "mirror (docs/surface.md); figures: rt70_surface.png, rt70_surface_maps.png.\n\n" + table,
        run_header(command_line()),
    )
    OUT.mkdir(parents=True, exist_ok=True)
    paths = atomic_write_all(
        {
            OUT / "rt70_surface.md": lambda tmp: tmp.write_text(page),
            OUT / "rt70_surface.png": lambda tmp: fig.savefig(tmp, dpi=110, format="png"),
            OUT / "rt70_surface_maps.png": lambda tmp: maps.savefig(tmp, dpi=110, format="png"),
        }
    )
    for path in paths:
        print(f"wrote {path}")
    print(f"total run time {time.perf_counter() - start:.1f} s")
    return 0


def curves_figure(curves, closed, names, rigging):
    """RMS against elevation (both dishes, closed forms dashed) and Ruze against elevation."""
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(12.0, 4.6))
    for key, style in (("shipped", "o-"), ("fine", "s-")):
        ax.plot(ELEVATIONS, curves[key].rms_um, style, label=names[key])
        ax.plot(ELEVATIONS, closed[key], "k--", lw=0.8)
    ax.plot([], [], "k--", lw=0.8, label="closed form (FE model, ideal attitude)")
    ax.axvline(rigging, color="grey", lw=0.8)
    ax.set_xlabel("elevation, °")
    ax.set_ylabel("surface RMS after best fit, µm")
    ax.set_title(f"Gravity homology, panels set at {rigging:g}°")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    for band in BANDS_GHZ:
        bx.plot(ELEVATIONS, curves["shipped"].ruze(band * 1e9), label=f"{band:g} GHz")
    bx.set_xlabel("elevation, °")
    bx.set_ylabel("Ruze efficiency of the surface")
    bx.set_ylim(0.0, 1.02)
    bx.set_title("Ruze efficiency, gravity only (shipped dish)")
    bx.grid(True, alpha=0.3)
    bx.legend()
    fig.tight_layout()
    return fig


def maps_figure(scene, surface, curve, budgets, rigging):
    """The residual over the aperture: gravity at 15°, and the steady wind of 10 m/s at 45°."""
    xy = surface.xyz[:, :2]
    gravity = curve.residual_um[list(ELEVATIONS).index(15.0)]
    fig, axes = plt.subplots(1, 2, figsize=(12.0, 5.2))
    from rt70.model.outputs import evaluate
    from rt70.telescope.surface_budget import PREFIX, budget_surface_outputs

    model = budget_model(scene, PointingCase(45.0, 0.0, 10.0))
    outs = budget_surface_outputs(surface)
    calm, windy = (
        evaluate(scene, q, outs, "reference")[f"{PREFIX}_residual"]
        for q in (model.state.q_calm, model.state.q_wind)
    )
    for ax, values, title in (
        (axes[0], gravity, f"gravity at 15°, panels set at {rigging:g}°"),
        (axes[1], windy - calm, "steady front wind 10 m/s at 45°"),
    ):
        limit = np.abs(values).max()
        levels = np.linspace(-limit, limit, 21)
        t = ax.tricontourf(xy[:, 0], xy[:, 1], values, levels=levels, cmap="RdBu_r")
        ax.plot(xy[:, 0], xy[:, 1], "k.", ms=2)
        ax.set_aspect("equal")
        ax.set_xlabel("x (elevation axis), m")
        ax.set_ylabel("y, m")
        rms = np.sqrt(surface.maps.weights @ values**2)
        ax.set_title(f"{title}\nRMS {rms:.0f} µm (positive: towards the focus)", fontsize=10)
        fig.colorbar(t, ax=ax, label="half-path error after best fit, µm")
    fig.suptitle("RT-70 main mirror: surface error over the aperture (rt70_mirror)")
    fig.tight_layout()
    return fig


if __name__ == "__main__":
    sys.exit(main())
