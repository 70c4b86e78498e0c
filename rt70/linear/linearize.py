"""Static equilibrium and the linear model ``M δq̈ + D δq̇ + K δq = B u`` of a URDF scene.

The linear model is taken on the textbook side at an equilibrium q0 of gravity and
springs (formalism §4.3–§4.4):

- ``M = A(q0)`` (4.79);
- ``K = −∂(Q_g + Q_c)/∂q`` at q0 — the springs' stiffness plus the geometric stiffness
  of gravity — by **central finite differences** of the static forces (step
  ``h = 1e-6`` per coordinate; the truncation error is O(h²) ≈ 1e-12 relative, the
  rounding error O(ε/h) ≈ 1e-10 relative). The differences are taken of the reference
  side's forces (Pinocchio's kinematics, all bushings at once: 0.34 ms a force against
  the textbook side's 2.25 ms on the RT-70), which the cross-check holds equal to the
  textbook's to ~1e-12 relative; ``side="textbook"`` differences the textbook's own
  (tests/test_fast_linearize.py: the two K agree to 1e-8 of max|K|). The tests check
  the gravity part against Pinocchio's analytic ``computeGeneralizedGravityDerivatives``
  and the spring part at rest against the exact ``Σ Jᵀ C J``;
- ``D = −∂Q_d/∂q̇`` at q0 — exact (Q_d is linear in q̇): ``Σ Jᵀ D J`` of the textbook's
  elements, their Jacobians evaluated once.

The equilibrium is the textbook's (its residual is the textbook's static force); the
stiffness only steers Newton's steps.

Coordinates held by drives (for the RT-70 its azimuth and elevation axes,
:func:`rt70.scenes.rt70_state.rt70_pointing`) are given by name: held at given values
while the equilibrium is solved, and locked (removed) or left free in the linear model.

A scene of :data:`rt70.linear.compiled.LARGE_NV` coordinates or more that the compiled
kernels cover takes its static force, M, K, K_gravity and D from them instead
(:mod:`rt70.linear.compiled`: no Pinocchio ``Data``, no dense textbook form); the tests
hold the two paths equal.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from rt70.errors import Rt70Error
from rt70.linear import compiled
from rt70.linear.newton_step import factor
from rt70.model.scene import Scene
from rt70.model.sides import Side, check_side, side_of
from rt70.physics.constraints import HolonomicMap, locking
from rt70.physics.loads import Wrench
from rt70.textbook import dynamics, forces, points

#: Newton in :func:`equilibrium` stops when its step is below this (relative, m or rad).
STEP_TOL = 1e-12

#: Finite-difference step of the stiffness matrix, per coordinate (m or rad).
FD_STEP = 1e-6
#: :func:`equilibrium` keeps its stiffness matrix while each Newton step cuts the force
#: residual at least this much (a factor 10).
REUSE_RATIO = 0.1


def static_force(scene: Scene, q: np.ndarray, side: str = "textbook") -> np.ndarray:
    """Generalised static force ``Q_g + Q_c`` at rest (q̇ = 0), in book coordinates.

    Parameters
    ----------
    scene : Scene
        The scene (both sides built).
    q : numpy.ndarray, shape (nv,)
        Generalised coordinates in the book's order, m or rad.
    side : {"textbook", "reference"}
        Whose forces: the book's (the residual of :func:`equilibrium`) or Pinocchio's.
    """
    return _static_force(side_of(scene, side), q)


def _static_force(s: Side, q: np.ndarray) -> np.ndarray:
    """``Q_g + Q_c`` at rest on the side ``s``."""
    Qc, _ = s.forces.spring_damper_force(s.model, s.data, q, np.zeros(s.model.nv))
    return s.dynamics.gravity_force(s.model, s.data, q) + Qc


def negative_jacobian(force, q: np.ndarray, h: float = FD_STEP) -> np.ndarray:
    """``−∂force/∂q`` by central differences with step h per coordinate, as it is.

    Not symmetrised: a non-conservative force (the wind's, :mod:`rt70.telescope.pointing`) has a
    non-symmetric stiffness.

    Parameters
    ----------
    force : callable
        ``q ↦ Q(q)``, shape (n,): a generalised force, N or N·m per coordinate.
    q : array_like, shape (n,)
        The point, m or rad per coordinate.
    h : float
        The difference step per coordinate, m or rad.
    """
    q = np.asarray(q, dtype=float)
    K = np.empty((q.size, q.size))
    for i in range(q.size):
        e = np.zeros(q.size)
        e[i] = h
        K[:, i] = -(force(q + e) - force(q - e)) / (2.0 * h)
    return K


def _negative_jacobian(force, q: np.ndarray, h: float) -> np.ndarray:
    """``−∂force/∂q`` by central differences with step h per coordinate, symmetrised."""
    K = negative_jacobian(force, q, h)
    return 0.5 * (K + K.T)


def stiffness_matrix(
    scene: Scene, q: np.ndarray, h: float = FD_STEP, side: str = "reference"
) -> np.ndarray:
    """``K = −∂(Q_g + Q_c)/∂q`` by central differences, symmetrised (see module docstring).

    Parameters
    ----------
    scene : Scene
        The scene (both sides built).
    q : array_like, shape (nv,)
        Generalised coordinates in the book's order, m or rad.
    h : float
        The difference step per coordinate, m or rad.
    side : {"reference", "textbook"}
        Whose static forces are differenced: Pinocchio's (fast) or the book's.
    """
    s = side_of(scene, side)
    return _negative_jacobian(lambda x: _static_force(s, x), np.asarray(q, dtype=float), h)


def newton_stiffness(scene: Scene, q: np.ndarray, side: str = "reference") -> np.ndarray:
    """Newton's matrix of the static equilibria: the reference side's ``∂g/∂q + Σ JᵀCJ``.

    :func:`rt70.reference.dynamics.newton_stiffness` where the book's coordinates are
    Pinocchio's own (the RT-70: 1 ms against 27 ms for the differenced K), else
    :func:`stiffness_matrix` on ``side``.

    Parameters
    ----------
    scene : Scene
        The scene (both sides built).
    q : array_like, shape (nv,)
        Generalised coordinates in the book's order, m or rad.
    side : {"reference", "textbook"}
        Whose matrix: the reference side's where it has one, else the differenced K of
        this side's static forces.
    """
    if side == "reference":
        s = side_of(scene, side)
        K = s.dynamics.newton_stiffness(s.model, s.data, np.asarray(q, dtype=float))
        if K is not None:
            return K
    return stiffness_matrix(scene, q, side=side)


def damping_matrix(scene: Scene, q: np.ndarray) -> np.ndarray:
    """``D = −∂Q_d/∂q̇ = Σ Jᵀ D J`` and the modal bodies' ``D_η``, exact.

    Column i of the elements' part is ``−Q_d(q, e_i)``.

    The elements' deformation Jacobians are evaluated once; every column reuses them.
    """
    model, data = scene.textbook, scene.textbook_data
    q = np.asarray(q, dtype=float)
    found = forces.elements(model, data, q)
    D = np.empty((model.nv, model.nv))
    for i in range(model.nv):
        e = np.zeros(model.nv)
        e[i] = 1.0
        Qd = np.zeros(model.nv)
        for el in found:
            el.subtract_jt(model, Qd, el.weighted(el.damping, el.rate(model, e)))
        D[:, i] = -Qd
    for body in model.modal:  # the modal bodies' own D_η
        D[body.coords, body.coords] += body.damping
    return 0.5 * (D + D.T)


def coordinate_indices(scene: Scene, names: list[str] | tuple[str, ...]) -> np.ndarray:
    """Indices of the named textbook coordinates (clear error for an unknown name)."""
    known = scene.textbook.coordinate_names
    missing = [n for n in names if n not in known]
    if missing:
        raise Rt70Error(f"{scene.name}: no coordinate(s) {', '.join(missing)}")
    return np.array([known.index(n) for n in names], dtype=int)


def locking_map(scene: Scene, locked: dict[str, float] | list[str]) -> HolonomicMap:
    """The coordinates held or locked by the drives as a constraint map (chapter 3).

    :func:`rt70.physics.constraints.locking`, with the scene's name in the error for an
    unknown coordinate.
    """
    try:
        return locking(scene.textbook.coordinate_names, locked)
    except Rt70Error as exc:  # the same check, its message with the scene's name
        raise Rt70Error(f"{scene.name}: {exc}") from None


def equilibrium(
    scene: Scene,
    held: dict[str, float] | None = None,
    q_start: np.ndarray | None = None,
    tol: float = 1e-10,
    max_iter: int = 50,
    side: str = "reference",
) -> np.ndarray:
    """Static equilibrium ``Q_g(q) + Q_c(q) = 0`` over the coordinates not held.

    Newton's method with the matrix of :func:`newton_stiffness` (on ``side``; the
    residual is always the textbook's static force). Held
    coordinates (``{name: value}``, the drives) keep their values; their generalised
    force is what the drives must supply. Converged when the force residual is below
    ``tol`` times the force scale (the largest ``|Q_g + Q_c|`` at the start, or 1); the
    rounding floor of the RT-70's stiff springs is about 2e-12 of it, but up to 1.2e-10 at
    some pointings of ``rt70_servo`` (30° elevation: the strut packages' force terms, some
    10⁵ times the residual's scale, cancel): so Newton also stops when its step moves no
    coordinate by more than :data:`STEP_TOL` (relative to the largest ``|q|``, at least 1) —
    the configuration is then fixed to rounding (measured steps there: 1e-14). K is recomputed
    only when the residual fell by less than ``1/REUSE_RATIO`` in the last step (the
    RT-70's sag is small: one K usually suffices).

    Parameters
    ----------
    scene : Scene
        The scene (both sides built).
    held : dict of str to float, optional
        Coordinates held at values, m or rad (the RT-70's azimuth and elevation,
        :func:`rt70.scenes.rt70_state.rt70_pointing`); none by default.
    q_start : array_like, shape (nv,), optional
        Newton's start (default zeros; the held values are set in it).
    tol : float
        Relative tolerance of the force residual (above).
    max_iter : int
        Newton steps allowed.
    side : {"reference", "textbook"}
        Whose static forces the stiffness is differenced from (with "reference", a large
        scene the compiled kernels cover uses them: module docstring).

    Returns
    -------
    numpy.ndarray, shape (nv,)
        The equilibrium, in the book's coordinates.

    Raises
    ------
    Rt70Error
        If the free coordinates have no stiffness against some direction (singular K),
        or Newton does not converge.
    """
    check_side(side)
    hold = locking_map(scene, held or {})
    nv = scene.textbook.nv
    q = np.zeros(nv) if q_start is None else np.array(q_start, dtype=float)
    q = hold.expand(hold.T.T @ q)  # the free values kept, the held ones set
    kernels = compiled.kernels_for(scene) if side == "reference" else None
    if kernels is None:
        force = lambda x: static_force(scene, x)  # noqa: E731
        stiffness = lambda x: newton_stiffness(scene, x, side)  # noqa: E731
    else:  # a large scene: the compiled kernels (rt70.linear.compiled)
        force, stiffness = kernels.static_force, kernels.stiffness_matrix
    return _newton(scene, hold, q, force, stiffness, tol, max_iter)


def _newton(scene: Scene, hold: HolonomicMap, q: np.ndarray, force, stiffness, tol: float,
            max_iter: int) -> np.ndarray:  # fmt: skip
    """:func:`equilibrium`'s Newton iteration with the callables ``force`` and ``stiffness``."""
    Q = force(q)
    scale = max(float(np.max(np.abs(Q))), 1.0)
    solve, previous = None, np.inf
    for _ in range(max_iter):
        residual, size = _free_residual(scene, hold, Q)
        if size <= tol * scale:
            return q
        if solve is not None and size <= REUSE_RATIO * previous:
            previous = size  # the last K still converges fast: keep it (modified Newton)
        else:
            solve, previous = factor(scene.name, hold.reduce_matrix(stiffness(q)), hold.names), size
        step = solve(residual)
        q += hold.expand(step, offset=False)
        if float(np.max(np.abs(step), initial=0.0)) <= STEP_TOL * max(1.0, np.abs(q).max()):
            return q  # the position is fixed to rounding; what is left is the forces' rounding
        Q = force(q)
    raise Rt70Error(f"{scene.name}: static equilibrium not found in {max_iter} Newton steps")


def _free_residual(scene: Scene, hold: HolonomicMap, force: np.ndarray) -> tuple[np.ndarray, float]:
    """The static ``force`` on the free coordinates and its largest magnitude (finite)."""
    with np.errstate(over="ignore", invalid="ignore"):  # checked just below
        residual = hold.reduce_force(force)
    size = float(np.max(np.abs(residual), initial=0.0))
    if not np.isfinite(size):
        raise Rt70Error(
            f"{scene.name}: static equilibrium: the forces are not finite on Newton's "
            "way (a load or a number in the model beyond what its stiffness can hold?)"
        )
    return residual, size


@dataclass
class Linearization:
    """``M δq̈ + D δq̇ + K δq = Q`` about the state ``q0`` of a scene.

    ``coordinates`` names the rows (locked coordinates removed); ``K_gravity`` is the
    geometric-stiffness part of K (K without springs).
    """

    scene: str
    q0: np.ndarray
    coordinates: list[str]
    M: np.ndarray
    K: np.ndarray
    D: np.ndarray
    K_gravity: np.ndarray
    locked: list[str] = field(default_factory=list)


def linearize(
    scene: Scene, q0: np.ndarray, locked: tuple[str, ...] = (), side: str = "reference"
) -> Linearization:
    """The linear model about ``q0``; ``locked`` coordinates are removed (f = 0, §4.1).

    Locking a coordinate of the pair structure is the book's holonomic constraint in 3-D:
    its column of the mobility matrix f is deleted, so its rows and columns of A, K and
    D are deleted — ``Tᵀ M T`` of :func:`locking_map` (:mod:`rt70.physics.constraints`).
    M and D are the textbook's.

    Parameters
    ----------
    scene : Scene
        The scene (both sides built).
    q0 : array_like, shape (nv,)
        The state linearised about (an equilibrium, :func:`equilibrium`), m or rad.
    locked : tuple of str
        Coordinates removed from the model (the drives infinitely stiff).
    side : {"reference", "textbook"}
        Whose static forces K is differenced from (:func:`stiffness_matrix`; with
        "reference", a large scene the compiled kernels cover uses them).
    """
    check_side(side)
    lock = locking_map(scene, list(locked))
    kernels = compiled.kernels_for(scene) if side == "reference" else None
    if kernels is None:
        model, data = scene.textbook, scene.textbook_data
        M, K = dynamics.mass_matrix(model, data, q0), stiffness_matrix(scene, q0, side=side)
        D, K_gravity = damping_matrix(scene, q0), _gravity_stiffness(scene, q0, side=side)
    else:  # a large scene: the compiled kernels (rt70.linear.compiled)
        M, K, D, K_gravity = kernels.matrices(q0)
    return Linearization(
        scene=scene.name,
        q0=np.array(q0, dtype=float),
        coordinates=list(lock.names),
        M=lock.reduce_matrix(M),
        K=lock.reduce_matrix(K),
        D=lock.reduce_matrix(D),
        K_gravity=lock.reduce_matrix(K_gravity),
        locked=list(locked),
    )


def locked_rotor(scene: Scene, lm: Linearization) -> Linearization:
    """The linear model with every scene drive's motor held: the locked-rotor structure.

    A drive (``<rt70:drive>``, formalism §4.5) whose rotor does not turn holds its axis
    through the reducer: the twist ``Δ = θ_d(q) − α_m / i_r`` with α_m fixed adds the
    spring ``C_r g gᵀ`` and the damper ``D_r g gᵀ`` to K and D, with ``g = ∂θ_d/∂q`` at
    q0 (:func:`rt70.textbook.drives.drive_force` at unit torque; for a torque drive g is
    the unit vector of its coordinate). The spectrum of this model is the locked-rotor
    spectrum servo engineers compare (docs/drives.md §3). The geometric stiffness of the
    reducer's static pre-torque through the sector's curvature is left out: K₀ ∂²θ_d/∂q²
    with K₀ ≲ 2·10⁷ N·m and curvature ~1/r² is some 10⁻⁵ of ``C_r``.
    """
    from rt70.textbook.drives import drive_force

    model, data = scene.textbook, scene.textbook_data
    columns = coordinate_indices(scene, lm.coordinates)
    K, D = lm.K.copy(), lm.D.copy()
    for drive in scene.description.drives:
        g = drive_force(model, data, lm.q0, drive)[1][columns]
        K += drive.C_r * np.outer(g, g)
        D += drive.D_r * np.outer(g, g)
    return replace(lm, K=K, D=D)


def _gravity_stiffness(
    scene: Scene, q: np.ndarray, h: float = FD_STEP, side: str = "reference"
) -> np.ndarray:
    """``−∂Q_g/∂q`` by central differences (the geometric stiffness of gravity)."""
    s = side_of(scene, side)
    force = lambda x: s.dynamics.gravity_force(s.model, s.data, x)  # noqa: E731
    return _negative_jacobian(force, np.asarray(q, dtype=float), h)


def force_input(
    lm: Linearization, scene: Scene, link: str, direction, torque: bool = False, xyz=(0, 0, 0)
) -> np.ndarray:
    """Input column of a unit force (or torque) on ``link`` along a ground-axis ``direction``.

    The generalised force of the wrench (:class:`rt70.physics.loads.Wrench`, applied at ``xyz``
    in the link frame) is ``Q_u = S U`` (4.129)–(4.131),
    :func:`rt70.textbook.points.generalized_force`. Rows follow ``lm.coordinates``.

    Parameters
    ----------
    lm : Linearization
        The linear model (its q0 and coordinates).
    scene : Scene
        The scene it was taken of.
    link : str
        The URDF link the load acts on.
    direction : array_like, shape (3,)
        The load's direction in ground axes (normalised here).
    torque : bool
        A unit torque (N·m) instead of a unit force (N).
    xyz : array_like, shape (3,)
        The force's point of application in the link frame, m.

    Returns
    -------
    numpy.ndarray, shape (n,)
        ``Q_u`` of the unit load on each coordinate of ``lm.coordinates`` (N or N·m per
        N, or per N·m for a torque).
    """
    a = np.asarray(direction, dtype=float)
    unit = a / np.linalg.norm(a)
    zero = np.zeros(3)
    wrench = Wrench(link, xyz, force=zero if torque else unit, torque=unit if torque else zero)
    column = points.generalized_force(scene.textbook, scene.textbook_data, lm.q0, wrench)
    keep = coordinate_indices(scene, lm.coordinates)
    return column[keep]


def point_output(lm: Linearization, scene: Scene, link: str, xyz) -> np.ndarray:
    """Output rows (3 × n) of the ground-axis displacement of a point of ``link``.

    ``δr = J_p δq`` about q0 — e.g. the foci and vertices of the mirrors (§4.1.8,
    ``<rt70:optical_point>``).

    Parameters
    ----------
    lm : Linearization
        The linear model (its q0 and coordinates: the columns).
    scene : Scene
        The scene it was taken of.
    link : str
        The URDF link the point is fixed in.
    xyz : array_like, shape (3,)
        The point in the link frame, m.
    """
    Jv, _ = points.point_jacobian(scene.textbook, scene.textbook_data, lm.q0, link, xyz)
    return Jv[:, coordinate_indices(scene, lm.coordinates)]


def rotation_output(lm: Linearization, scene: Scene, link: str) -> np.ndarray:
    """Output rows (3 × n) of the small rotation of ``link`` about the ground axes.

    Parameters
    ----------
    lm : Linearization
        The linear model (its q0 and coordinates: the columns).
    scene : Scene
        The scene it was taken of.
    link : str
        The URDF link.
    """
    _, Jw = points.point_jacobian(scene.textbook, scene.textbook_data, lm.q0, link, np.zeros(3))
    return Jw[:, coordinate_indices(scene, lm.coordinates)]
