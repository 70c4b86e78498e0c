"""Servo scenarios on the scene's own drives: one servo per ``<rt70:drive>``, encoders on the axes.

One job: a drive factory for :func:`rt70.telescope.scenarios.run_scenario` that closes the servo
cascade around the drives the scene itself declares (``<rt70:drive>``,
docs/urdf-extensions.md) instead of torques on the axis coordinates
(:func:`rt70.telescope.scenarios.servo_drives`), optionally with the book's dry friction on both
axes (:class:`rt70.control.friction.AxisFriction`).

- **Drives.** Each ``<rt70:drive>`` becomes a
  :class:`rt70.control.antiwindup.BackCalculationServo` with the element's parameters
  (:func:`rt70.control.drives.drive_parameters`) whose reducer acts through
  :class:`rt70.model.couplings.SceneCoupling`: on ``rt70_servo`` the azimuth drive is a torque
  on ``platform_rz`` (4.143) and the elevation drive a force ``K / r`` on the
  counterweight through its gear sector (r = 16 m), along the mesh angle θ_d (4.150).
- **Encoders.** The position loop reads the axis coordinate (``platform_rz``,
  ``base_rx``: the joint of the drive), not θ_d: a telescope's encoder sits on the axis,
  and the sector's compliance lies between the two (θ_d − base_rx = −45″ of sag at 45°).
- **Limits.** The scene lumps an axis's two motors in *parallel* (one voltage: L_a, R_a
  halved, c_m, c_e per motor, J_m doubled); :func:`rt70.telescope.scenarios.drive_parameters`
  lumps them in series. The limits are taken from the table so that the axis-referred
  torque limit is the same, n × peak × i_r = 9.81·10⁷ N·m, whatever the lumping: current
  limit ``n T_peak / c_m`` (:func:`scene_axis_gains`), voltage limit the rated voltage
  times ``c_e / c_e,motor`` (the lumped back-EMF constant scales with the lumped voltage).
- **Start.** The static equilibrium with the drives' own forces: the encoders held at the
  pointing, the other coordinates free, and the unknown holding torques K_d of the
  drives, ``Q_g(q) + Q_c(q) + Σ_d K_d ∂θ_d/∂q = 0`` (:func:`scene_equilibrium`); the
  sector's force has components on ``base_y``, ``base_z`` and ``counterweight_y``
  besides ``base_rx``, so the coordinate equilibrium would start with a transient.
- **Friction.** :class:`~rt70.control.friction.AxisFriction` on each driven axis coordinate
  (the book's figures are axis-referred), the linear zone of width 10⁻⁶ of top speed
  chosen in docs/drive-train.md §2.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.antiwindup import BackCalculationServo
from rt70.control.drives import drive_parameters
from rt70.control.friction import AxisFriction
from rt70.control.servo import CascadeGains, cascade_gains
from rt70.errors import Rt70Error
from rt70.linear.linearize import STEP_TOL, equilibrium, static_force, stiffness_matrix
from rt70.model.antenna import mount_of
from rt70.model.couplings import SceneCoupling
from rt70.model.scene import Scene
from rt70.model.sides import check_side
from rt70.scenes.rt70_drives import DRIVES, FRICTION, AxisDrive
from rt70.simulation.states import StateComponent
from rt70.telescope.servo_tuning import (
    AXIS_TUNING,
    EQUILIBRIUM_TOL,
    preset_servo_state,
    servo_drives,
    servo_tolerances,
)


def axis_tables(scene: Scene) -> dict[str, AxisDrive]:
    """The drive table of each axis of the scene's ``<rt70:mount>``, by the joint it turns."""
    return {a.joint: DRIVES[a.name] for a in mount_of(scene).axes}


#: Friction regularisation (docs/drive-train.md §2: ``rt70.reports.drivetrain``).
FRICTION_WIDTH = 1e-6 * FRICTION.top_speed
FRICTION_KIND = "linear"
#: Absolute tolerance of the friction's dissipated heat, J.
FRICTION_ATOL = 1e-3
#: Newton steps of :func:`scene_equilibrium` at most.
MAX_ITER = 30


