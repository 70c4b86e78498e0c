"""Stress families on RT-70 variants: stiffness, mass ratio, gimbal lock, rigid modes.

Each family rewrites the RT-70's URDF (:mod:`rt70.reports.stress.edits`), measures every
variant (:mod:`~rt70.reports.stress.measures`), runs it capped
(:mod:`~rt70.reports.stress.runs`) and returns a :class:`~rt70.reports.stress.tables.Table`
with notes quoting its numbers.
"""

from __future__ import annotations

import math

import numpy as np

from rt70.errors import Rt70Error, SingularConfigurationError
from rt70.model.scene import Scene, load_scene, scene_from_text
from rt70.reports.stress.edits import (
    remove_spring,
    rt70_text,
    scale_link_inertia,
    scale_springs,
    set_spring_entry,
)
from rt70.reports.stress.measures import (
    condition_number,
    cross_check_error,
    frequencies_hz,
    per_body_qdd_error,
    rel_error,
)
from rt70.reports.stress.runs import SIM_RTOL, RunOutcome, Settings, run_capped
from rt70.reports.stress.tables import SIM_COLUMNS, Table, short_error, sim_fields, worst_value
from rt70.scenes.rt70_state import listing_initial_state
from rt70.simulation.backends import BACKENDS
from rt70.textbook import dynamics, forces
from rt70.textbook.spatial import DYNAMICS_GIMBAL_COS, GIMBAL_LOCK_COS, euler_matrix

#: Counterreflector coordinate whose θ is taken to gimbal lock.
GIMBAL_COORDINATE = "counterreflector_ry"
#: Bushing of the counterreflector (its deformation is the pair's [x, y, z, β, θ, α]).
GIMBAL_BUSHING = "rigel_counterreflector"


def rt70_case(text: str, name: str, settings: Settings) -> tuple[Scene, dict, RunOutcome]:
    """Scene, cond(A), f_max, cross-check and a capped run of an RT-70 variant."""
    scene = scene_from_text(text, name)
    q0, v0 = listing_initial_state(scene)
    err, quantity, _ = cross_check_error(scene, settings.samples)
    freq = frequencies_hz(scene)
    run = run_capped(scene, (0.0, settings.span), (q0, v0), cap_s=settings.cap_s)
    row = {
        "cond": condition_number(scene, q0),
        "fmax": float(freq[-1]),
        "xerr": err,
        "xq": quantity,
        **sim_fields(run, settings.span),
    }
    return scene, row, run


def stiffness_cases(quick: bool = False) -> Table:
    """Every spring's stiffness × 10^k; damping × 0 and × 10^k."""
    settings = Settings.make(quick)
    table = Table(
        "Stiffness × 10^k, damping × 0 and × 10^k (RT-70)",
        "Every spring and strut of the RT-70 has its stiffness multiplied by 10^k and its "
        f"damping by 0 or by 10^k. f_max is the highest eigenfrequency of the undeformed "
        f"structure (springs only, q = 0). Simulation: {settings.span:g} s from the "
        f"listing's state, Pinocchio backend, BDF, rtol {SIM_RTOL:g}, cap "
        f"{settings.cap_s:g} s.",
        [
            ("k", "k"),
            ("damping", "damping"),
            ("fmax", "f_max Hz"),
            ("cond", "cond(A)"),
            ("xerr", "cross-check err"),
            ("xq", "worst quantity"),
            *SIM_COLUMNS,
        ],
    )
    base = rt70_text()
    for k in settings.stiffness_k:
        for label, d in (("× 0", 0.0), ("× 10^k", 10.0**k)):
            _, row, _ = rt70_case(scale_springs(base, 10.0**k, d), f"rt70_C1e{k}", settings)
            table.rows.append({"k": k, "damping": label, **row})
    damped = [r for r in table.rows if r["damping"] == "× 10^k"]
    undamped = [r for r in table.rows if r["damping"] == "× 0"]
    f0 = table.rows[0]["fmax"]
    table.notes.append(
        "f_max grows as 10^(k/2) (from "
        + ", ".join(f"{r['fmax']:.4g}" for r in damped)
        + f" Hz; ratio to k = 0: {damped[-1]['fmax'] / f0:.4g}); cond(A) does not depend "
        f"on the springs ({damped[0]['cond']:.3g} at the listing's state)."
    )
    table.notes.append(
        "The cross-check stays at rounding level at every k (worst "
        f"{worst_value(table.rows, 'xerr'):.2g}, relative to the largest entry of each quantity)."
    )
    over = [r for r in undamped if not r["sim"].startswith("ok")]
    finished = [r for r in undamped if r["sim"].startswith("ok")]
    text = (
        "Undamped, the error test makes BDF follow every oscillation of the stiffest "
        "modes (nothing damps them, so they cannot be stepped over)"
    )
    if finished:
        r0 = finished[0]
        per_period = r0["steps"] / (settings.span * r0["fmax"])
        text += (
            f": k = {r0['k']} takes {r0['steps']} steps, {per_period:.0f} per period of "
            f"f_max, and its energy balance drifts by {r0['drift']:.1g}, "
            f"{r0['drift'] / SIM_RTOL:.0f} × rtol (the integration error of the undamped "
            "oscillations accumulates)"
        )
        if over:
            worst = over[-1]
            needed = r0["steps"] * worst["fmax"] / r0["fmax"]
            text += (
                f"; k = {', '.join(str(r['k']) for r in over)} are over the cap (≈ "
                f"{over[0]['steps']} steps reached); k = {worst['k']} would need ≈ "
                f"{needed:.1g} steps"
            )
    elif over:
        text += f"; every run is over the cap (k = {', '.join(str(r['k']) for r in over)})"
    table.notes.append(text + ".")
    done = [r for r in damped if r["sim"].startswith("ok")]
    if done:
        table.notes.append(
            "Damped × 10^k: the stiff modes are overdamped and BDF steps over them; steps "
            + ", ".join(f"k={r['k']}: {r['steps']}" for r in done)
            + f"; worst energy drift {worst_value(done, 'drift'):.2g} (of the energy exchanged)."
        )
    return table


