"""Stress families of scale: long chains (size), unit systems, a free-floating structure.

Long elastic chains check the textbook side against Pinocchio and the structured
algorithm against the dense one as nv grows; the RT-70 in three unit systems checks
mechanical similarity; a free-floating chain checks the conservation of momentum and
angular momentum.
"""

from __future__ import annotations

import time

import numpy as np
import scipy
import scipy.linalg

from rt70.crosscheck.samples import random_state
from rt70.model.scene import Scene, load_scene, scene_from_text
from rt70.reports.stress.edits import convert_units, free_floating_text, rt70_text
from rt70.reports.stress.measures import (
    condition_number,
    cross_check_error,
    frequencies_hz,
    momentum_pinocchio,
    momentum_textbook,
    rel_error,
    translational,
)
from rt70.reports.stress.runs import Settings, run_capped
from rt70.reports.stress.tables import SIM_COLUMNS, Table, sim_fields, worst_value
from rt70.scenes.rt70_state import listing_initial_state
from rt70.simulation.simulate import SimulationResult
from rt70.textbook import dynamics, forces, structured

#: Largest nv for which the Pinocchio side is built. Pinocchio 4.1's ``Data`` allocates
#: O(nv³) memory (four nv × nv × nv second-order-derivative tensors, upstream issue
#: stack-of-tasks/pinocchio#2949), and :class:`rt70.reference.ReferenceData` holds two
#: of them: a 100-body elastic chain (nv = 600) peaks at ~15 GB and takes ~1 min to
#: build, a 300-body one (nv = 1800) raises MemoryError.
MAX_PINOCCHIO_NV = 360
#: Largest nv for which the dense textbook bias ``B q̇`` (an nb² loop) is evaluated.
MAX_DENSE_BIAS_NV = 1800


def long_chain_cases(quick: bool = False) -> Table:
    """Elastic chains of 10…1000 bodies: cross-check error against size.

    Parameters
    ----------
    quick : bool, optional
        The quick smoke test's chains (:class:`~rt70.reports.stress.runs.Settings`).
    """
    settings = Settings.make(quick)
    table = _chain_table(settings)
    for n in settings.chains:
        table.rows.append(_chain_row(n, settings))
    _chain_notes(table)
    return table


def _chain_table(settings: Settings) -> Table:
    """The long-chain table's title, introduction and columns."""
    return Table(
        "Long chains: `synthetic.elastic_chain(n)` (6-DOF elastic pairs)",
        "Each chain is checked at one random state (q ±0.5, q̇ ±1, seed 0; three for "
        f"n = 10). Against Pinocchio (`cross_check`) for nv ≤ {MAX_PINOCCHIO_NV}: "
        "Pinocchio 4.1's `Data` holds O(nv³) memory (four nv×nv×nv tensors, "
        "stack-of-tasks/pinocchio#2949) and the reference model builds two of them, so "
        "larger chains cannot be built on this machine (n = 100 peaks at ~15 GB, "
        "n = 300 raises MemoryError). For every n the structured textbook algorithm "
        "(`rt70.textbook.structured`) is checked against the dense one; at n = 1000 "
        "(S is 6000 × 6000) only A and S·G (the dense B q̇ loops over nb² blocks), and "
        "cond(A) is LAPACK's 1-norm estimate. Simulation "
        f"({settings.span:g} s from rest, reference side, BDF) only for "
        f"n ≤ {settings.chain_sim_max}: the implicit method's Jacobian is dense, O(nv³) "
        "per LU factorisation.",
        [
            ("n", "n"),
            ("nv", "nv"),
            ("cond", "cond(A)"),
            ("xerr", "vs Pinocchio: max err"),
            ("xq", "worst quantity"),
            ("xA", "A err"),
            ("xfd", "q̈ err"),
            ("sA", "structured vs dense: A"),
            ("sB", "B q̇"),
            ("sG", "S·G"),
            ("sfd", "q̈"),
            ("sim", "integration"),
            ("steps", "steps"),
            ("drift", "energy drift"),
            ("seconds", "case s"),
        ],
    )


