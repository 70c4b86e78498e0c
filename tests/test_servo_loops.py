"""Servo loops around the linear RT-70 plant (rt70.control.axis_plant, loops, loop_measures,
lqg, servo_compare).

The linear drive + structure is checked against two independent forms: the drive's
Lagrange equations on a rigid rotor (rt70.bondgraph.lagrange) and, on the RT-70, an
assembly of the structure's M, K, D with the DcDrive's own equations linearised by
central differences. Then the cascade's margins at the chosen design bandwidth, the
finding that a 1 Hz PI design is not adequate on this plant, and the LQG designed on a
reduced plant, closed around the full plant. Numbers measured by validation/servo_loops.py.
"""

from __future__ import annotations

import control
import numpy as np
import pytest
from test_drives import J_L, PARAMS  # a rotor and a well-conditioned drive

from rt70.bondgraph.lagrange import drive_lagrange
from rt70.control import axis_plant, loop_measures, loops, lqg
from rt70.control.drives import DcDrive
from rt70.errors import Rt70Error
from rt70.linear import linearize as lin
from rt70.model.scene import load_scene
from rt70.reports import servo_loops as rs
from rt70.testing import assert_close

FREQS = np.array([0.013, 0.37, 1.1, 4.7, 23.0])  # Hz


@pytest.fixture(scope="module")
def scene():
    return load_scene("rt70_servo")


@pytest.fixture(scope="module")
def azimuth45(scene):
    """The azimuth loop at 45° (validation/servo_loops.py has 10°, 45°, 80° and elevation)."""
    return rs.axis_plant(scene, "azimuth", 45.0)


def test_connected_drive_on_a_rotor_is_its_lagrange_form():
    """connect_drive on a rigid rotor (1/(J_l s²)) against drive_lagrange's transfer."""
    rotor = control.ss(
        [[0, 1], [0, 0]],
        [[0, 0], [1 / J_L, 1 / J_L]],
        np.eye(2),
        np.zeros((2, 2)),
        inputs=["reducer_torque", "load_torque"],
        outputs=["axis_angle", "axis_rate"],
    )
    sys = axis_plant.connect_drive(rotor, PARAMS)
    lagrange = drive_lagrange(PARAMS, "voltage")  # q = [ρ, α_m, α_l], u = [U, τ_l]
    for f in FREQS:
        s = 2j * np.pi * f
        G = lagrange.transfer(s)
        H = sys(s)
        out, inp = list(sys.output_labels), list(sys.input_labels)
        pairs = {
            ("axis_angle", "voltage"): G[2, 0],
            ("current", "voltage"): s * G[0, 0],
            ("motor_speed", "voltage"): s * G[1, 0],
            ("axis_angle", "load_torque"): G[2, 1],
        }
        for (o, i), ref in pairs.items():
            got = H[out.index(o), inp.index(i)]
            # complex: the modulus of the difference, on the modulus of the transfer
            assert_close(abs(got - ref), 0.0, rel=1e-10, scale=abs(ref), what=f"{o}/{i} {f} Hz")


def _direct_assembly(scene, ap: axis_plant.AxisPlant) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A, b_voltage, c_angle of [q; q̇; I, α_m, ω_m] from M, K, D and DcDrive's equations.

    The drive's rates and reducer torque are linear in (q, q̇, s, u): their Jacobians by
    central differences are exact up to rounding.
    """
    lm = lin.linearize(scene, ap.q0, locked=("base_rx",))
    n = len(lm.coordinates)
    drive = DcDrive("az", lm.coordinates, "platform_rz", ap.parameters)
    k = lm.coordinates.index("platform_rz")

    def rates(x: np.ndarray, u: float) -> np.ndarray:
        q, qd, s = x[:n], x[n : 2 * n], x[2 * n :]
        tau = np.zeros(n)
        tau[k] = drive.reducer_torque(q, qd, s)
        qdd = np.linalg.solve(lm.M, tau - lm.K @ q - lm.D @ qd)
        return np.concatenate([qd, qdd, drive.motor_rates(q, qd, s, u)])

    N = 2 * n + 3
    A = np.empty((N, N))
    for j in range(N):
        e = np.zeros(N)
        e[j] = 1.0
        A[:, j] = (rates(e, 0.0) - rates(-e, 0.0)) / 2.0
    b = (rates(np.zeros(N), 1.0) - rates(np.zeros(N), -1.0)) / 2.0
    c = np.zeros(N)
    c[k] = 1.0
    return A, b, c


def test_rt70_drive_plant_matches_a_direct_assembly(scene, azimuth45):
    """voltage → axis angle of the interconnected plant against the direct assembly.

    Over the servo band (≤ 5 Hz; measured ≤ 8e-13). At 23 Hz, where the transfer is
    1e-11 rad/V (roll-off of an 85-state plant), both evaluations meet their rounding
    floor and differ by 2e-10.
    """
    A, b, c = _direct_assembly(scene, azimuth45)
    G = azimuth45.system["axis_angle", "voltage"]
    for f in FREQS[FREQS < 5.0]:
        s = 2j * np.pi * f
        ref = c @ np.linalg.solve(s * np.eye(A.shape[0]) - A, b)
        assert_close(abs(G(s) - ref), 0.0, rel=1e-10, scale=abs(ref), what=f"{f} Hz")


def test_cascade_margins_at_the_design_bandwidth(azimuth45):
    """At 0.15 Hz design every loop has GM ≥ 6 dB, PM ≥ 30°; the closed loop is stable.

    Measured (azimuth, 45°): position GM 16.2 dB, PM 61° at 0.19 Hz; rate −12.3 dB
    gain-reduction margin, PM 47°; current PM 121°; bandwidth 0.349 Hz.
    """
    r = loops.analyse_cascade(azimuth45, rs.CASCADE_POSITION_HZ)
    assert r.stable and r.adequate
    for m in r.margins.values():
        assert np.isfinite(m.pm_deg) and m.pm_deg >= loop_measures.MIN_PM_DEG
    # measured values (docstring): GM to ±0.2 dB, PM to ±1°, bandwidth to 2 %
    assert_close(r.margins["position"].gm_db, 16.2, rel=0.0125)
    assert_close(r.margins["position"].pm_deg, 60.9, rel=0.0165)
    assert_close(r.bandwidth_hz, 0.349, rel=0.02)


def test_a_one_hertz_pi_cascade_is_not_adequate(azimuth45):
    """The issue's 1 Hz: the rigid-axis PI design goes unstable on the flexible plant."""
    r = loops.analyse_cascade(azimuth45, 1.0)
    assert not r.stable
    assert not r.adequate


