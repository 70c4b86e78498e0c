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
- **Limits and design.** Each axis's ``<rt70:servo>`` (:mod:`rt70.telescope.axis_servos`):
  the current clamp is its peak axis torque through the drive's reducer,
  ``torque_limit / (c_m i_r)`` (for the RT-70, ``n T_peak i_r`` = 9.81·10⁷ N·m
  whatever the motors' lumping), the rate and voltage clamps as declared, the
  bandwidths declared or tuned on the model.
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

import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.antiwindup import BackCalculationServo
from rt70.control.friction import AxisFriction
from rt70.control.servo import CascadeGains
from rt70.errors import Rt70Error
from rt70.model.antenna import mount_of
from rt70.model.couplings import SceneCoupling
from rt70.model.scene import Scene
from rt70.model.sides import check_side
from rt70.simulation.states import StateComponent
from rt70.telescope.axis_servos import (
    Tuning,
    axis_servos,
    drive_servos,
    friction_of,
    servo_gains,
    servo_parameters,
)
from rt70.telescope.drive_equilibrium import scene_equilibrium
from rt70.telescope.servo_design import declared_tuning
from rt70.telescope.servo_tuning import (
    preset_servo_state,
    servo_drives,
    servo_tolerances,
)


def _servos_by_joint(scene: Scene) -> dict:
    """Each declared axis servo (:func:`rt70.telescope.axis_servos.axis_servos`) by its joint."""
    return {d.axis.joint: d for d in axis_servos(scene).values()}


#: Friction regularisation, a fraction of the axis's rate limit (docs/drive-train.md §2:
#: ``rt70.reports.drivetrain``).
FRICTION_WIDTH_OF_RATE = 1e-6
FRICTION_KIND = "linear"
#: Absolute tolerance of the friction's dissipated heat, J.
FRICTION_ATOL = 1e-3


def scene_servos(
    scene: Scene, tuning: Tuning | None = None
) -> dict[str, tuple[DriveParameters, CascadeGains]]:
    """Each scene drive's parameters and cascade gains, as :class:`SceneServoFactory` uses.

    For the linear closed loop (:func:`rt70.control.scene_loop.closed_loop`); ``tuning``
    overrides the scene's (:func:`rt70.telescope.servo_design.declared_tuning`).
    """
    return drive_servos(scene, {**declared_tuning(scene), **(tuning or {})})


class SceneServoFactory:
    """Drive factory of the scene's ``<rt70:drive>`` elements (module docstring).

    Use as ``run_scenario(scene, sc, drives=SceneServoFactory())``: its :meth:`start`
    gives the start state, its call the components.

    Parameters
    ----------
    tuning : dict, optional
        ``{"azimuth": (position_hz, ratio), ...}`` by axis, overriding the scene's
        (:func:`rt70.telescope.servo_design.declared_tuning`).
    friction : bool
        Add the book's dry friction on each driven axis.
    side : {"reference", "textbook"}
        Whose kinematics computes θ_d (use the simulation's side).
    """

    def __init__(
        self,
        tuning: Tuning | None = None,
        friction: bool = False,
        side: str = "reference",
    ) -> None:
        self.tuning = dict(tuning or {})
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
            servos = {d.drive.name for d in axis_servos(scene).values()}
            for d in drives:
                if d.name not in servos:
                    raise Rt70Error(
                        f"{scene.name}: drive '{d.name}' is no axis's servo drive "
                        f"(<rt70:servo drive>: {', '.join(sorted(servos))})"
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
        servos = _servos_by_joint(scene)
        design = {**declared_tuning(scene), **self.tuning}
        out: list[StateComponent] = []
        for c in self.couplings(scene):
            joint = names[c.index]
            declared = servos[joint]
            p = servo_parameters(scene, declared)
            gains = servo_gains(p, declared.servo, *design[declared.axis.name])
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
        Add each axis's declared dry friction (``<rt70:servo static_friction …>``).
    side : {"reference", "textbook"}
        Which side computes the scene drives' couplings.

    Raises
    ------
    Rt70Error
        An axis without a ``<rt70:servo>``, an unknown model, or ``"scene"`` for a scene
        without a drive on each axis.
    """
    axis_servos(scene)  # one line naming an axis without its <rt70:servo>
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
    """Each axis's declared dry friction on the axis ``joints``.

    Regularised over :data:`FRICTION_WIDTH_OF_RATE` of the axis's rate limit.
    """
    names = list(scene.coordinate_names)
    servos = _servos_by_joint(scene)
    return [
        AxisFriction(
            f"{servos[j].axis.name}_friction",
            names,
            j,
            friction_of(scene, servos[j]),
            FRICTION_WIDTH_OF_RATE * servos[j].servo.rate_limit,
            FRICTION_KIND,
            FRICTION_ATOL,
        )
        for j in joints
    ]