def scene_axis_gains(
    p: DriveParameters, axis: AxisDrive, position_hz: float, ratio: float
) -> CascadeGains:
    """The cascade of a scene drive with the table's limits, whatever the motors' lumping.

    Current limit ``n T_peak / c_m`` and voltage limit ``U_n c_e / c_e,motor``: the
    axis-referred torque limit is ``n T_peak i_r`` (9.81·10⁷ N·m for the RT-70) and the
    top voltage the rated one per motor, for parallel (the scene's) or series
    (:func:`rt70.telescope.scenarios.drive_parameters`) lumping alike.

    Parameters
    ----------
    p : DriveParameters
        The scene drive's lumped parameters (:func:`rt70.control.drives.drive_parameters`).
    axis : AxisDrive
        The RT-70 table's axis it drives (:func:`axis_tables`): the limits and reference inertia.
    position_hz : float
        Bandwidth of the position loop, Hz.
    ratio : float
        Ratio of the position loop's proportional to integral corner
        (:func:`rt70.control.servo.cascade_gains`).
    """
    m, n = axis.motor, axis.motors_per_axis
    return cascade_gains(
        p,
        axis.reference_inertia,
        position_hz=position_hz,
        ratio=ratio,
        current_limit=n * m.peak_torque / p.c_m,
        rate_limit=axis.servo.rate_limit,
        voltage_limit=m.rated_voltage * p.c_e / m.back_emf_constant,
    )


