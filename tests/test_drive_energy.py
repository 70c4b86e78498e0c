"""Scene drives in a simulation: both backends agree, and the energy balance closes.

    ∫u I − ∫(R_a I² + D_m ω_m² + D_r Δ̇²) = Δ(½L_a I² + ½J_m ω_m² + ½C_r Δ²)
                                          + Δ(T + U_g + U_c) + E_ψ

(:mod:`rt70.control.drive_energy`). It closes to the integration tolerance only because the
drive's force is the gradient of the angle its twist is measured on; the book's
Δβ = β − α_m/i_r on the elevation coordinate with the force through the sector does not
(the last test).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rt70.control.drive_energy import AuditedDrive, energy_balance
from rt70.control.drives import DcDrive, drive_parameters, scene_drive, scene_drives
from rt70.control.servo import ServoDrive, cascade_gains
from rt70.model.couplings import CoordinateCoupling, SceneCoupling
from rt70.model.scene import load_scene
from rt70.simulation.simulate import simulate
from rt70.testing import MIN_REL, assert_close

TURRET = Path(__file__).parent / "data" / "turret_drives.urdf"
VOLTS = {"azimuth": 6.0, "elevation": 12.0}
RTOL = 1e-9
T_END = 0.3


@pytest.fixture(scope="module")
def turret():
    return load_scene(TURRET)


def _run(scene, side, components, t_end=T_END, rtol=RTOL, method="DOP853"):
    return simulate(
        scene, (0.0, t_end), side=side, components=components, method=method,
        rtol=rtol, t_eval=np.linspace(0.0, t_end, 7),
    )  # fmt: skip


@pytest.fixture(scope="module")
def runs(turret):
    """A voltage step on both drives of the turret, on each side, audited."""
    out = {}
    for side in ("reference", "textbook"):
        audited = [AuditedDrive(d) for d in scene_drives(turret, side, voltage=VOLTS)]
        out[side] = (_run(turret, side, audited), audited)
    return out


@pytest.mark.slow
def test_sides_agree_on_the_driven_trajectory(runs):
    (a, _), (b, _) = runs["reference"], runs["textbook"]
    assert a.success and b.success
    moved = np.max(np.abs(a.q))
    assert moved > 0.1  # the step turned the axes
    assert_close(b.q, a.q, rel=10 * RTOL, scale=moved)
    for name in ("azimuth:current", "elevation:motor_speed", "elevation:electrical_work"):
        assert_close(b.states[name], a.states[name], rel=10 * RTOL, what=name)


@pytest.mark.parametrize("side", ["reference", "textbook"])
def test_energy_balance_closes_with_drives(runs, side):
    run, audited = runs[side]
    residual, scale = energy_balance(run, audited)
    assert scale > 1.0  # joules exchanged: electrical work, losses, the structure's energy
    assert residual[0] == 0.0  # the balance starts from the same numbers on both sides
    print(f"{side}: residual {np.max(np.abs(residual)) / scale:.2e} of {scale:.3g} J")
    assert_close(residual, np.zeros_like(residual), rel=RTOL, scale=scale)
    # every flow took part
    for flow in ("armature_loss", "motor_loss", "reducer_loss"):
        assert run.states[f"elevation:{flow}"][-1] > 0.0


def test_energy_balance_closes_on_the_rt70(tmp_path):
    """Both drives of rt70_servo under a voltage step, from the undeformed zenith pointing."""
    scene = load_scene("rt70_servo")
    audited = [AuditedDrive(d) for d in scene_drives(scene, "reference", voltage=20.0)]
    run = _run(scene, "reference", audited, t_end=0.01, rtol=1e-8, method="Radau")
    residual, scale = energy_balance(run, audited)
    print(f"rt70_servo: residual {np.max(np.abs(residual)) / scale:.2e} of {scale:.3g} J")
    assert run.states["azimuth:electrical_work"][-1] > 1.0
    assert_close(residual, np.zeros_like(residual), rel=1e-8, scale=scale)


class _BookCoupling(CoordinateCoupling):
    """Δβ = β − α_m/i_r on the elevation coordinate, the force through the sector."""

    def __init__(self, scene, drive, side):
        super().__init__(scene.coordinate_names, drive.joint)
        self.sector = SceneCoupling(scene, drive, side)

    def force(self, q, torque):
        return self.sector.force(q, torque)


def test_twist_on_the_coordinate_with_the_sector_force_breaks_the_balance(turret):
    """The book's Δβ (4.146) on β = el while the sector's force acts: not a gradient pair."""
    el = turret.description.drives[1]
    drive = DcDrive(
        "elevation", None, None, drive_parameters(el), 12.0,
        coupling=_BookCoupling(turret, el, "reference"),
    )  # fmt: skip
    audited = [AuditedDrive(drive)]
    run = _run(turret, "reference", audited)
    residual, scale = energy_balance(run, audited)
    print(f"book's twist: residual {np.max(np.abs(residual)) / scale:.2e} of {scale:.3g} J")
    assert np.max(np.abs(residual)) > 1e4 * RTOL * scale


@pytest.mark.slow
def test_servo_reads_the_drive_angle_and_its_energy_balances(turret):
    """A ServoDrive on the scene's elevation sector: its position loop reads θ_d, not the
    coordinate; the audit (voltage read back from the loop) closes the balance."""
    el = scene_drive(turret, "elevation")
    inertia = 0.5 + 3 * (0.2**2 + 0.5**2) + 0.1 + 2 * 1.1**2  # rough rigid el inertia
    p = drive_parameters(el, inertia)
    gains = cascade_gains(p, inertia, position_hz=0.3)
    servo = ServoDrive(
        "elevation", None, None, p, gains, lambda t: 0.1,
        coupling=SceneCoupling(turret, el, "reference"),
    )  # fmt: skip
    q = np.array([0.0, 0.2, 0.01, 0.03])  # the hinge bent: θ_d ≠ el
    theta = servo.coupling.angle(q)
    assert abs(theta - q[1]) > 1e-3
    errors, _, _ = servo._loops(0.0, q, np.zeros(6))
    assert_close(errors[0], 0.1 - theta, rel=MIN_REL, scale=0.1 + abs(theta))
    audited = [AuditedDrive(servo)]
    run = _run(turret, "reference", audited, t_end=0.6)
    residual, scale = energy_balance(run, audited)
    assert_close(residual, np.zeros_like(residual), rel=RTOL, scale=scale)
    assert 0.02 < servo.coupling.angle(run.q[-1]) < 0.1  # on its way to the 0.1 rad step
