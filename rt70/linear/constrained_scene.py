"""Modes of a URDF scene closed by loop constraints: the wiring of :mod:`rt70.linear.constrained`.

A scene with closed chains (``<rt70:loop>``, docs/loops.md) is its tree plus the
closure Φ(q) = 0. Each side computes the closure with its own kinematics:
``loop_residual(model, data, q) → Φ`` and ``loop_jacobian(model, data, q) → B_c`` in
``rt70/textbook/loops.py`` and ``rt70/reference/loops.py``. This module takes those two
functions **as arguments** (any pair with that signature: a hand-written closure of an
existing scene serves as well) and gives what ``rt70 modes`` gives for a tree:

1. the static equilibrium on the manifold
   (:func:`rt70.linear.constrained_equilibrium.equilibrium`),
   with the held coordinates (the RT-70's pointing) added as the linear constraints
   ``q_h = value`` — their multipliers are the torques that hold them, as the drives'
   are in :func:`rt70.linear.linearize.equilibrium`;
2. the full-coordinate M, K and D of :mod:`rt70.linear.linearize` at that state
   (K differenced from ``side``'s static force, M from ``side``, D the textbook's), the
   locked-rotor stiffness of the scene's drives added as ``rt70 modes`` does, the held
   coordinates locked instead when ``lock_held``;
3. the reduced model on the manifold (null space with the multipliers' geometric
   stiffness, or a coordinate partition) and its modes, shapes in the full coordinates;
4. the rows of ``rt70 modes --json`` (:mod:`rt70.linear.mode_table`).

docs/constrained-modes.md; tests/test_constrained_scene.py.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from rt70.errors import Rt70Error
from rt70.linear import constrained as cm
from rt70.linear import constrained_equilibrium, manifold, modal, mode_table
from rt70.linear import linearize as lin
from rt70.linear.damped import damped_modes
from rt70.model.scene import Scene
from rt70.model.sides import side_of

#: A side's loop function: ``(model, data, q) → Φ`` or ``→ B_c``.
LoopFunction = Callable[[Any, Any, np.ndarray], np.ndarray]
#: A side's loop bias: ``(model, data, q, q̇) → C`` with ``B_c q̈ + C = 0``.
BiasFunction = Callable[[Any, Any, np.ndarray, np.ndarray], np.ndarray]

#: How the reduced model is formed (:func:`rt70.linear.constrained.linearize` or
#: :func:`~rt70.linear.constrained.partition_linearize`).
METHODS = ("null-space", "partition")


def scene_constraints(
    scene: Scene,
    loop_residual: LoopFunction,
    loop_jacobian: LoopFunction,
    side: str = "textbook",
    loop_bias: BiasFunction | None = None,
) -> manifold.Constraints:
    """The scene's loop closures on ``side`` as :class:`~rt70.linear.manifold.Constraints`.

    With ``loop_bias`` (``(model, data, q, q̇) → C``, ``B_c q̈ + C = 0``) the geometric
    stiffness is formed exactly from it; without, by differences of the Jacobian.

    Parameters
    ----------
    scene : Scene
        The tree the loops close.
    loop_residual, loop_jacobian : callable
        ``(model, data, q) → Φ``, shape (m,), and ``→ B_c``, shape (m, n), of ``side``.
    side : {"textbook", "reference"}
        Whose model and data the loop functions are called with.
    loop_bias : callable, optional
        ``(model, data, q, q̇) → C``, shape (m,), of ``side``.
    """
    s = side_of(scene, side)
    model, data = s.model, s.data
    bias = None if loop_bias is None else (lambda q, qd: loop_bias(model, data, q, qd))
    return manifold.Constraints(
        residual=lambda q: loop_residual(model, data, q),
        jacobian=lambda q: loop_jacobian(model, data, q),
        bias=bias,
    )


def _static_force(scene: Scene, side: str) -> manifold.Vector:
    return lambda q: lin.static_force(scene, q, side)


def _mass_matrix(scene: Scene, side: str, q: np.ndarray) -> np.ndarray:
    s = side_of(scene, side)
    return s.dynamics.mass_matrix(s.model, s.data, q)


@dataclass(frozen=True)
class SceneConstrainedModel:
    """The linear model of a closed-chain scene about its equilibrium on the manifold.

    Attributes
    ----------
    scene : str
        Scene name.
    coordinates : list of str
        The full (tree) coordinates the shapes are given in.
    equilibrium : rt70.linear.constrained_equilibrium.Equilibrium
        q*, the multipliers (the loop rows first, then the held coordinates').
    M, K, D : ndarray, shape (n, n)
        Full-coordinate mass, stiffness (with the locked rotor's) and damping at q*.
    reduced : rt70.linear.constrained.ConstrainedLinearization
        The model on the manifold.
    loop_rows : int
        Number of loop-closure rows (the first rows of the multipliers).
    held : dict
        Coordinates held at given values while the equilibrium was solved.
    lock_held : bool
        The held coordinates are constraints of the linear model too.
    locked_rotor : bool
        The scene's drives hold their axes through their reducers (rt70 modes' default).
    """

    scene: str
    coordinates: list[str]
    equilibrium: constrained_equilibrium.Equilibrium
    M: np.ndarray
    K: np.ndarray
    D: np.ndarray
    reduced: cm.ConstrainedLinearization
    loop_rows: int
    held: dict = field(default_factory=dict)
    lock_held: bool = False
    locked_rotor: bool = False

    @property
    def q0(self) -> np.ndarray:
        """The state linearised about, q* (as :attr:`rt70.linear.linearize.Linearization.q0`)."""
        return self.equilibrium.q


def constrained_linearize(
    scene: Scene,
    loop_residual: LoopFunction,
    loop_jacobian: LoopFunction,
    held: dict[str, float] | None = None,
    lock_held: bool = False,
    side: str = "textbook",
    method: str = "null-space",
    q_start: np.ndarray | None = None,
    tol: float = 1e-10,
    loop_bias: BiasFunction | None = None,
    descend: bool = False,
) -> SceneConstrainedModel:
    """Equilibrium on the manifold and the reduced linear model of a closed-chain scene.

    Parameters
    ----------
    scene : Scene
        The tree.
    loop_residual, loop_jacobian : callable
        ``(model, data, q) → Φ`` and ``→ B_c`` of ``side`` (the loops of the scene).
    held : dict, optional
        ``{coordinate: value}`` held during the equilibrium (the RT-70's pointing).
    lock_held : bool
        Keep the held coordinates as constraints of the linear model (``--lock-axes``);
        otherwise they are free, and the scene's drives, if any, hold them through their
        reducers (:func:`rt70.linear.linearize.locked_rotor`), as ``rt70 modes`` does.
    side : str
        ``"textbook"`` or ``"reference"``: whose loop functions, static force and mass
        matrix (D is the textbook's on both).
    method : str
        ``"null-space"`` (with the geometric stiffness) or ``"partition"``.
    q_start : array_like, optional
        Start of Newton (default zeros, the held values set).
    tol : float
        Relative tolerance of the equilibrium
        (:func:`rt70.linear.constrained_equilibrium.equilibrium`).
    loop_bias : callable, optional
        ``(model, data, q, q̇) → C`` of ``side``: the geometric stiffness exactly, in
        n(n+1)/2 calls, instead of 2n differenced Jacobians.
    descend : bool
        Look for a stable equilibrium (:func:`rt70.linear.constrained_equilibrium.equilibrium`).

    Raises
    ------
    Rt70Error
        On an unknown side, method or coordinate, no equilibrium, or no motion left.
    """
    if method not in METHODS:
        raise Rt70Error(f"unknown method {method!r} (choose from {', '.join(METHODS)})")
    held = dict(held or {})
    hold_idx = lin.coordinate_indices(scene, list(held))
    loops = scene_constraints(scene, loop_residual, loop_jacobian, side, loop_bias)
    hold = manifold.fixed(len(scene.textbook.coordinate_names), hold_idx, list(held.values()))
    q = _start(scene, q_start, hold_idx, list(held.values()))
    both = manifold.combine(loops, hold) if held else loops
    eq = _scene_equilibrium(scene, side, both, q, tol, descend)
    m_loop = np.atleast_1d(loops.residual(eq.q)).size
    drives = bool(scene.description.drives) and not lock_held
    full, K0 = _full_model(scene, side, eq.q, drives)
    constraints, lam = (both, eq.lam) if lock_held and held else (loops, eq.lam[:m_loop])
    return SceneConstrainedModel(
        scene=scene.name,
        coordinates=list(scene.textbook.coordinate_names),
        equilibrium=eq,
        M=full.M,
        K=full.K,
        D=full.D,
        reduced=_reduce(scene, side, method, constraints, eq.q, lam, full, K0),
        loop_rows=m_loop,
        held=held,
        lock_held=lock_held,
        locked_rotor=drives,
    )


def _start(
    scene: Scene, q_start: np.ndarray | None, hold_idx: np.ndarray, values: list[float]
) -> np.ndarray:
    """Newton's start: ``q_start`` (default zeros) with the held coordinates at their values."""
    n = len(scene.textbook.coordinate_names)
    q = np.zeros(n) if q_start is None else np.array(q_start, dtype=float)
    if q.shape != (n,):
        raise Rt70Error(f"{scene.name}: q_start has shape {q.shape}, the scene has {n} coordinates")
    q[hold_idx] = values
    return q


def _scene_equilibrium(
    scene: Scene,
    side: str,
    constraints: manifold.Constraints,
    q: np.ndarray,
    tol: float,
    descend: bool,
) -> constrained_equilibrium.Equilibrium:
    """The equilibrium on the manifold under ``side``'s static force and stiffness."""
    force = _static_force(scene, side)
    K_of = lambda x: lin.stiffness_matrix(scene, x, side=side)  # noqa: E731
    try:
        return constrained_equilibrium.equilibrium(
            force, constraints, q, stiffness=K_of, tol=tol, descend=descend
        )
    except Rt70Error as exc:
        raise Rt70Error(f"{scene.name}: {exc}") from None


def _full_model(
    scene: Scene, side: str, q: np.ndarray, locked_rotor: bool
) -> tuple[lin.Linearization, np.ndarray]:
    """M, K and D in the tree coordinates at q, and K without the locked rotor's springs.

    K is differenced from ``side``'s static force, M is ``side``'s, D the textbook's; with
    ``locked_rotor`` the scene's drives' reducer springs are added
    (:func:`rt70.linear.linearize.locked_rotor`).
    """
    K0 = lin.stiffness_matrix(scene, q, side=side)
    n = K0.shape[0]
    full = lin.Linearization(
        scene=scene.name,
        q0=q,
        coordinates=list(scene.textbook.coordinate_names),
        M=_mass_matrix(scene, side, q),
        K=K0,
        D=lin.damping_matrix(scene, q),
        K_gravity=np.full((n, n), np.nan),  # not formed: only M, K and D are used
    )
    return (lin.locked_rotor(scene, full) if locked_rotor else full), K0


def _reduce(
    scene: Scene,
    side: str,
    method: str,
    constraints: manifold.Constraints,
    q: np.ndarray,
    lam: np.ndarray,
    full: lin.Linearization,
    K0: np.ndarray,
) -> cm.ConstrainedLinearization:
    """The model on the manifold by ``method`` (:data:`METHODS`) about (q, λ).

    The partition differences the static force, so the locked rotor's springs about q
    (``full.K − K0``) are added to it.
    """
    try:
        if method == "null-space":
            return cm.linearize(constraints, q, lam, full.M, full.K, full.D)
        force = _static_force(scene, side)
        extra = full.K - K0  # the locked rotor's springs about q*
        with_rotor = lambda x: force(x) - extra @ (x - q)  # noqa: E731
        return cm.partition_linearize(with_rotor, constraints, q, full.M, full.D)
    except Rt70Error as exc:
        raise Rt70Error(f"{scene.name}: {exc}") from None


def spectrum(model: SceneConstrainedModel) -> tuple[modal.Modes, np.ndarray, Any, dict]:
    """Modes of the reduced model, shapes, damped modes and the ``constraints`` entry.

    The shapes are in the tree coordinates (``N φ``), the damped modes those of the
    reduced system; ``constraints`` holds the loop rows, their rank at q* (with the held
    coordinates when locked) and the loop multipliers.
    """
    red = model.reduced
    result = cm.modes(red)
    constraints = {
        "loop_rows": model.loop_rows,
        "rank": red.rank,
        "multipliers": model.equilibrium.lam[: model.loop_rows].tolist(),
    }
    return result.modes, result.shapes, damped_modes(red.M_r, red.K_r, red.D_r), constraints


def constrained_modes(model: SceneConstrainedModel) -> dict:
    """The modes of a closed-chain scene in the form ``rt70 modes --json`` prints.

    The keys of ``rt70 modes --json`` (``scene``, ``held``, ``locked_rotor``, ``modes``,
    ``damped``) and ``constraints`` (:func:`spectrum`). The mode shapes are in the full
    tree coordinates (``N φ``) and the dominant coordinate is chosen by kinetic energy in
    them; the damped system is the reduced one.
    """
    modes, shapes, damped, constraints = spectrum(model)
    return {
        "scene": model.scene,
        "held": model.held,
        "locked_rotor": model.locked_rotor,
        "constraints": constraints,
        "modes": mode_table.mode_rows(modes, shapes, model.M, model.coordinates),
        "damped": mode_table.damped_summary(modes, damped),
    }
