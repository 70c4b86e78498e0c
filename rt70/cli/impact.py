"""``rt70 impact``: brakes and stow pins engaging suddenly (companion source 004 (15)).

Its own module, as ``rt70 pointing``'s (rt70/cli/pointing.py). The impact:
:mod:`rt70.physics.impact`, the locks: :mod:`rt70.mechanics.locks`, the engagement after a
simulation and its energy audit: :mod:`rt70.mechanics.engagement` (docs: 'Impacts',
docs/impacts.md).
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from rt70.cli import options
from rt70.errors import Rt70Error

#: Where the state comes from (``--state``).
STATES = ("start", "rest", "random")

#: Coordinates listed in the text output at most (the largest velocity changes).
SHOWN = 12
#: Joints whose reaction impulses the text output lists (the largest).
SHOWN_JOINTS = 6


def _rate(text: str) -> tuple[str, float]:
    """``COORD=VALUE``: a coordinate's velocity, rad/s or m/s."""
    name, sep, value = text.partition("=")
    if not sep or not name:
        raise argparse.ArgumentTypeError(f"'{text}' is not COORD=VALUE")
    return name, options.physical_float(value)


def add_parser(sub) -> argparse.ArgumentParser:
    """The ``impact`` subcommand."""
    imp = sub.add_parser(
        "impact",
        help="a brake or stow pin engaging suddenly: post-impact velocities, impulses, energy lost",
        description="Engage brakes (a 1-DOF joint held) and stow pins (a point of a link "
        "fixed to the ground) at once, and solve the impact (15) of companion source 004 "
        "on both sides: the textbook's KKT solve against Pinocchio's impulseDynamics. "
        "Prints the post-impact velocities, the impulses and the energy lost (Carnot); "
        "with --after T the scene is first simulated T seconds and the energy audit is "
        "carried across the event (docs: 'Impacts', docs/impacts.md).",
    )
    imp.add_argument("scene", metavar="SCENE", help="scene name or URDF path")
    imp.add_argument(
        "--brake", action="append", default=[], metavar="JOINT", help="brake a 1-DOF joint"
    )
    imp.add_argument(
        "--pin",
        action="append",
        default=[],
        metavar="LINK:x,y,z",
        help="fix the point x,y,z (link frame, m; default its origin) of LINK to the ground",
    )
    imp.add_argument(
        "--restitution",
        type=options.non_negative_float,
        default=0.0,
        metavar="E",
        help="restitution e in [0, 1] (default 0: plastic, a brake or a pin)",
    )
    imp.add_argument(
        "--state",
        choices=STATES,
        default="start",
        help="the state before: start (rt70 simulate's start state: the listing's for "
        "rt70, rest otherwise; default), rest, or random (validate's, --seed)",
    )
    imp.add_argument("--seed", type=options.seed, default=0, help="seed of --state random")
    imp.add_argument(
        "--rate",
        type=_rate,
        action="append",
        default=[],
        metavar="COORD=VALUE",
        help="set a coordinate's velocity before the impact (rad/s or m/s), repeatable",
    )
    imp.add_argument(
        "--after",
        type=options.positive_float,
        metavar="T",
        help="simulate T seconds from the state first (Pinocchio, BDF, rtol 1e-8) and "
        "report the energy audit across the engagement",
    )
    imp.add_argument("--json", action="store_true", help="print JSON")
    imp.set_defaults(func=run)
    return imp


def _locks(args: argparse.Namespace) -> list[tuple[str, object]]:
    """The locks asked for, each with the option that asked for it (``--pin b:0,0,1``)."""
    from rt70.mechanics.locks import Brake, parse_pin

    if not args.brake and not args.pin:
        raise Rt70Error("impact: give at least one --brake JOINT or --pin LINK:x,y,z")
    if args.restitution > 1.0:
        raise Rt70Error(f"--restitution {args.restitution:g}: must lie in [0, 1]")
    locks: list[tuple[str, object]] = [(f"--brake {j}", Brake(j)) for j in args.brake]
    for text in args.pin:
        with options.option_at_fault(f"--pin {text}"):
            locks.append((f"--pin {text}", parse_pin(text)))
    return locks