def test_lqg_on_a_reduced_plant_closes_the_full_plant_near_one_hertz(azimuth45):
    """LQG designed on 21 of 85 states: stable on the full plant, ~1.4 Hz, PM ≥ 60°.

    Measured (azimuth, 45°): bandwidth 1.392 Hz, input PM 99° at 0.61 Hz, no phase
    crossover (GM ∞).
    """
    ctrl = lqg.design(azimuth45, weights=rs.LQG_WEIGHTS)
    assert ctrl.reduced.nstates < azimuth45.system.nstates / 3
    closed = lqg.lqg_system(azimuth45, ctrl)
    assert loop_measures.stable(closed)
    m = loop_measures.margins(lqg.input_loop(azimuth45, ctrl))
    assert m.pm_deg >= 60.0 and m.gm_db >= loop_measures.MIN_GM_DB
    assert_close(loop_measures.bandwidth_hz(closed["axis_angle", "reference"]), 1.39, rel=0.03)


def test_reduction_keeps_the_low_frequency_response(azimuth45):
    """The reduced plant follows the full one below 2 Hz (measured 7e-4; 2.9 % at 10°)."""
    red = lqg.reduce_plant(azimuth45.system)
    f = np.array([0.01, 0.1, 0.5, 1.0, 2.0])
    for out in ("axis_angle", "motor_speed"):
        full = loop_measures.siso_response(azimuth45.system[out, "voltage"], f)
        reduced = loop_measures.siso_response(red[out, "voltage"], f)
        # complex, frequency by frequency: each response on its own modulus
        error = np.abs(reduced - full)
        assert_close(error, np.zeros_like(error), rel=3e-3, scale=np.abs(full), what=out)


def test_unknown_axis_and_loop_are_refused(scene, azimuth45):
    with pytest.raises(Rt70Error, match="unknown axis 'roll'"):
        rs.axis_plant(scene, "roll", 45.0)
    with pytest.raises(Rt70Error, match="unknown loop 'torque'"):
        loops.cascade_system(azimuth45, loops.cascade_design(azimuth45, 0.1), "torque")


def test_elevation_axis_cascade_and_lqg(scene):
    """Elevation at 45°: cascade adequate at 0.15 Hz (bandwidth 0.327 Hz); the LQG stable
    on the full plant with bandwidth 0.775 Hz and input PM 90° (validation/servo_loops.py
    has 10° and 80°: the same to 3 digits, the swinging part turns as a whole).
    """
    ap = rs.axis_plant(scene, "elevation", 45.0)
    r = loops.analyse_cascade(ap, rs.CASCADE_POSITION_HZ)
    assert r.adequate
    assert_close(r.bandwidth_hz, 0.327, rel=0.02)
    ctrl = lqg.design(ap, weights=rs.LQG_WEIGHTS)
    closed = lqg.lqg_system(ap, ctrl)
    assert loop_measures.stable(closed)
    assert_close(loop_measures.margins(lqg.input_loop(ap, ctrl)).pm_deg, 89.5, rel=0.0112)  # ±1°
    assert_close(loop_measures.bandwidth_hz(closed["axis_angle", "reference"]), 0.775, rel=0.03)