def scene_equilibrium(
    scene: Scene,
    couplings: list[SceneCoupling],
    held: dict[str, float],
    tol: float = EQUILIBRIUM_TOL,
    load: Callable[[np.ndarray], np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray, float]:
    """Static equilibrium held by the scene's drives, encoders at ``held``.

    Solves ``R(q, K) = Q_g(q) + Q_c(q) + Q_l(q) + Σ_d K_d ∂θ_d/∂q = 0`` for the coordinates not
    held and the drives' reducer torques K_d (one per coupling): n equations, n unknowns
    when each held coordinate is a drive's joint. Newton's method with the stiffness
    matrix (:func:`rt70.linear.linearize.stiffness_matrix`) and the columns ∂θ_d/∂q for
    the K_d, leaving out the term ``K_d ∂²θ_d/∂q²`` (the sector's geometric stiffness,
    some 10⁻⁴ of the structure's: it slows the convergence, not the answer). ``Q_l`` is
    an external static load; its stiffness is left out of Newton's matrix likewise.

    Parameters
    ----------
    scene : Scene
        A scene with ``<rt70:drive>`` elements.
    couplings : list of SceneCoupling
        The drives' couplings to the structure (:meth:`SceneServoFactory.couplings`).
    held : dict of str to float
        The encoders' readings: each driven joint's coordinate, rad.
    tol : float
        Convergence: ``max |R|`` relative to the force scale (below).
    load : callable q -> Q_l, optional
        An external static generalised force, shape (nv,), N·m or N (a steady wind's);
        default none.

    Returns
    -------
    q : numpy.ndarray
        The configuration.
    torques : numpy.ndarray
        K_d, N·m on θ_d, in the order of ``couplings``.
    residual : float
        ``max |R|`` relative to the static force of the undeformed structure (the
        weights: the scale of :func:`rt70.linear.linearize.equilibrium`). Newton also
        stops, as there, when its step moves no coordinate by more than ``STEP_TOL``.

    Raises
    ------
    Rt70Error
        If a held coordinate is not a drive's joint, or Newton does not converge.
    """
    names = scene.coordinate_names
    joints = sorted(names[c.index] for c in couplings)
    if sorted(held) != joints:
        raise Rt70Error(
            f"{scene.name}: the drives hold {', '.join(joints)}, asked to hold "
            f"{', '.join(sorted(held)) or 'nothing'}"
        )
    q = equilibrium(scene, held, tol=tol)  # the coordinate equilibrium: a close start
    Q = static_force(scene, q)
    K = np.array([-float(Q[c.index]) for c in couplings])
    scale = _force_scale(scene, held)
    free = np.array([i for i in range(len(names)) if names[i] not in held])
    S = stiffness_matrix(scene, q)

    def force(q: np.ndarray) -> np.ndarray:
        return static_force(scene, q) if load is None else static_force(scene, q) + load(q)

    return _drives_newton(scene, couplings, force, (q, K), (S, free), scale, tol)


def _force_scale(scene: Scene, held: dict[str, float]) -> float:
    """The force scale of :func:`rt70.linear.linearize.equilibrium`, at least 1.

    The static force of the undeformed structure (the weights) at the held pointing;
    the held torques alone have none at the zenith.
    """
    names = scene.coordinate_names
    undeformed = np.zeros(len(names))
    for name, value in held.items():
        undeformed[names.index(name)] = value
    return max(float(np.max(np.abs(static_force(scene, undeformed)))), 1.0)


def _drives_newton(
    scene: Scene,
    couplings: list[SceneCoupling],
    force: Callable[[np.ndarray], np.ndarray],
    start: tuple[np.ndarray, np.ndarray],
    jacobian: tuple[np.ndarray, np.ndarray],
    scale: float,
    tol: float,
) -> tuple[np.ndarray, np.ndarray, float]:
    """Newton's iteration of :func:`scene_equilibrium`: ``(q, K, residual)``.

    From ``start = (q, K)``; ``jacobian = (S, free)``, the stiffness matrix at the start
    (kept throughout) and the coordinates that move. Stops when ``max |R| / scale ≤ tol``
    or when a step moves no coordinate by more than ``STEP_TOL``.
    """
    q, K = start
    S, free = jacobian
    size = np.inf
    for k in range(MAX_ITER):
        with np.errstate(over="ignore", invalid="ignore"):  # checked just below
            G = np.column_stack([c.angle_gradient(q)[1] for c in couplings])
            R = force(q) + G @ K
        size = float(np.max(np.abs(R))) / scale
        if not np.isfinite(size):
            raise Rt70Error(
                f"{scene.name}: drives' equilibrium: the static forces are not finite after "
                f"{k} Newton step(s): the load (a wind?) deforms the structure beyond any "
                "equilibrium its stiffness can give"
            )
        if size <= tol:
            return q, K, size
        step = _newton_step(scene, np.column_stack([-S[:, free], G]), R)
        q[free] += step[: free.size]
        K += step[free.size :]
        if np.abs(step[: free.size]).max() <= STEP_TOL * max(1.0, np.abs(q).max()):
            # the configuration is fixed to rounding (as equilibrium() stops)
            R = force(q) + np.column_stack([c.angle_gradient(q)[1] for c in couplings]) @ K
            return q, K, float(np.max(np.abs(R))) / scale
    raise Rt70Error(
        f"{scene.name}: drives' equilibrium not found in {MAX_ITER} Newton steps "
        f"(residual {size:.2g} of the force scale)"
    )


def _newton_step(scene: Scene, J: np.ndarray, R: np.ndarray) -> np.ndarray:
    """``J⁻¹(−R)`` with J's columns scaled to unit max-norm first.

    The columns mix units (a coordinate's stiffness, N·m/rad, against a sector's angle
    gradient, 1/m): scaled, the solve's conditioning is the equations', not the units'.
    """
    scale = np.max(np.abs(J), axis=0)
    scale[scale == 0.0] = 1.0
    try:
        step = scipy.linalg.solve(J / scale, -R) / scale
    except (np.linalg.LinAlgError, ValueError):
        raise Rt70Error(
            f"{scene.name}: drives' equilibrium: Newton's matrix is singular or not finite "
            "(a coordinate nothing holds?)"
        ) from None
    return step


def scene_servos(
    scene: Scene, tuning: dict[str, tuple[float, float]] | None = None
) -> dict[str, tuple[DriveParameters, CascadeGains]]:
    """Each scene drive's parameters and cascade gains, as :class:`SceneServoFactory` uses.

    For the linear closed loop (:func:`rt70.control.scene_loop.closed_loop`); ``tuning``
    as the factory's.
    """
    tuning = {**AXIS_TUNING, **(tuning or {})}
    tables = axis_tables(scene)
    out = {}
    for d in scene.description.drives:
        if d.joint not in tables:
            raise Rt70Error(
                f"{scene.name}: drive '{d.name}' turns '{d.joint}', no axis of its <rt70:mount>"
            )
        axis = tables[d.joint]
        p = drive_parameters(d, axis.reference_inertia)
        out[d.name] = (p, scene_axis_gains(p, axis, *tuning[axis.name]))
    return out


class SceneServoFactory:
    """Drive factory of the scene's ``<rt70:drive>`` elements (module docstring).

    Use as ``run_scenario(scene, sc, drives=SceneServoFactory())``: its :meth:`start`
    gives the start state, its call the components.

    Parameters
    ----------
    tuning : dict, optional
        ``{"azimuth": (position_hz, ratio), ...}`` by table axis; default
        :data:`rt70.telescope.scenarios.AXIS_TUNING`.
    friction : bool
        Add the book's dry friction on each driven axis.
    side : {"reference", "textbook"}
        Whose kinematics computes θ_d (use the simulation's side).
    """

    def __init__(
        self,
        tuning: dict[str, tuple[float, float]] | None = None,
        friction: bool = False,
        side: str = "reference",
    ) -> None:
        self.tuning = {**AXIS_TUNING, **(tuning or {})}
        self.friction = friction
        self.side = check_side(side)
        self.residual = np.nan  # of the last start (scene_equilibrium)
        self._couplings: dict[str, list[SceneCoupling]] = {}

    def couplings(self, scene: Scene) -> list[SceneCoupling]:
        """One :class:`SceneCoupling` per scene drive (kept per scene).

        Raises
        ------
        Rt70Error
            If the scene has no drives, or one on a joint that is not an RT-70 axis.
        """
        if scene.name not in self._couplings:
            drives = scene.description.drives
            if not drives:
                raise Rt70Error(f"{scene.name}: no <rt70:drive>: use the coordinate drives")
            tables = axis_tables(scene)
            for d in drives:
                if d.joint not in tables:
                    raise Rt70Error(
                        f"{scene.name}: drive '{d.name}' turns '{d.joint}', no axis of its "
                        f"<rt70:mount> ({', '.join(tables)})"
                    )
            self._couplings[scene.name] = [SceneCoupling(scene, d, self.side) for d in drives]
        return self._couplings[scene.name]

    def start(self, scene: Scene, held: dict[str, float]) -> tuple[np.ndarray, dict[str, float]]:
        """Start state and holding torques by joint coordinate (:func:`scene_equilibrium`)."""
        couplings = self.couplings(scene)
        q, K, self.residual = scene_equilibrium(scene, couplings, held)
        names = scene.coordinate_names
        return q, {names[c.index]: float(k) for c, k in zip(couplings, K, strict=True)}

    def __call__(self, scene, q0, torques, references) -> list[StateComponent]:
        """The servos (and frictions), preset to hold ``torques`` at ``q0``."""
        names = scene.coordinate_names
        tables = axis_tables(scene)
        out: list[StateComponent] = []
        for c in self.couplings(scene):
            joint = names[c.index]
            axis = tables[joint]
            p = drive_parameters(c.drive, axis.reference_inertia)
            gains = scene_axis_gains(p, axis, *self.tuning[axis.name])
            initial = preset_servo_state(p, gains, c.angle(q0), torques[joint])
            servo = BackCalculationServo(
                c.drive.name,
                None,
                None,
                p,
                gains,
                references[joint],
                initial,
                servo_tolerances(p),
                coupling=c,
                encoder=lambda q, k=c.index: float(q[k]),
            )
            out.append(servo)
        if self.friction:
            out += axis_frictions(scene, [names[c.index] for c in self.couplings(scene)])
        return out


#: The drive models of ``rt70 simulate --drives``.
DRIVE_MODELS = ("scene", "coordinate")


def has_scene_drives(scene: Scene) -> bool:
    """Whether every axis of the scene's ``<rt70:mount>`` has a ``<rt70:drive>``."""
    mount = scene.description.mount
    if mount is None:
        return False
    return {a.joint for a in mount.axes} <= {d.joint for d in scene.description.drives}


def check_scene_drives(scene: Scene) -> None:
    """Refuse a scene without a ``<rt70:drive>`` on each mount axis (:class:`Rt70Error`)."""
    joints = [a.joint for a in mount_of(scene).axes]
    if not has_scene_drives(scene):
        raise Rt70Error(
            f"{scene.name}: --drives scene needs a <rt70:drive> on each of {', '.join(joints)}"
        )


def choose_drives(
    scene: Scene, model: str | None, friction: bool = False, side: str = "reference"
) -> tuple[object, str]:
    """The drive factory of a scenario and a phrase describing it.

    Parameters
    ----------
    scene : Scene
        The scene the scenario runs on.
    model : {"scene", "coordinate"} or None
        The drives' model (:data:`DRIVE_MODELS`): the scene's ``<rt70:drive>`` elements,
        or torques on the axis coordinates; None: the scene's drives where it declares
        one per axis (its own model of the drives), the coordinate drives otherwise.
    friction : bool
        Add the book's dry friction on both axes.
    side : {"reference", "textbook"}
        Which side computes the scene drives' couplings.

    Raises
    ------
    Rt70Error
        An unknown model, or ``"scene"`` for a scene without a drive on each axis.
    """
    if model is None:
        model = "scene" if has_scene_drives(scene) else "coordinate"
    if model not in DRIVE_MODELS:
        raise Rt70Error(f"unknown drive model {model!r} (choose from {', '.join(DRIVE_MODELS)})")
    if model == "scene":
        check_scene_drives(scene)
    extra = ", dry friction" if friction else ""
    if model == "scene":
        return SceneServoFactory(friction=friction, side=side), f"scene drives{extra}"
    base = servo_drives()
    if not friction:
        return base, "coordinate drives"

    def build(scene, q0, torques, references):
        joints = [a.joint for a in mount_of(scene).axes]
        return base(scene, q0, torques, references) + axis_frictions(scene, joints)

    return build, f"coordinate drives{extra}"


def axis_frictions(scene: Scene, joints: list[str]) -> list[StateComponent]:
    """The book's dry friction (:data:`FRICTION_WIDTH`) on each of the axis ``joints``."""
    names = list(scene.coordinate_names)
    tables = axis_tables(scene)
    return [
        AxisFriction(
            f"{tables[j].name}_friction",
            names,
            j,
            tables[j].friction,
            FRICTION_WIDTH,
            FRICTION_KIND,
            FRICTION_ATOL,
        )
        for j in joints
    ]