def _check_locks(scene, locks: list[tuple[str, object]]) -> list:
    """Check each lock against the scene, naming its option; return the locks."""
    from rt70.mechanics.locks import check_locks
    from rt70.model.scene import require_coordinates

    require_coordinates(scene)
    for option, lock in locks:
        with options.option_at_fault(option):
            check_locks(scene, [lock])
    return [lock for _, lock in locks]


def _state(scene, args: argparse.Namespace) -> tuple[np.ndarray, np.ndarray]:
    from rt70.crosscheck.samples import random_state
    from rt70.scenes.rt70_state import start_state

    n = scene.textbook.nv
    if args.state == "random":
        q, qd = random_state(n, np.random.default_rng(args.seed))
    else:
        start = start_state(scene) if args.state == "start" else None
        q, qd = (np.zeros(n), np.zeros(n)) if start is None else start
    qd = np.array(qd, dtype=float)
    names = list(scene.textbook.coordinate_names)
    for name, value in args.rate:
        if name not in names:
            raise Rt70Error(
                f"{scene.path}: --rate {name}=…: no coordinate '{name}' "
                f"(coordinates: {', '.join(names)[:200]})"
            )
        qd[names.index(name)] = value
    return np.asarray(q, dtype=float), qd


def run(args: argparse.Namespace) -> int:
    """Check the options, the scene and the locks; solve on both sides; print."""
    from rt70.mechanics.locks import engage, joint_impulses
    from rt70.model.scene import load_scene

    asked = _locks(args)  # options first
    scene = load_scene(args.scene)
    locks = _check_locks(scene, asked)
    q, qd = _state(scene, args)
    audit = None
    if args.after is not None:
        from rt70.mechanics.engagement import engage_after

        result, impact, audit = engage_after(scene, (q, qd), args.after, locks, args.restitution)
        q, qd = result.q[-1], result.qd[-1]
    else:
        impact = engage(scene, q, qd, locks, "textbook", args.restitution)
    ref = engage(scene, q, qd, locks, "reference", args.restitution)
    shock = joint_impulses(scene, q, impact, locks, "textbook")  # (16), bearing shock loads
    shock_ref = joint_impulses(scene, q, ref, locks, "reference")
    out = _report(scene, q, locks, (impact, shock), (ref, shock_ref))
    if audit is not None:
        out["audit"] = audit.to_dict()
    options.check_finite(out, f"{scene.name}: impact")
    if args.json:
        out["units"] = {
            "q": "rad or m (each coordinate's)",
            "qd_before, qd_after": "rad/s or m/s",
            "impulses": "N·s or N·m·s (each lock's row)",
            "joint_impulses": "N·s, N·m·s",
            "kinetic_before, kinetic_after, energy_lost": "J",
            "max_rel_err_*": "1",
        }
        print(json.dumps(out, indent=2))
        return 0
    _print_text(args, out, (impact, ref), shock, audit)
    return 0


def _report(scene, q: np.ndarray, locks: list, textbook: tuple, reference: tuple) -> dict:
    """The JSON-ready result: the textbook's impact, the reference side's and their differences.

    ``textbook`` and ``reference`` are each side's ``(Impact, joint impulses)``.
    """
    from rt70.mechanics.locks import labels

    (impact, shock), (ref, shock_ref) = textbook, reference
    err_j = _relative(
        np.concatenate(list(shock.values())), np.concatenate(list(shock_ref.values()))
    )
    return {
        "scene": scene.name,
        "locks": labels(locks),  # one label per impulse (a lock given twice: twice)
        "restitution": impact.restitution,
        "coordinates": list(scene.textbook.coordinate_names),
        "q": q.tolist(),
        "qd_before": impact.qd_before.tolist(),
        "qd_after": impact.qd_after.tolist(),
        "impulses": impact.impulses.tolist(),  # in the order of "locks"
        "rank": impact.rank,
        "kinetic_before": impact.kinetic_before,
        "kinetic_after": impact.kinetic_after,
        "energy_lost": impact.energy_lost,
        "carnot": impact.carnot,
        "balance": impact.balance,
        "reference": {
            "qd_after": ref.qd_after.tolist(),
            "impulses": ref.impulses.tolist(),
            "max_rel_err_qd_after": _relative(impact.qd_after, ref.qd_after),
            "max_rel_err_impulses": _relative(impact.impulses, ref.impulses),
            "max_rel_err_joint_impulses": err_j,
        },
        "joint_impulses": {k: v.tolist() for k, v in shock.items()},  # [F; M], joint axes
    }