def _chain_row(n: int, settings: Settings) -> dict:
    """One chain of ``n`` bodies: cond(A), against Pinocchio, structured against dense, a run."""
    from rt70.scenes.synthetic import elastic_chain

    start = time.perf_counter()
    scene = scene_from_text(elastic_chain(n), f"elastic_chain_{n}")
    model = scene.textbook
    q, qd = random_state(model.nv, np.random.default_rng(0))
    row: dict = {"n": n, "nv": model.nv}
    cond = condition_number(scene, q)
    row["cond"] = cond if model.nv <= 2000 else f"≈ {cond:.2e}"
    if model.nv <= MAX_PINOCCHIO_NV:
        err, quantity, per = cross_check_error(scene, 3 if n <= 10 else 1)
        row.update(xerr=err, xq=quantity, xA=per["mass_matrix"], xfd=per["forward_dynamics"])
    else:
        row["xerr"] = "not built (memory)"
    row.update(_structured_against_dense(scene, q, qd))
    if n <= settings.chain_sim_max and model.nv <= MAX_PINOCCHIO_NV:
        run = run_capped(
            scene,
            (0.0, settings.span),
            cap_s=settings.cap_s,
            max_evaluations=settings.max_evaluations,
        )
        row.update(sim_fields(run, settings.span))
    else:
        row["sim"] = "skipped (size)"
    row["seconds"] = time.perf_counter() - start
    return row


def _structured_against_dense(scene: Scene, q: np.ndarray, qd: np.ndarray) -> dict:
    """Errors of the structured A, S·G and (up to :data:`MAX_DENSE_BIAS_NV`) B q̇ and q̈.

    Against the dense textbook form at the state ``(q, qd)``: keys ``sA``, ``sG``,
    ``sB``, ``sfd``.
    """
    model, data = scene.textbook, scene.textbook_data
    out = {}
    bdata = structured.BatchData(model, 1)
    A_s = structured.mass_matrix(model, bdata, q)
    A_d = dynamics.mass_matrix(model, data, q)
    out["sA"] = rel_error(A_s, A_d)
    G_s = structured.gravity_force_batch(model, bdata, q[None])[0]
    out["sG"] = rel_error(G_s, dynamics.gravity_force(model, data, q))
    if model.nv <= MAX_DENSE_BIAS_NV:
        b_s = structured.bias_force(model, bdata, q, qd)
        out["sB"] = rel_error(b_s, dynamics.bias_force(model, data, q, qd))
        Qc, Qd = forces.spring_damper_force(model, data, q, qd)
        a_d = dynamics.forward_dynamics(model, data, q, qd, Qc + Qd)
        rhs = G_s + Qc + Qd - b_s
        a_s = scipy.linalg.cho_solve(scipy.linalg.cho_factor(A_s), rhs)
        out["sfd"] = rel_error(a_s, a_d)
    return out


def _chain_notes(table: Table) -> None:
    """The long-chain table's notes."""
    checked = [r for r in table.rows if isinstance(r.get("xerr"), float)]
    if checked:
        table.notes.append(
            "Against Pinocchio, A stays at rounding level ("
            + ", ".join(f"n = {r['n']}: {r['xA']:.1g}" for r in checked)
            + ") while q̈ loses digits as cond(A) grows ("
            + ", ".join(f"n = {r['n']}: {r['xfd']:.1g} at cond {r['cond']:.1g}" for r in checked)
            + "): the error of q̈ is ≈ cond(A)·ε, a property of the problem, not of "
            "either implementation."
        )
    table.notes.append(
        "Structured against dense textbook: A "
        + ", ".join(f"{r['sA']:.1g}" for r in table.rows)
        + " (n = "
        + ", ".join(str(r["n"]) for r in table.rows)
        + "): the two forms of the book's algorithm agree to rounding at every size; q̈ "
        "follows cond(A) as above."
    )
    table.notes.append(
        "The 1000-body chain needed two fixes (see the findings): the URDF reader's cycle "
        "check was cubic in the depth of the tree, and `build_model` recursed once per "
        "body."
    )