def mass_ratio_cases(quick: bool = False) -> Table:
    """The counterreflector's mass and inertia × 10^−k."""
    settings = Settings.make(quick)
    table = Table(
        "Mass ratio: counterreflector mass and inertia × 10^−k (RT-70)",
        "The counterreflector (2.3 t of a 1.57e6 kg structure) has its mass and inertia "
        "tensor multiplied by 10^−k. Same simulation as above.",
        [
            ("k", "k"),
            ("mass", "m_cr kg"),
            ("ratio", "m_cr / m_total"),
            ("fmax", "f_max Hz"),
            ("cond", "cond(A)"),
            ("xerr", "cross-check err"),
            ("xq", "worst quantity"),
            ("body", "q̈ err per body"),
            *SIM_COLUMNS,
        ],
    )
    base = rt70_text()
    for k in settings.mass_k:
        text = scale_link_inertia(base, "counterreflector", 10.0**-k)
        scene, row, _ = rt70_case(text, f"rt70_m1e-{k}", settings)
        model = scene.textbook
        m = float(model.mass[model.body_names.index("counterreflector")])
        row["body"] = per_body_qdd_error(scene, settings.samples)
        table.rows.append({"k": k, "mass": m, "ratio": m / float(model.mass.sum()), **row})
    first, last = table.rows[0], table.rows[-1]
    table.notes.append(
        f"cond(A) grows from {first['cond']:.3g} to {last['cond']:.3g} "
        f"(factor {last['cond'] / first['cond']:.3g} for a mass factor "
        f"{10.0 ** -last['k']:g}): the light body's rows and columns of A scale with its "
        "mass."
    )
    table.notes.append(
        f"f_max is another body's mode ({first['fmax']:.4g} Hz) until the "
        "counterreflector's own modes overtake it; from there it grows as 10^(k/2) "
        f"(→ {last['fmax']:.4g} Hz), and BDF needs only a few more steps "
        f"({first['steps']} → {last['steps']}): its damping grows relative to its mass, "
        "so the new fast modes are overdamped."
    )
    table.notes.append(
        "The cross-check does not degrade (worst "
        f"{worst_value(table.rows, 'xerr'):.2g}), even per body: 'q̈ err per body' is the "
        "largest error of each body's six accelerations relative to that body's own "
        f"largest |q̈| (worst {worst_value(table.rows, 'body'):.2g}). The ill-conditioning "
        "is a diagonal scaling (one body's rows × 10^−k), to which the Cholesky solve and "
        "ABA are insensitive: cond(A) overstates the error here."
    )
    return table


