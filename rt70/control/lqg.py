"""LQG servo of one axis: designed on a reduced plant, checked on the full one.

One job: the model-based alternative to the PI cascade. The DSN 34-m beam-waveguide
antenna needed a position-loop bandwidth of about 1 Hz and reached it with a high-gain
LQG controller (TMO Progress Report 42-137, 1999; Gawronski, *Modeling and Control of
Antennas and Telescopes*, Springer 2008: LQG and H∞ about 10× better than PI — via
antenna-servo.md).

- :func:`reduce_plant` keeps the slow modes of the drive + structure plant
  (:class:`rt70.control.axis_plant.AxisPlant`) that the measurements see, by modal truncation
  with static correction (the fast or invisible modes residualised: their DC
  contribution kept as feedthrough). It is the one place a reduction enters: a better
  one (balanced truncation, Hankel singular values) replaces this function alone.
- :func:`design` solves the LQR (``control.lqr``) on the reduced plant augmented by the
  integral of the axis-angle error, with a reference feedforward ``(N_x, N_u)`` to the
  steady state of a unit angle, and the Kalman filter (``control.lqe``) from the
  encoder angle and the motor speed, with process noise at the voltage and wind-torque
  inputs; the reduced states are scaled first (:func:`_scaled`) so that both Riccati
  equations are well conditioned.
- :func:`lqg_system` closes the controller around the FULL plant; :func:`input_loop`
  breaks it at the plant input (the armature voltage) for margins. The checks (poles,
  margins, bandwidth) use :mod:`rt70.control.loop_measures`, the step and wind numbers
  :mod:`rt70.control.servo_compare`.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np
import scipy.linalg

from rt70.control.axis_plant import POINTING, AxisPlant
from rt70.errors import Rt70Error

#: Measurements the controller reads: the encoder's axis angle, the tachometer's motor
#: speed.
MEASURED = ("axis_angle", "motor_speed")
#: Fictitious process noise on every scaled state of the Kalman filter, relative to the
#: mean of the physical noises' intensities.
STATE_NOISE = 1e-6
#: Eigenvalues below this (rad/s) are the rigid rotation of the axis with its motor
#: (exactly 0 in azimuth, about 1e-6 from rounding).
RIGID_RAD_S = 1e-3


def _modal_peaks(lam: np.ndarray, V: np.ndarray, sys: control.StateSpace) -> np.ndarray:
    """Each mode's peak gain on every input–output channel, relative to the channel's largest.

    A mode ``c b / (s − λ)`` (with its conjugate) peaks at about ``|c b| / |Re λ|``
    (the modal H∞ norm of a lightly damped mode, Gawronski 2004); a real mode at
    ``|c b| / |λ|``. Independent of how the eigenvectors are scaled. Rigid modes (λ = 0)
    (``|λ| <`` :data:`RIGID_RAD_S`, the drive's free rotation up to rounding) count as
    infinite. Returns ``(modes, channels)``.
    """
    b = np.linalg.solve(V, sys.B)  # (modes, inputs)
    c = sys.C @ V  # (outputs, modes)
    gain = np.abs(c.T[:, :, None] * b[:, None, :]).reshape(lam.size, -1)
    decay = np.where(np.abs(lam.imag) > 0, np.abs(lam.real), np.abs(lam))
    rigid = np.abs(lam) < RIGID_RAD_S
    peak = np.where(rigid[:, None], np.inf, gain / np.where(rigid, 1.0, decay)[:, None])
    finite = np.where(np.isfinite(peak), peak, 0.0)
    top = finite.max(axis=0)
    return np.where(top > 0, peak / np.where(top > 0, top, 1.0), 0.0)


def reduce_plant(
    sys: control.StateSpace,
    f_max_hz: float = 10.0,
    rel_peak: float = 1e-3,
    outputs: tuple[str, ...] | None = None,
) -> control.StateSpace:
    """Modal truncation with static correction: the slow modes that matter kept.

    A is brought to real block-diagonal (modal) form by its eigenvectors. A mode is
    kept when ``|λ| ≤ 2π f_max_hz`` and its peak gain (:func:`_modal_peaks`) on some
    input–output channel is at least ``rel_peak`` of the channel's largest modal peak
    (antenna-servo.md: modes chosen by their modal norms, not by frequency alone); the
    others are residualised, ``D_r = D − C_f A_f⁻¹ B_f``, so the reduced plant keeps the
    full plant's DC gain. Names of inputs and outputs kept. The one place the reduction
    enters the LQG design: a better one replaces this function alone.

    ``outputs`` names the outputs whose channels select the modes (default all): the
    LQG design selects by its measurements, so that a mode seen only in the pointing
    (a structural mode the axis torque does not excite) is not kept unobservable.

    Parameters
    ----------
    sys : control.StateSpace
        The full plant (for an axis: :attr:`rt70.control.axis_plant.AxisPlant.system`, inputs
        ``voltage`` and ``wind_torque``).
    f_max_hz : float
        The fastest mode kept, Hz.
    rel_peak : float
        The smallest modal peak kept, relative to the channel's largest.
    outputs : tuple of str, optional
        The outputs whose channels select the modes (default all).

    Raises
    ------
    Rt70Error
        If the eigenvectors are too ill-conditioned for a modal form (a defective A).
    """
    lam, V = scipy.linalg.eig(sys.A)
    chosen = sys if outputs is None else sys[list(outputs), :]
    peaks = _modal_peaks(lam, V, chosen).max(axis=1)
    columns, slow = [], []
    for k in np.argsort(np.abs(lam), kind="stable"):
        value = lam[k]
        if value.imag < 0.0:
            continue  # the conjugate of a pair taken with its partner
        keep = bool(abs(value) <= 2 * np.pi * f_max_hz and peaks[k] >= rel_peak)
        if value.imag > 0.0:
            columns += [V[:, k].real, V[:, k].imag]
            slow += [keep, keep]
        else:
            columns.append(V[:, k].real)
            slow.append(keep)
    T = np.column_stack(columns)
    if np.linalg.cond(T) > 1e12:
        raise Rt70Error("reduce_plant: the plant's eigenvectors are nearly dependent")
    Am = np.linalg.solve(T, sys.A @ T)
    Bm = np.linalg.solve(T, sys.B)
    Cm = sys.C @ T
    s = np.array(slow)
    f = ~s
    D = sys.D + (-Cm[:, f] @ np.linalg.solve(Am[np.ix_(f, f)], Bm[f]) if f.any() else 0.0)
    return control.ss(
        Am[np.ix_(s, s)],
        Bm[s],
        Cm[:, s],
        D,
        inputs=list(sys.input_labels),
        outputs=list(sys.output_labels),
        name="reduced",
    )


@dataclass(frozen=True)
class LqgWeights:
    """Weights of the LQR and the Kalman filter (Bryson's rule: 1 / largest value²).

    Attributes
    ----------
    angle : float
        Axis-angle error that costs as much as ``voltage``, rad.
    integral : float
        Time constant of the integral action, s: the integral of the error weighs as an
        error of ``angle`` lasting this long.
    voltage : float
        Armature voltage, V.
    wind_torque : float
        Process noise at the wind-torque input, N·m (its intensity).
    input_noise : float
        Process noise at the voltage input, V (for the loop's robustness at the input).
    angle_noise, speed_noise : float
        Measurement noise of the encoder (rad) and tachometer (rad/s).
    """

    angle: float = 1e-6
    integral: float = 1.0
    voltage: float = 440.0
    wind_torque: float = 4.9e6
    input_noise: float = 440.0
    angle_noise: float = 5e-7
    speed_noise: float = 1e-2


@dataclass(frozen=True)
class LqgController:
    """The LQG controller as a state space and what it was designed on.

    Attributes
    ----------
    controller : control.StateSpace
        Inputs ``reference`` (rad) and :data:`MEASURED`; output ``voltage``; states the
        estimate of the reduced state and the error integral.
    reduced : control.StateSpace
        The reduced plant it was designed on.
    K : ndarray
        State-feedback gain on ``[x̂; z]``.
    L : ndarray
        Kalman gain.
    """

    controller: control.StateSpace
    reduced: control.StateSpace
    K: np.ndarray
    L: np.ndarray


def _scaled(red: control.StateSpace, w: LqgWeights) -> control.StateSpace:
    """The reduced plant with its states scaled for the Riccati equations.

    A diagonal similarity ``x = S x̃`` with ``s_i = sqrt(|b_i| / |c_i|)``: the rows of
    B (the inputs in their units, voltage and wind torque) and the columns of C (the
    measurements in their noise units) of each mode made equal in norm (the modal A of
    :func:`reduce_plant` is block-diagonal; a pair's two coordinates share a scale). The modal
    coordinates otherwise span many decades (motor angle ~ i_r × axis angle).
    """
    inputs, outputs = list(red.input_labels), list(red.output_labels)
    Bn = red.B[:, [inputs.index("voltage"), inputs.index("wind_torque")]] * [
        w.voltage,
        w.wind_torque,
    ]
    Cn = np.vstack(
        [
            red.C[outputs.index("axis_angle")] / w.angle_noise,
            red.C[outputs.index("motor_speed")] / w.speed_noise,
        ]
    )
    b, c = np.linalg.norm(Bn, axis=1), np.linalg.norm(Cn, axis=0)
    # one scale for both coordinates of a complex pair (a 2 × 2 block of the modal A),
    # which keeps the block a scaled rotation
    n = red.A.shape[0]
    i = 0
    while i < n - 1:
        if red.A[i, i + 1] != 0.0 or red.A[i + 1, i] != 0.0:
            b[i : i + 2] = np.hypot(b[i], b[i + 1])
            c[i : i + 2] = np.hypot(c[i], c[i + 1])
            i += 2
        else:
            i += 1
    floor = 1e-12 * max(b.max(), c.max())
    s = np.sqrt(np.maximum(b, floor) / np.maximum(c, floor))
    return control.ss(
        red.A * (1 / s)[:, None] * s[None, :],
        red.B / s[:, None],
        red.C * s[None, :],
        red.D,
        inputs=inputs,
        outputs=outputs,
        name="reduced",
    )


def design(
    ap: AxisPlant, f_max_hz: float = 10.0, weights: LqgWeights | None = None
) -> LqgController:
    """LQR with integral action + Kalman filter on the plant reduced to ``f_max_hz``.

    The LQR state is ``[x_r; z]``, ``ż = axis_angle − reference``; the control
    ``u = −K_x (x̂ − N_x r) − K_z z + N_u r`` where ``(N_x, N_u)`` is the reduced
    plant's steady state for a unit angle (least squares, exact when it exists).

    Parameters
    ----------
    ap : AxisPlant
        The plant of one axis (drive and structure).
    f_max_hz : float
        The fastest mode of the reduced plant the design uses, Hz (:func:`reduce_plant`).
    weights : LqgWeights, optional
        The LQR and Kalman weights (default :class:`LqgWeights`' values).
    """
    w = weights or LqgWeights()
    red = _scaled(reduce_plant(ap.system, f_max_hz, outputs=MEASURED), w)
    names = list(red.output_labels)
    iu, iw = list(red.input_labels).index("voltage"), list(red.input_labels).index("wind_torque")
    A, B, G = red.A, red.B[:, [iu]], red.B[:, [iw]]
    n = A.shape[0]
    ia = names.index("axis_angle")
    Ca, Da = red.C[[ia]], red.D[[ia]][:, [iu]]
    Aa = np.block([[A, np.zeros((n, 1))], [Ca, np.zeros((1, 1))]])
    Ba = np.vstack([B, Da])
    Ca_aug = np.hstack([Ca, np.zeros((1, 1))])
    Q = Ca_aug.T @ Ca_aug / w.angle**2
    Q[n, n] += 1.0 / (w.angle * w.integral) ** 2
    R = np.array([[1.0 / w.voltage**2]])
    K, _, _ = control.lqr(Aa, Ba, Q, R)
    Kx, Kz = K[:, :n], K[:, n:]
    # steady state of a unit angle: A x + B u = 0, angle = 1
    M = np.block([[A, B], [Ca, Da]])
    sol = np.linalg.lstsq(M, np.r_[np.zeros(n), 1.0], rcond=None)[0]
    Nx, Nu = sol[:n, None], sol[n:, None]
    Nr = Kx @ Nx + Nu
    # Kalman filter on the measured outputs
    im = [names.index(m) for m in MEASURED]
    Cm, Dm = red.C[im], red.D[im][:, [iu]]
    Gn = np.hstack([B * w.input_noise, G * w.wind_torque])  # unit-intensity noises
    QN = Gn @ Gn.T
    # fictitious noise on every (scaled) state: keeps the Riccati equation well posed for
    # lightly damped modes the two noise inputs barely excite
    QN = 0.5 * (QN + QN.T) + STATE_NOISE * np.trace(QN) / n * np.eye(n)
    # the measurements in units of their noise (RN = 1): the Riccati equation is then
    # well scaled; the gain on the physical measurements follows
    noise = np.diag([1.0 / w.angle_noise, 1.0 / w.speed_noise])
    Ls, _, _ = control.lqe(A, np.eye(n), noise @ Cm, QN, np.eye(2))
    Lk = Ls @ noise
    # the controller: states [x̂; z], inputs [r, y_angle, y_speed], output u
    Bu = B - Lk @ Dm
    Ac = np.block([[A - Lk @ Cm - Bu @ Kx, -Bu @ Kz], [np.zeros((1, n)), np.zeros((1, 1))]])
    Bc = np.block([[Bu @ Nr, Lk], [np.array([[-1.0, 1.0, 0.0]])]])
    Cc = np.hstack([-Kx, -Kz])
    Dc = np.hstack([Nr, np.zeros((1, 2))])
    controller = control.ss(
        Ac, Bc, Cc, Dc, inputs=["reference", *MEASURED], outputs=["voltage"], name="lqg"
    )
    return LqgController(controller, red, K, Lk)


def lqg_system(
    ap: AxisPlant, lqg: LqgController, open_at_input: bool = False
) -> control.StateSpace:
    """The LQG controller around the FULL plant, closed or broken at the voltage.

    Returns inputs ``reference``, ``wind_torque`` (and ``w``, the plant's voltage, when
    broken); outputs ``axis_angle``, :data:`POINTING`, ``voltage``, ``current``,
    ``motor_speed``.

    Parameters
    ----------
    ap : AxisPlant
        The FULL plant of the axis.
    lqg : LqgController
        The controller (:func:`design`).
    open_at_input : bool
        Break the loop at the plant's voltage input (for :func:`input_loop`).
    """
    P = ap.system
    if open_at_input:
        inputs = ["w" if n == "voltage" else n for n in P.input_labels]
        P = control.ss(P.A, P.B, P.C, P.D, inputs=inputs, outputs=list(P.output_labels))
    inplist = ["reference", "wind_torque"] + (["w"] if open_at_input else [])
    outlist = ["axis_angle", *POINTING, "voltage", "current", "motor_speed"]
    return control.interconnect(
        [P, lqg.controller],
        inplist=inplist,
        outlist=outlist,
        inputs=inplist,
        outputs=outlist,
        check_unused=False,
    )


def input_loop(ap: AxisPlant, lqg: LqgController) -> control.StateSpace:
    """The loop transfer at the plant input, ``L = −u/w`` (controller output per plant input)."""
    return -lqg_system(ap, lqg, open_at_input=True)["voltage", "w"]