def _unit_state(scene: Scene, x: np.ndarray, lam: float) -> np.ndarray:
    out = np.array(x, dtype=float)
    out[..., translational(scene)] *= lam
    return out


def unit_cases(quick: bool = False) -> Table:
    """The same RT-70 in m/kg/s, mm/g/s and m/kgf/s (mechanical similarity, §1).

    Parameters
    ----------
    quick : bool, optional
        The quick smoke test's span and samples (:class:`~rt70.reports.stress.runs.Settings`).
    """
    settings = Settings.make(quick)
    kgf = 9.80665
    systems = [
        ("m, kg, s (SI)", 1.0, 1.0),
        ("mm, g, s", 1e3, 1e3),
        ("m, kgf, s (mass kgf·s²/m)", 1.0, 1.0 / kgf),
    ]
    rtol = 1e-8
    table = _units_table(settings, rtol)
    base = rt70_text()
    grid = np.linspace(0.0, settings.span, 51)
    reference = None
    for label, lam, mu in systems:
        row, got = _unit_run(base, label, lam, mu, settings, rtol, grid)
        if reference is None:
            reference = got
        else:
            row.update(_unit_differences(got, reference))
        table.rows.append(row)
    _units_notes(table, rtol)
    return table


def _units_table(settings: Settings, rtol: float) -> Table:
    """The unit-system table's title, introduction and columns."""
    return Table(
        "Units: the RT-70 in m/kg/s, mm/g/s and m/kgf/s",
        "The same model rewritten by `convert_units` (lengths × λ, masses × μ, inertias "
        "and torsional gains × μλ², translational gains × μ, gravity × λ; time in s), "
        "with the initial state converted likewise. Frequencies: springs-only K and "
        "A at q = 0, compared with SI over all modes (relative to each SI frequency, the "
        f"rigid modes excluded). Trajectories: {settings.span:g} s from the listing's "
        f"state, reference side, BDF, rtol {rtol:g}, on a common grid of 51 times, "
        "converted back to SI and compared per kind of coordinate (lengths, angles) "
        "relative to the largest SI value of that kind. E0: the initial energy "
        "T + U_g + U_c converted back (× 1/(μλ²)).",
        [
            ("system", "units"),
            ("factors", "λ, μ"),
            ("fmax", "f_max Hz"),
            ("df", "freq. rel diff"),
            ("cond", "cond(A)"),
            ("xerr", "cross-check err"),
            ("e0", "E0 rel diff"),
            ("dx", "Δ lengths"),
            ("dphi", "Δ angles"),
            ("sim", "integration"),
            ("nfev", "f evals"),
            ("drift", "energy drift"),
            ("wall", "wall s"),
        ],
    )


def _unit_run(
    base: str,
    label: str,
    lam: float,
    mu: float,
    settings: Settings,
    rtol: float,
    grid: np.ndarray,
) -> tuple[dict, tuple]:
    """The RT-70 in one unit system: its row and (frequencies, SI trajectory, SI E0, mask).

    ``lam`` and ``mu`` are the new length units per metre and mass units per kilogram;
    the trajectory (converted back to SI) is None when the run did not finish.
    """
    text = base if lam == mu == 1.0 else convert_units(base, lam, mu)
    scene = scene_from_text(text, f"rt70_{label.split()[0]}")
    q0, v0 = listing_initial_state(load_scene("rt70"))
    q0, v0 = _unit_state(scene, q0, lam), _unit_state(scene, v0, lam)
    freq = frequencies_hz(scene)
    model, data = scene.textbook, scene.textbook_data
    e0 = (
        dynamics.kinetic_energy(model, data, q0, v0)
        + dynamics.gravity_potential(model, data, q0)
        + forces.spring_potential(model, data, q0)
    ) / (mu * lam**2)
    err, _, _ = cross_check_error(scene, settings.samples)
    run = run_capped(scene, (0.0, settings.span), (q0, v0), rtol=rtol, t_eval=grid)
    row = {
        "system": label,
        "factors": f"{lam:g}, {mu:.6g}",
        "fmax": float(freq[-1]),
        "cond": condition_number(scene, q0),
        "xerr": err,
        **sim_fields(run, settings.span),
    }
    row.pop("steps"), row.pop("rejected")
    mask = translational(scene)
    traj = None
    if run.result is not None:
        traj = np.array(run.result.q, dtype=float)
        traj[:, mask] /= lam
    return row, (freq, traj, e0, mask)