def _gimbal_states(settings: Settings, scene: Scene):
    q0, v0 = listing_initial_state(scene)
    i = scene.textbook.coordinate_names.index(GIMBAL_COORDINATE)
    for k in settings.gimbal_k:
        q = q0.copy()
        q[i] = np.pi / 2 - 10.0**-k
        yield f"{k}", q, v0, i
    q = q0.copy()
    q[i] = np.pi / 2
    yield "∞", q, v0, i


def gimbal_spring_cases(quick: bool = False) -> Table:
    """The counterreflector's θ = π/2 − 10^−k: spring forces, both sides."""
    settings = Settings.make(quick)
    table = Table(
        "Approach to gimbal lock: spring forces (RT-70)",
        f"The counterreflector's pair angle θ (`{GIMBAL_COORDINATE}`) is set to "
        "π/2 − 10^−k in the listing's state (k = ∞: θ = π/2 exactly); the bushing "
        f"`{GIMBAL_BUSHING}` measures its "
        "deformation with 1–2–3 Euler angles, so its δ is exactly the pair's "
        "[x, y, z, β, θ, α]. Threshold: |cos θ| < GIMBAL_LOCK_COS = "
        f"{GIMBAL_LOCK_COS:g} raises `SingularConfigurationError` on both sides. "
        "cond(ε) is the condition number of the Euler matrix (1.38): the Euler-angle "
        "rates ε⁻¹ω grow as 1/cos θ. Errors: textbook against Pinocchio, relative to "
        "Pinocchio's largest entry.",
        [
            ("k", "k"),
            ("cos", "|cos θ|"),
            ("side", "vs threshold"),
            ("ceps", "cond(ε)"),
            ("springs", "spring forces"),
            ("qc", "Q_c err"),
            ("qd", "Q_d err"),
            ("fd", "q̈ err (dense vs ABA)"),
            ("message", "error message (textbook / Pinocchio)"),
        ],
    )
    from rt70 import reference

    scene = load_scene("rt70")
    model, data = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    for label, q, v, i in _gimbal_states(settings, scene):
        c = abs(math.cos(q[i]))
        row = {
            "k": label,
            "cos": c,
            "side": "above" if c >= GIMBAL_LOCK_COS else "below",
            "ceps": float(np.linalg.cond(euler_matrix(q[i - 1 : i + 2]))),
        }
        messages = []
        try:
            Qc, Qd = forces.spring_damper_force(model, data, q, v)
        except SingularConfigurationError as exc:
            Qc = Qd = None
            messages.append(str(exc))
        try:
            Qc_p, Qd_p = reference.spring_damper_force(ref, rd, q, v)
        except SingularConfigurationError as exc:
            Qc_p = Qd_p = None
            messages.append(str(exc))
        if Qc is not None and Qc_p is not None:
            row.update(springs="computed", qc=rel_error(Qc, Qc_p), qd=rel_error(Qd, Qd_p))
            try:
                a_tb = dynamics.forward_dynamics(model, data, q, v, Qc + Qd)
                row["fd"] = rel_error(a_tb, reference.forward_dynamics(ref, rd, q, v))
            except Rt70Error as exc:
                row["fd"] = short_error(exc)
        elif Qc is None and Qc_p is None:
            row["springs"] = "SingularConfigurationError (both)"
        else:
            row["springs"] = "raised on one side only"
        row["message"] = " / ".join(messages) if messages else None
        table.rows.append(row)
    computed = [r for r in table.rows if r["springs"] == "computed"]
    raised = [r for r in table.rows if r["springs"].startswith("Singular")]
    table.notes.append(
        f"Spring forces are computed for |cos θ| ≥ {GIMBAL_LOCK_COS:g} ("
        + ", ".join(f"k = {r['k']}" for r in computed)
        + ") and raise SingularConfigurationError on both sides below it ("
        + ", ".join(f"k = {r['k']}" for r in raised)
        + "): no value is returned past the threshold."
    )
    if computed:
        table.notes.append(
            "Before the threshold the two sides agree, with an error that grows as the "
            "Euler rates do: Q_c "
            + ", ".join(f"{r['qc']:.1g}" for r in computed)
            + "; Q_d (two factors ε⁻¹: 1/cos²θ) "
            + ", ".join(f"{r['qd']:.1g}" for r in computed)
            + ". β and α are individually ill-conditioned near θ = π/2 (only β ± α is "
            "defined at the lock), so each side's rounding is amplified by ~1/cos θ."
        )
    fd_bad = [r for r in computed if isinstance(r.get("fd"), float) and r["fd"] > 1e-6]
    fd_raised = [r for r in computed if isinstance(r.get("fd"), str)]
    if fd_bad:
        first = fd_bad[0]
        table.summary["fd_bad"] = (first["k"], first["cos"], first["fd"])
        table.notes.append(
            "q̈ (springs included) is another matter: the two sides disagree by "
            f"{first['fd']:.1g} already at k = {first['k']} (|cos θ| = {first['cos']:.0e}) "
            "and by O(1) further on, while the spring forces still agree — the mass matrix "
            "is numerically singular there (next table)"
            + (
                "; the dense textbook path raises Rt70Error only at k = "
                + ", ".join(str(r["k"]) for r in fd_raised)
                if fd_raised
                else ""
            )
            + "."
        )
    return table


