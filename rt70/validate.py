"""Cross-check of the textbook algorithm against Pinocchio: error against run time.

For each scene and each of N random states (q, q̇) both sides compute the same
quantities; every row of the report gives the largest absolute error, the largest
error relative to the reference's max-norm, and the mean wall time per evaluation of
each side.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass

import numpy as np

from rt70.scene import Scene
from rt70.textbook import dynamics, forces

#: Default agreement tolerance, relative to the reference's max-norm.
DEFAULT_TOLERANCE = 1e-10

#: Quantities compared, in report order.
QUANTITIES = (
    "mass_matrix",
    "bias",
    "gravity",
    "spring_force",
    "damper_force",
    "forward_dynamics",
    "kinetic_energy",
    "potential_energy",
)


@dataclass(frozen=True)
class Record:
    """One row of the cross-check report."""

    target: str
    nv: int
    quantity: str
    max_abs_err: float
    max_rel_err: float
    t_textbook_s: float
    t_reference_s: float

    def passed(self, tolerance: float = DEFAULT_TOLERANCE) -> bool:
        """Whether the relative error is within ``tolerance``."""
        return bool(self.max_rel_err <= tolerance)

    def as_dict(self) -> dict:
        """The record as a JSON-ready dict."""
        return asdict(self)


def random_state(nv: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """A random state: ``q`` uniform in ±0.5 (rad or m), ``q̇`` uniform in ±1."""
    return rng.uniform(-0.5, 0.5, nv), rng.uniform(-1.0, 1.0, nv)


def _timed(fn: Callable[[], object], repeat: int) -> tuple[object, float]:
    """Value of ``fn()`` and its mean wall time over ``repeat`` calls after one warm-up."""
    out = fn()
    start = time.perf_counter()
    for _ in range(repeat):
        fn()
    return out, (time.perf_counter() - start) / repeat


def _relative(abs_err: float, scale: float) -> float:
    if scale > 0.0:
        return abs_err / scale
    return 0.0 if abs_err == 0.0 else float("inf")


def _pairs(scene: Scene, q: np.ndarray, qd: np.ndarray) -> dict[str, tuple[Callable, Callable]]:
    """Per quantity: (textbook evaluation, reference evaluation), both in textbook order."""
    tm, td, ref, perm = scene.textbook, scene.textbook_data, scene.reference, scene.perm
    qp, vp = scene.to_reference(q), scene.to_reference(qd)
    ix = np.ix_(perm, perm)

    def tb_forward():
        Qc, Qd = forces.spring_damper_force(tm, td, q, qd)
        return dynamics.forward_dynamics(tm, td, q, qd, Qc + Qd)

    return {
        "mass_matrix": (
            lambda: dynamics.mass_matrix(tm, td, q),
            lambda: ref.mass_matrix(qp)[ix],
        ),
        "bias": (lambda: dynamics.bias_force(tm, td, q, qd), lambda: ref.bias_force(qp, vp)[perm]),
        "gravity": (lambda: dynamics.gravity_force(tm, td, q), lambda: ref.gravity_force(qp)[perm]),
        "spring_force": (
            lambda: forces.spring_damper_force(tm, td, q, qd)[0],
            lambda: ref.spring_damper_force(qp, vp)[0][perm],
        ),
        "damper_force": (
            lambda: forces.spring_damper_force(tm, td, q, qd)[1],
            lambda: ref.spring_damper_force(qp, vp)[1][perm],
        ),
        "forward_dynamics": (tb_forward, lambda: ref.forward_dynamics(qp, vp)[perm]),
        "kinetic_energy": (
            lambda: forces.kinetic_energy(tm, td, q, qd),
            lambda: ref.kinetic_energy(qp, vp),
        ),
        "potential_energy": (
            lambda: forces.gravity_potential(tm, td, q) + forces.spring_potential(tm, td, q),
            lambda: ref.gravity_potential(qp) + ref.spring_potential(qp),
        ),
    }


def cross_check(scene: Scene, samples: int = 10, seed: int = 0, repeat: int = 3) -> list[Record]:
    """Compare every quantity of :data:`QUANTITIES` on ``samples`` random states.

    Each evaluation is timed as the mean of ``repeat`` calls after a warm-up call.
    """
    rng = np.random.default_rng(seed)
    nv = scene.textbook.nv
    abs_err = dict.fromkeys(QUANTITIES, 0.0)
    rel_err = dict.fromkeys(QUANTITIES, 0.0)
    t_tb = dict.fromkeys(QUANTITIES, 0.0)
    t_ref = dict.fromkeys(QUANTITIES, 0.0)
    for _ in range(samples):
        q, qd = random_state(nv, rng)
        for name, (tb_fn, ref_fn) in _pairs(scene, q, qd).items():
            x_tb, dt_tb = _timed(tb_fn, repeat)
            x_ref, dt_ref = _timed(ref_fn, repeat)
            x_tb, x_ref = np.asarray(x_tb, dtype=float), np.asarray(x_ref, dtype=float)
            err = float(np.max(np.abs(x_tb - x_ref))) if x_ref.size else 0.0
            scale = float(np.max(np.abs(x_ref))) if x_ref.size else 0.0
            abs_err[name] = max(abs_err[name], err)
            rel_err[name] = max(rel_err[name], _relative(err, scale))
            t_tb[name] += dt_tb / samples
            t_ref[name] += dt_ref / samples
    return [
        Record(scene.name, nv, name, abs_err[name], rel_err[name], t_tb[name], t_ref[name])
        for name in QUANTITIES
    ]


def format_table(records: Iterable[Record], tolerance: float = DEFAULT_TOLERANCE) -> str:
    """The error-against-run-time table as plain text."""
    header = (
        f"{'target':<26} {'nv':>4} {'quantity':<17} {'max abs err':>11} {'max rel err':>11} "
        f"{'textbook µs':>12} {'pinocchio µs':>12} {'ratio':>7}  ok"
    )
    lines = [header, "-" * len(header)]
    for r in records:
        ratio = r.t_textbook_s / r.t_reference_s if r.t_reference_s > 0 else float("inf")
        lines.append(
            f"{r.target:<26} {r.nv:>4} {r.quantity:<17} {r.max_abs_err:>11.2e} "
            f"{r.max_rel_err:>11.2e} {r.t_textbook_s * 1e6:>12.1f} {r.t_reference_s * 1e6:>12.1f} "
            f"{ratio:>7.1f}  {'yes' if r.passed(tolerance) else 'NO'}"
        )
    return "\n".join(lines)