def _unit_differences(got: tuple, reference: tuple) -> dict:
    """A unit system's frequencies, E0 and trajectory against SI's (:func:`_unit_run`)."""
    freq, traj, e0, mask = got
    ref_freq, ref_traj, ref_e0, _ = reference
    elastic = ref_freq > 0
    out = {
        "df": float(np.max(np.abs(freq[elastic] / ref_freq[elastic] - 1.0))),
        "e0": abs(e0 / ref_e0 - 1.0),
    }
    if traj is not None and ref_traj is not None:
        out["dx"] = rel_error(traj[:, mask], ref_traj[:, mask])
        out["dphi"] = rel_error(traj[:, ~mask], ref_traj[:, ~mask])
    return out


def _units_notes(table: Table, rtol: float) -> None:
    """The unit-system table's notes."""
    others = table.rows[1:]
    table.notes.append(
        "Frequencies agree to "
        + ", ".join(f"{r['df']:.1g}" for r in others)
        + " (mm/g/s, kgf) — rounding of the converted numbers, far inside 1e-10: "
        "mechanical similarity holds."
    )
    if all(isinstance(r.get("dx"), float) for r in others):
        table.notes.append(
            "Trajectories converted back agree to "
            + ", ".join(f"{r['dx']:.1g} (lengths) / {r['dphi']:.1g} (angles)" for r in others)
            + f", of the order of the integration tolerance rtol = {rtol:g}: the step sequences "
            "differ (the absolute tolerance acts on the numbers in each unit system), the "
            "solution does not."
        )
    table.notes.append(
        "cond(A) depends on the units ("
        + ", ".join(f"{r['system'].split(' (')[0]}: {r['cond']:.3g}" for r in table.rows)
        + "): translations and rotations are scaled differently, so the condition number "
        "of a mixed-coordinate A is not a property of the mechanics alone."
    )