def gimbal_mass_matrix_cases(quick: bool = False) -> Table:
    """The singular mass matrix of the euler6 pair near θ = π/2, without the spring."""
    settings = Settings.make(quick)
    table = Table(
        "Approach to gimbal lock: the mass matrix (RT-70 without the counterreflector bushing)",
        "The counterreflector's coordinates are 1–2–3 Euler angles, so its block of A is "
        "built from M = diag(cᵀ, ε) and A is singular at θ = π/2 whether or not a spring "
        f"is attached. Here the bushing `{GIMBAL_BUSHING}` is removed (the counterreflector "
        "falls freely under gravity) so that only the mass matrix can fail. Three "
        "forward-dynamics paths: the dense textbook `dynamics.forward_dynamics` "
        "(Cholesky, raises Rt70Error when it fails), the structured textbook backend and "
        "the Pinocchio (ABA) backend of `rt70.simulation.simulate`. 'spread' is the largest "
        "difference of q̈ between the paths that returned, relative to the largest |q̈|.",
        [
            ("k", "k"),
            ("cos", "|cos θ|"),
            ("cond", "cond(A) textbook"),
            ("condp", "cond(A) Pinocchio"),
            ("dense", "dense textbook"),
            ("structured", "structured backend"),
            ("pinocchio", "Pinocchio backend"),
            ("spread", "q̈ spread"),
            ("qmax", "max |q̈|"),
        ],
    )
    from rt70 import reference

    scene = scene_from_text(remove_spring(rt70_text(), GIMBAL_BUSHING), "rt70_free_cr")
    model, data = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    backends = {name: cls(scene) for name, cls in BACKENDS.items()}
    for label, q, v, i in _gimbal_states(settings, scene):
        row = {"k": label, "cos": abs(math.cos(q[i]))}
        row["cond"] = float(np.linalg.cond(dynamics.mass_matrix(model, data, q)))
        row["condp"] = float(np.linalg.cond(reference.mass_matrix(ref, rd, q)))
        results = {}
        Qc, Qd = forces.spring_damper_force(model, data, q, v)
        try:
            results["dense"] = dynamics.forward_dynamics(model, data, q, v, Qc + Qd)
        except Rt70Error as exc:
            row["dense"] = short_error(exc)
        for key, name in (("structured", "textbook"), ("pinocchio", "pinocchio")):
            try:
                with np.errstate(all="ignore"):
                    results[key] = backends[name].accelerations(q, v, None)[0]
            except (Rt70Error, np.linalg.LinAlgError) as exc:
                row[key] = short_error(exc)
        for key, a in results.items():
            row[key] = "returned" if np.all(np.isfinite(a)) else "returned non-finite"
        if len(results) >= 2:
            values = list(results.values())
            scale = max(float(np.max(np.abs(a))) for a in values)
            row["spread"] = max(
                float(np.max(np.abs(a - b))) / scale
                for n, a in enumerate(values)
                for b in values[n + 1 :]
            )
        if results:
            row["qmax"] = max(float(np.max(np.abs(a))) for a in results.values())
        table.rows.append(row)
    eps = np.finfo(float).eps
    singular = [r for r in table.rows if r["cond"] * eps >= 1.0]
    bad = [r for r in table.rows if isinstance(r.get("spread"), float) and r["spread"] > 1e-6]
    silent = [r["k"] for r in singular if r.get("pinocchio") == "returned"]
    silent_structured = [r["k"] for r in singular if r.get("structured") == "returned"]
    dense_raised = [
        r["k"] for r in table.rows if str(r.get("dense", "")).startswith(("Rt70", "Singular"))
    ]
    exact = table.rows[-1]
    table.summary.update(
        singular=(singular[0]["k"], singular[0]["cos"]) if singular else None,
        spread=(bad[0]["k"], bad[0]["cos"], bad[0]["spread"]) if bad else None,
        silent=silent,
        silent_structured=silent_structured,
        dense_raised=dense_raised,
        exact={key: exact.get(key) for key in ("dense", "structured", "pinocchio")},
    )
    table.summary["refused"] = [
        r["k"]
        for r in table.rows
        if all(
            str(r.get(key, "")).startswith("Singular")
            for key in ("dense", "structured", "pinocchio")
        )
    ]
    text = (
        "cond(A) grows as 1/cos²θ ("
        + ", ".join(f"k = {r['k']}: {r['cond']:.2g}" for r in table.rows)
        + ")"
    )
    if singular:
        text += (
            f": A is numerically singular (cond(A)·ε ≥ 1) from k = {singular[0]['k']} "
            f"(|cos θ| = {singular[0]['cos']:.0e}) on, far above the spring threshold "
            f"{GIMBAL_LOCK_COS:g}"
        )
    table.notes.append(text + ".")
    if bad:
        table.notes.append(
            "The three paths disagree by more than 1e-6 from k = "
            + f"{bad[0]['k']} on (spread "
            + ", ".join(f"{r['k']}: {r['spread']:.1g}" for r in bad)
            + "): q̈ there is rounding noise amplified by cond(A)."
        )
    refused = [
        r["k"]
        for r in table.rows
        if all(
            str(r.get(key, "")).startswith("Singular")
            for key in ("dense", "structured", "pinocchio")
        )
    ]
    table.notes.append(
        f"Every forward-dynamics path refuses a pair within |cos θ| < {DYNAMICS_GIMBAL_COS:g} "
        "of gimbal lock (`rt70.textbook.spatial.DYNAMICS_GIMBAL_COS`, checked by "
        "`dynamics.forward_dynamics` and both backends of `rt70.simulation.simulate`) with "
        "`SingularConfigurationError` naming the pair: k = "
        + (", ".join(refused) or "none")
        + ". Where q̈ is still returned, the paths agree (spread column); no path returns "
        "values past the threshold (Pinocchio-returned rows past it: "
        + (", ".join(silent) or "none")
        + "; structured: "
        + (", ".join(silent_structured) or "none")
        + ")."
    )
    return table