def _print_text(args: argparse.Namespace, out: dict, impacts: tuple, shock: dict, audit) -> None:
    """The text output: impulses, the largest velocity changes, energies, joint impulses.

    ``impacts`` is ``(textbook Impact, Pinocchio's Impact)``; ``shock`` the textbook's
    joint impulses; ``audit`` the energy audit across the engagement (``--after``) or None.
    """
    impact, ref = impacts
    names, locks = out["coordinates"], out["locks"]
    print(
        f"{out['scene']}: {', '.join(locks)} engage (e = {impact.restitution:g}, "
        f"{impact.rank} independent row(s))"
        + (f" after {args.after:g} s" if args.after is not None else "")
    )
    print("  impulses (N·s, N·m·s; pins in ground axes):")
    for name, a, b in zip(locks, impact.impulses, ref.impulses, strict=True):
        print(f"    {name:<28} {a:>16.9g}   (reference {b:.9g})")
    change = np.abs(impact.qd_after - impact.qd_before)
    shown = sorted(np.argsort(-change, kind="stable")[:SHOWN])
    which = "all" if len(names) <= SHOWN else f"the {SHOWN} largest changes"
    print(f"  velocities (rad/s, m/s), {which}:")
    for i in shown:
        print(f"    {names[i]:<28} {impact.qd_before[i]:>14.6g} → {impact.qd_after[i]:>14.6g}")
    print(
        f"  kinetic energy {impact.kinetic_before:.9g} J → {impact.kinetic_after:.9g} J; "
        f"lost {impact.energy_lost:.9g} J (Carnot ½Δq̇ᵀAΔq̇ = {impact.carnot:.9g} J); "
        f"balance {impact.balance:.3g} J"
    )
    print("  joint reaction impulses (16), the largest (joint axes; N·s, N·m·s):")
    size = {k: float(np.abs(v).max()) for k, v in shock.items()}
    for k in sorted(size, key=size.get, reverse=True)[:SHOWN_JOINTS]:
        F, M = shock[k][:3], shock[k][3:]
        print(f"    {k:<28} |F| {np.linalg.norm(F):>12.6g}   |M| {np.linalg.norm(M):>12.6g}")
    err = out["reference"]
    print(
        "  against Pinocchio (impulseDynamics; rnea for the joints): "
        f"q̇⁺ {err['max_rel_err_qd_after']:.2e}, Λ {err['max_rel_err_impulses']:.2e}, "
        f"joint impulses {err['max_rel_err_joint_impulses']:.2e} relative"
    )
    if audit is not None:
        _print_audit(audit)


def _print_audit(audit) -> None:
    """The energy audit across the engagement (``--after``): each term, the jump, the drift."""
    print(
        f"  energy audit at t = {audit.t:g} s: T {audit.kinetic_before:.9g} → "
        f"{audit.kinetic_after:.9g}, U_g {audit.gravity:.9g}, U_c {audit.elastic:.9g}, "
        f"E_ψ {audit.dissipated:.9g}, W_u {audit.input_work:.9g}, impact "
        f"{audit.impact_lost:.9g} J"
    )
    print(
        f"    total {audit.total_before:.12g} J before, {audit.total_after:.12g} J after "
        f"(jump {audit.jump:.3g} J); simulation drift since t = 0: "
        f"{audit.drift_before:.3g} J"
    )


def _relative(x: np.ndarray, ref: np.ndarray) -> float:
    """``max|x − ref| / max|ref|`` (0 when both vanish)."""
    scale = float(np.max(np.abs(ref), initial=0.0))
    err = float(np.max(np.abs(x - ref), initial=0.0))
    return err / scale if scale > 0.0 else err
