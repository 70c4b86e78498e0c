"""Stress families of the approach to gimbal lock on the RT-70: spring forces, mass matrix.

The counterreflector's pair angle θ is taken to π/2 − 10^−k and to π/2 exactly; one
family measures the bushing's spring forces on both sides of the cross-check, the other
the mass matrix of the euler6 pair and the forward dynamics of every path with the
bushing removed. Each returns a :class:`~rt70.reports.stress.tables.Table` with notes
quoting its numbers.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np

from rt70.errors import Rt70Error, SingularConfigurationError
from rt70.model.scene import Scene, load_scene, scene_from_text
from rt70.reports.stress.edits import remove_spring, rt70_text
from rt70.reports.stress.measures import rel_error
from rt70.reports.stress.runs import Settings
from rt70.reports.stress.tables import Table, short_error
from rt70.scenes.rt70_state import listing_initial_state
from rt70.simulation.backends import BACKENDS
from rt70.textbook import dynamics, forces
from rt70.textbook.spatial import DYNAMICS_GIMBAL_COS, GIMBAL_LOCK_COS, euler_matrix

#: Counterreflector coordinate whose θ is taken to gimbal lock.
GIMBAL_COORDINATE = "counterreflector_ry"
#: Bushing of the counterreflector (its deformation is the pair's [x, y, z, β, θ, α]).
GIMBAL_BUSHING = "rigel_counterreflector"
#: The forward-dynamics paths of :func:`gimbal_mass_matrix_cases`.
_PATHS = ("dense", "structured", "pinocchio")


def _gimbal_states(
    settings: Settings, scene: Scene
) -> Iterator[tuple[str, np.ndarray, np.ndarray, int]]:
    """(label k, q, q̇, index of θ): the listing's state with θ = π/2 − 10^−k, then π/2."""
    q0, v0 = listing_initial_state(scene)
    i = scene.textbook.coordinate_names.index(GIMBAL_COORDINATE)
    for k in settings.gimbal_k:
        q = q0.copy()
        q[i] = np.pi / 2 - 10.0**-k
        yield f"{k}", q, v0, i
    q = q0.copy()
    q[i] = np.pi / 2
    yield "∞", q, v0, i


# --- spring forces ---------------------------------------------------------------------


def gimbal_spring_cases(quick: bool = False) -> Table:
    """The counterreflector's θ = π/2 − 10^−k: spring forces, both sides.

    Parameters
    ----------
    quick : bool, optional
        The quick smoke test's k (:class:`~rt70.reports.stress.runs.Settings`).
    """
    settings = Settings.make(quick)
    table = _spring_table()
    scene = load_scene("rt70")
    for label, q, v, i in _gimbal_states(settings, scene):
        table.rows.append(_spring_row(scene, label, q, v, i))
    _spring_notes(table)
    return table


def _spring_table() -> Table:
    """The spring-force table's title, introduction and columns."""
    return Table(
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


def _spring_row(scene: Scene, label: str, q: np.ndarray, v: np.ndarray, i: int) -> dict:
    """One state: the spring forces (1.38) on both sides, then q̈, or who refused them."""
    from rt70 import reference

    model, data = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
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
    return row


def _spring_notes(table: Table) -> None:
    """The spring-force table's notes, and its ``fd_bad`` summary for the findings."""
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


# --- the mass matrix -------------------------------------------------------------------


def gimbal_mass_matrix_cases(quick: bool = False) -> Table:
    """The singular mass matrix of the euler6 pair near θ = π/2, without the spring.

    Parameters
    ----------
    quick : bool, optional
        The quick smoke test's k (:class:`~rt70.reports.stress.runs.Settings`).
    """
    settings = Settings.make(quick)
    table = _mass_matrix_table()
    scene = scene_from_text(remove_spring(rt70_text(), GIMBAL_BUSHING), "rt70_free_cr")
    backends = {side: cls(scene) for side, cls in BACKENDS.items()}
    for label, q, v, i in _gimbal_states(settings, scene):
        table.rows.append(_mass_matrix_row(scene, backends, label, q, v, i))
    _mass_matrix_notes(table, _mass_matrix_summary(table))
    return table


def _mass_matrix_table() -> Table:
    """The mass-matrix table's title, introduction and columns."""
    return Table(
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


def _mass_matrix_row(
    scene: Scene, backends: dict[str, object], label: str, q: np.ndarray, v: np.ndarray, i: int
) -> dict:
    """One state: cond(A) on both sides, q̈ of the three paths and their spread."""
    from rt70 import reference

    model, data = scene.textbook, scene.textbook_data
    ref, rd = scene.reference, scene.reference_data
    row = {"k": label, "cos": abs(math.cos(q[i]))}
    row["cond"] = float(np.linalg.cond(dynamics.mass_matrix(model, data, q)))
    row["condp"] = float(np.linalg.cond(reference.mass_matrix(ref, rd, q)))
    results = {}
    Qc, Qd = forces.spring_damper_force(model, data, q, v)
    try:
        results["dense"] = dynamics.forward_dynamics(model, data, q, v, Qc + Qd)
    except Rt70Error as exc:
        row["dense"] = short_error(exc)
    for key, side in (("structured", "textbook"), ("pinocchio", "reference")):
        try:
            with np.errstate(all="ignore"):
                results[key] = backends[side].accelerations(q, v, None)[0]
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
    return row


def _mass_matrix_summary(table: Table) -> dict:
    """Fill the table's summary for the findings; return it."""
    eps = np.finfo(float).eps
    singular = [r for r in table.rows if r["cond"] * eps >= 1.0]
    bad = [r for r in table.rows if isinstance(r.get("spread"), float) and r["spread"] > 1e-6]
    dense_raised = [
        r["k"] for r in table.rows if str(r.get("dense", "")).startswith(("Rt70", "Singular"))
    ]
    exact = table.rows[-1]
    table.summary.update(
        singular=(singular[0]["k"], singular[0]["cos"]) if singular else None,
        spread=(bad[0]["k"], bad[0]["cos"], bad[0]["spread"]) if bad else None,
        silent=[r["k"] for r in singular if r.get("pinocchio") == "returned"],
        silent_structured=[r["k"] for r in singular if r.get("structured") == "returned"],
        dense_raised=dense_raised,
        exact={key: exact.get(key) for key in _PATHS},
    )
    table.summary["refused"] = [
        r["k"]
        for r in table.rows
        if all(str(r.get(key, "")).startswith("Singular") for key in _PATHS)
    ]
    return table.summary


def _mass_matrix_notes(table: Table, summary: dict) -> None:
    """The mass-matrix table's notes, quoting its summary."""
    eps = np.finfo(float).eps
    singular = [r for r in table.rows if r["cond"] * eps >= 1.0]
    bad = [r for r in table.rows if isinstance(r.get("spread"), float) and r["spread"] > 1e-6]
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
    table.notes.append(
        f"Every forward-dynamics path refuses a pair within |cos θ| < {DYNAMICS_GIMBAL_COS:g} "
        "of gimbal lock (`rt70.textbook.spatial.DYNAMICS_GIMBAL_COS`, checked by "
        "`dynamics.forward_dynamics` and both backends of `rt70.simulation.simulate`) with "
        "`SingularConfigurationError` naming the pair: k = "
        + (", ".join(summary["refused"]) or "none")
        + ". Where q̈ is still returned, the paths agree (spread column); no path returns "
        "values past the threshold (Pinocchio-returned rows past it: "
        + (", ".join(summary["silent"]) or "none")
        + "; structured: "
        + (", ".join(summary["silent_structured"]) or "none")
        + ")."
    )