def free_floating_state(scene: Scene, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """A deformed, moving initial state: q ±0.05 (m, rad), q̇ ±0.3 (m/s, rad/s)."""
    rng = np.random.default_rng(seed)
    nv = scene.textbook.nv
    return rng.uniform(-0.05, 0.05, nv), rng.uniform(-0.3, 0.3, nv)


def free_floating_cases(quick: bool = False) -> Table:
    """Momentum and angular momentum of a free-floating structure (no gravity).

    Parameters
    ----------
    quick : bool, optional
        Only the 2-body structure, over the quick span
        (:class:`~rt70.reports.stress.runs.Settings`).
    """
    settings = Settings.make(quick)
    rtol = 1e-10
    table = _floating_table(rtol)
    cases = [(2, settings.floating_span)]
    if not quick:
        cases.append((3, settings.floating_span / 10.0))
    for n, span in cases:
        scene = scene_from_text(free_floating_text(n), f"free_floating_{n}")
        x0 = free_floating_state(scene)
        rigid = int(np.sum(frequencies_hz(scene) == 0.0))
        err, _, _ = cross_check_error(scene, settings.samples)
        for side in ("reference", "textbook"):
            run = run_capped(
                scene,
                (0.0, span),
                x0,
                side=side,
                method="DOP853",
                rtol=rtol,
                cap_s=settings.cap_s,
                max_evaluations=settings.max_evaluations,
            )
            row = {"n": n, "nv": scene.textbook.nv, "side": side, "rigid": rigid}
            row.update(xerr=err, span=span, fmax=float(frequencies_hz(scene)[-1]))
            row.update(sim_fields(run, span))
            if run.result is not None:
                row.update(_momentum_drift(scene, run.result))
            table.rows.append(row)
    _floating_notes(table, rtol)
    return table


def _floating_table(rtol: float) -> Table:
    """The free-floating table's title, introduction and columns."""
    return Table(
        "Free-floating structure: momentum and angular momentum",
        "`free_floating_text(n)`: an elastic chain whose first body is on a URDF "
        "`floating` joint (textbook euler6 pair, Pinocchio free flyer), no ground "
        "bushing, no gravity; only internal springs act, so P and L_O are conserved "
        "((1.75), (1.80)). "
        "From a deformed, moving state (q ±0.05, q̇ ±0.3), DOP853 at rtol "
        f"{rtol:g} (no analytic Jacobian through the free-flyer map, and the system is "
        "not stiff). P and L_O (about the ground origin) from Pinocchio's "
        "`computeCentroidalMomentum` (L_O = L_G + c × P) at every step; the textbook "
        "sum Σ c_k Θ_k V_k gives the same values ('sides' column: largest difference "
        "along the run). Drift: max |X(t) − X(0)| / |X(0)|.",
        [
            ("n", "bodies"),
            ("nv", "nv"),
            ("side", "side"),
            ("span", "span s"),
            ("fmax", "f_max Hz"),
            ("rigid", "rigid modes"),
            ("P0", "|P(0)|"),
            ("L0", "|L_O(0)|"),
            ("dP", "P drift"),
            ("dL", "L_O drift"),
            ("sides", "sides"),
            ("xerr", "cross-check err"),
            *SIM_COLUMNS,
        ],
    )


def _momentum_drift(scene: Scene, res: SimulationResult) -> dict:
    """|P(0)|, |L_O(0)|, their relative drifts along a run, and the two sides' difference."""
    pin_m = [momentum_pinocchio(scene, a, b) for a, b in zip(res.q, res.qd, strict=True)]
    tb_m = [momentum_textbook(scene, a, b) for a, b in zip(res.q, res.qd, strict=True)]
    P = np.array([m[0] for m in pin_m])
    L = np.array([m[1] for m in pin_m])
    out = {"P0": float(np.linalg.norm(P[0])), "L0": float(np.linalg.norm(L[0]))}
    out["dP"] = float(np.max(np.linalg.norm(P - P[0], axis=1))) / out["P0"]
    out["dL"] = float(np.max(np.linalg.norm(L - L[0], axis=1))) / out["L0"]
    P_t = np.array([m[0] for m in tb_m])
    L_t = np.array([m[1] for m in tb_m])
    out["sides"] = max(rel_error(P_t, P), rel_error(L_t, L))
    return out


def _floating_notes(table: Table, rtol: float) -> None:
    """The free-floating table's notes."""
    done = [r for r in table.rows if "dP" in r]
    if done:
        table.notes.append(
            f"P is conserved to {worst_value(done, 'dP'):.1g} and L_O to "
            f"{worst_value(done, 'dL'):.1g} "
            f"(relative) at rtol {rtol:g} on both sides; the energy balance to "
            f"{worst_value(done, 'drift'):.1g}. The two momentum computations (Pinocchio, "
            f"textbook) agree to {worst_value(done, 'sides'):.1g} along the runs."
        )
    table.notes.append(
        "The spring-only stiffness has 6 rigid-body modes (3 translations, 3 rotations "
        "of the whole structure), as it must for a free body."
    )
