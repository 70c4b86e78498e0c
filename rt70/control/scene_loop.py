"""The scene's own drives and servos closed around its linear structure: both axes at once.

One job: the linear closed loop that :class:`rt70.telescope.scene_servo.SceneServoFactory` runs in
a nonlinear simulation, as one python-control ``StateSpace`` — the structure linearised
at a drive-held equilibrium, every ``<rt70:drive>`` (its DC motor and compliant reducer,
formalism §4.5, (4.137)–(4.150)) acting through its own angle θ_d(q), and each drive's
PI cascade (:mod:`rt70.control.servo`) reading its encoder on the axis coordinate. Disturbances
enter as generalised-force columns (a wind gust's, :mod:`rt70.telescope.pointing`); outputs are any
:class:`rt70.model.outputs.Output` (the mirror system's errors) linearised by
:func:`rt70.model.outputs.output_matrix`.

The structure (``x = [δq; δq̇]``, all the scene's coordinates free)::

    M δq̈ + D δq̇ + (K + K_extra) δq = Σ_d g_d τ_d + Σ_j b_j u_j

with ``g_d = ∂θ_d/∂q`` at q0 (:class:`rt70.model.couplings.SceneCoupling`, textbook side),
τ_d the reducer torque of drive d, ``b_j`` the disturbance columns and ``K_extra`` a
stiffness the caller adds (the wind's aerodynamic stiffness, not symmetric). Each drive
(:func:`rt70.control.axis_plant.drive_block`) is fed ``θ_d = g_dᵀ δq`` and ``θ̇_d = g_dᵀ δq̇``;
its cascade reads the encoder δq_k of the drive's joint, exactly as the nonlinear servo
(:class:`rt70.control.antiwindup.BackCalculationServo` while no loop is clamped). The sector's
geometric stiffness ``τ_d ∂²θ_d/∂q²`` is left out, as in
:func:`rt70.linear.linearize.locked_rotor` (about 10⁻⁵ of the reducer's).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import control
import numpy as np

from rt70.bondgraph.parameters import DriveParameters
from rt70.control.axis_plant import drive_block
from rt70.control.drives import drive_parameters
from rt70.control.loops import pi_block
from rt70.control.servo import CascadeGains
from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.model.couplings import SceneCoupling
from rt70.model.outputs import Output, column_labels, output_matrix
from rt70.model.scene import Scene


def _renamed(sys: control.StateSpace, prefix: str, name: str) -> control.StateSpace:
    """``sys`` named ``name``, its input and output names prefixed by ``prefix``.

    The states keep their names: the interconnection prefixes them with ``name``.
    """
    return control.ss(
        sys.A,
        sys.B,
        sys.C,
        sys.D,
        states=list(sys.state_labels),
        inputs=[f"{prefix}{n}" for n in sys.input_labels],
        outputs=[f"{prefix}{n}" for n in sys.output_labels],
        name=name,
    )


def structure_system(
    scene: Scene,
    lm: lin.Linearization,
    couplings: Sequence[SceneCoupling],
    disturbances: Mapping[str, np.ndarray],
    outputs: Sequence[Output],
    K_extra: np.ndarray | None = None,
) -> control.StateSpace:
    """The structure with the drives' torques and the disturbances in, θ_d and outputs out.

    Parameters
    ----------
    scene : Scene
        The scene.
    lm : Linearization
        Its linear model about a drive-held equilibrium, no coordinate locked.
    couplings : sequence of SceneCoupling
        One per drive (``d.drive.name`` labels its signals).
    disturbances : mapping name → (nv,) array
        Generalised-force column of each unit disturbance input.
    outputs : sequence of Output
        Linearised on the textbook side (one row per component, ``name:x`` …).
    K_extra : (nv, nv) array, optional
        Added to K as it is (not symmetrised).

    Returns
    -------
    control.StateSpace
        Inputs ``<drive>_reducer_torque`` (τ_d) then the disturbances; outputs
        ``<drive>_axis_angle`` (θ_d), ``<drive>_axis_rate`` (θ̇_d), ``<drive>_encoder``
        (the joint's coordinate) for each drive, then the outputs' components. The
        names match :func:`rt70.control.axis_plant.drive_block`'s, prefixed by the drive's
        name, so :func:`closed_loop` connects them by name.
    """
    if lm.locked:
        raise Rt70Error(f"{scene.name}: the closed loop needs every coordinate free")
    n = len(lm.coordinates)
    K = lm.K if K_extra is None else lm.K + K_extra
    Minv = np.linalg.inv(lm.M)
    G = np.column_stack([c.angle_gradient(lm.q0)[1] for c in couplings])
    columns = [np.asarray(b, dtype=float).reshape(n) for b in disturbances.values()]
    Bq = np.column_stack([G, *columns]) if columns else G
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ lm.D]])
    B = np.vstack([np.zeros_like(Bq), Minv @ Bq])
    rows, names = [], []
    for k, c in enumerate(couplings):
        d = c.drive.name
        e = np.zeros(n)
        e[c.index] = 1.0
        rows += [np.r_[G[:, k], np.zeros(n)], np.r_[np.zeros(n), G[:, k]], np.r_[e, np.zeros(n)]]
        names += [f"{d}_axis_angle", f"{d}_axis_rate", f"{d}_encoder"]
    if outputs:
        Cq = output_matrix(scene, lm.q0, list(outputs), "textbook")
        for row in Cq:
            rows.append(np.r_[row, np.zeros(n)])
        names += [label for y in outputs for label in _labels(y)]
    C = np.vstack(rows)
    inputs = [f"{c.drive.name}_reducer_torque" for c in couplings] + list(disturbances)
    states = [*lm.coordinates, *(f"{c}_dot" for c in lm.coordinates)]
    return control.ss(
        A, B, C, np.zeros((C.shape[0], B.shape[1])),
        states=states, inputs=inputs, outputs=names, name="structure",
    )  # fmt: skip


def _labels(y: Output) -> list[str]:
    return column_labels(y.name, y.size) if y.size > 1 else [y.name]


#: Each loop's error signal (suffix of ``<drive>_…``).
ERRORS = {"position": "e_p", "rate": "e_v", "current": "e_i"}


def _cascade_blocks(
    d: str, p: DriveParameters, g: CascadeGains, open_loop: tuple[str, str] | str | None
) -> list[control.StateSpace]:
    """Drive ``d``'s motor and its three PI loops, named ``<d>_…``, one loop maybe broken.

    ``open_loop`` (drive, loop) breaks that drive's loop (its PI reads ``w``); a loop name
    alone breaks it on every drive (each PI reads ``<d>_w``).
    """

    def err(loop: str) -> str:
        if open_loop == (d, loop):
            return "w"
        return f"{d}_w" if open_loop == loop else f"{d}_{ERRORS[loop]}"

    # the drive's own names: voltage, axis_angle, axis_rate → reducer_torque, …
    return [
        _renamed(drive_block(p), f"{d}_", d),
        control.summing_junction([f"{d}_reference", f"-{d}_encoder"], f"{d}_e_p"),
        pi_block(g.kp_p, g.ki_p, err("position"), f"{d}_speed_ref", p.i_r, f"{d}_position_loop"),
        control.summing_junction([f"{d}_speed_ref", f"-{d}_motor_speed"], f"{d}_e_v"),
        pi_block(g.kp_v, g.ki_v, err("rate"), f"{d}_current_ref", name=f"{d}_rate_loop"),
        control.summing_junction([f"{d}_current_ref", f"-{d}_current"], f"{d}_e_i"),
        pi_block(g.kp_i, g.ki_i, err("current"), f"{d}_voltage", name=f"{d}_current_loop"),
    ]


def closed_loop(
    scene: Scene,
    lm: lin.Linearization,
    disturbances: Mapping[str, np.ndarray],
    outputs: Sequence[Output],
    servos: Mapping[str, tuple[DriveParameters, CascadeGains]],
    K_extra: np.ndarray | None = None,
    open_loop: tuple[str, str] | str | None = None,
) -> control.StateSpace:
    """The scene's drives with their PI cascades closed around the structure.

    Parameters
    ----------
    scene, lm, disturbances, outputs, K_extra
        As :func:`structure_system`.
    servos : mapping drive name → (DriveParameters, CascadeGains)
        Every ``<rt70:drive>`` of the scene: its parameters and its cascade's gains
        (for the RT-70 :func:`rt70.telescope.scene_servo.scene_servos`, the gains
        :class:`rt70.telescope.scene_servo.SceneServoFactory` simulates with). The clamps are left
        out (a linear analysis).
    open_loop : (drive, loop) or loop, optional
        Break one drive's ``"position"``, ``"rate"`` or ``"current"`` loop at its error:
        its PI reads the input ``w`` instead, and the error ``<drive>_e_p|e_v|e_i`` is
        the last output (:func:`loop_gain`); a loop name alone breaks it on every drive,
        each PI reading ``<drive>_w``, the errors the last outputs.

    Returns
    -------
    control.StateSpace
        Inputs ``<drive>_reference`` (rad, on the encoder's coordinate, about its value
        at q0) then the disturbances (then ``w``); outputs the requested outputs'
        components, then each drive's ``encoder``, ``current`` (A) and ``voltage`` (V)
        (then the broken loop's error).

    Raises
    ------
    Rt70Error
        If a drive of the scene has no servo, or a servo names no drive of the scene.
    """
    drives = scene.description.drives
    names = {d.name for d in drives}
    if not drives or names != set(servos):
        raise Rt70Error(
            f"{scene.name}: servos for {', '.join(sorted(servos)) or 'no drive'}, the scene's "
            f"drives are {', '.join(sorted(names)) or 'none'}"
        )
    every = isinstance(open_loop, str)
    if open_loop is not None and not (
        (every and open_loop in ERRORS)
        or (not every and open_loop[0] in names and open_loop[1] in ERRORS)
    ):
        raise Rt70Error(f"{scene.name}: no loop {open_loop} to break (drives {sorted(names)})")
    couplings = [SceneCoupling(scene, d, "textbook") for d in drives]
    blocks = [structure_system(scene, lm, couplings, disturbances, outputs, K_extra)]
    extra_out = []
    for c in couplings:
        blocks += _cascade_blocks(c.drive.name, *servos[c.drive.name], open_loop)
        extra_out += [f"{c.drive.name}_{s}" for s in ("encoder", "current", "voltage")]
    inputs = [f"{c.drive.name}_reference" for c in couplings] + list(disturbances)
    outs = [label for y in outputs for label in _labels(y)] + extra_out
    if every:
        inputs += [f"{c.drive.name}_w" for c in couplings]
        outs += [f"{c.drive.name}_{ERRORS[open_loop]}" for c in couplings]
    elif open_loop is not None:
        inputs.append("w")
        outs.append(f"{open_loop[0]}_{ERRORS[open_loop[1]]}")
    return control.interconnect(
        blocks, inplist=inputs, outlist=outs, inputs=inputs, outputs=outs, check_unused=False
    )


def loop_gain(
    scene: Scene,
    lm: lin.Linearization,
    servos: Mapping[str, tuple[DriveParameters, CascadeGains]],
    drive: str,
    loop: str,
) -> control.StateSpace:
    """The loop transfer ``L = −e/w`` of one drive's loop broken at its error.

    Every other loop (this drive's inner ones, the other drives') closed, so margins and
    crossovers are those of ``L`` in python-control's convention (negative feedback),
    as :func:`rt70.control.loops.loop_transfer` for one axis.

    Parameters
    ----------
    scene, lm, servos
        As :func:`closed_loop`.
    drive : str
        The drive whose loop is broken.
    loop : {"position", "rate", "current"}
        The loop.
    """
    sys = closed_loop(scene, lm, {}, [], servos, open_loop=(drive, loop))
    return -sys[f"{drive}_{ERRORS[loop]}", "w"]


def driven_plant(
    scene: Scene,
    lm: lin.Linearization,
    outputs: Sequence[Output],
    disturbances: Mapping[str, np.ndarray] | None = None,
) -> control.StateSpace:
    """The structure with every ``<rt70:drive>`` on it, the armature voltages as inputs.

    The plant a servo is designed around, through the same drive elements as the
    nonlinear model (each drive's reducer acting through its own angle θ_d, gear sector
    included: :func:`structure_system`), with no loop closed.

    Parameters
    ----------
    scene, lm, outputs
        As :func:`structure_system`.
    disturbances : mapping name → (nv,) array, optional
        Generalised-force columns of unit disturbance inputs.

    Returns
    -------
    control.StateSpace
        Inputs ``<drive>_voltage`` (V) then the disturbances; outputs each drive's
        ``encoder`` (rad, its joint's coordinate about q0), ``current`` (A) and
        ``motor_speed`` (rad/s), then the outputs' components.
    """
    drives = scene.description.drives
    if not drives:
        raise Rt70Error(f"{scene.name}: no <rt70:drive>: no driven plant")
    disturbances = dict(disturbances or {})
    couplings = [SceneCoupling(scene, d, "textbook") for d in drives]
    blocks = [structure_system(scene, lm, couplings, disturbances, outputs)]
    for c in couplings:
        blocks.append(
            _renamed(drive_block(drive_parameters(c.drive)), f"{c.drive.name}_", c.drive.name)
        )
    inputs = [f"{c.drive.name}_voltage" for c in couplings] + list(disturbances)
    outs = [
        f"{c.drive.name}_{s}" for c in couplings for s in ("encoder", "current", "motor_speed")
    ] + [label for y in outputs for label in _labels(y)]
    return control.interconnect(
        blocks, inplist=inputs, outlist=outs, inputs=inputs, outputs=outs, check_unused=False
    )