def rigid_mode_cases(quick: bool = False) -> Table:
    """Zero stiffness on a coordinate: rigid-body modes of the RT-70."""
    settings = Settings.make(quick)
    table = Table(
        "Zero stiffness on a coordinate (rigid-body modes, RT-70)",
        "The listing has two zero-stiffness coordinates already: the azimuth bearing "
        "(`ground_platform` rz = 0) and the elevation bearing (the platform–base struts' "
        "rx = 0). The variant also frees the counterreflector's spin (`"
        f"{GIMBAL_BUSHING}` rz stiffness and damping = 0). 'rigid modes': zero "
        "eigenvalues of the springs-only K at q = 0. Simulation as in the stiffness "
        "table.",
        [
            ("case", "case"),
            ("rigid", "rigid modes"),
            ("fmin", "lowest elastic Hz"),
            ("cond", "cond(A)"),
            ("xerr", "cross-check err"),
            ("spin", "counterreflector α(T) − α(0)"),
            *SIM_COLUMNS,
        ],
    )
    base = rt70_text()
    cases = [
        ("RT-70 as listed", base),
        ("+ counterreflector rz free", set_spring_entry(base, GIMBAL_BUSHING, 5, 0.0, 0.0)),
    ]
    for label, text in cases:
        scene, row, run = rt70_case(text, "rt70_rigid", settings)
        freq = frequencies_hz(scene)
        row.update(case=label, rigid=int(np.sum(freq == 0.0)), fmin=float(freq[freq > 0][0]))
        i = scene.textbook.coordinate_names.index("counterreflector_rz")
        if run.result is not None:
            row["spin"] = float(run.result.q[-1, i] - run.result.q[0, i])
        table.rows.append(row)
    table.notes.append(
        "Each zero stiffness adds one rigid-body mode ("
        + " → ".join(str(r["rigid"]) for r in table.rows)
        + "); A is unaffected and the integration is not harder: the freed coordinate is "
        "no longer pulled back (counterreflector α moves by "
        + " → ".join(f"{r['spin']:.2g}" for r in table.rows if "spin" in r)
        + " rad over the run)."
    )
    return table
