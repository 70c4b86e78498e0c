"""Locked-rotor linear model and spectrum of a scene with drives (issue 10, item 7)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rt70.cli.main import main
from rt70.linear import linearize as lin
from rt70.linear import modal
from rt70.model.scene import load_scene
from rt70.scenes.rt70_state import rt70_pointing
from rt70.testing import assert_close, tolerance


@pytest.fixture(scope="module")
def rt70_servo_45():
    scene = load_scene("rt70_servo")
    held = rt70_pointing(45.0)
    q0 = lin.equilibrium(scene, held)
    return scene, held, lin.linearize(scene, q0)


def test_the_reducers_add_their_springs_on_the_drive_angles(rt70_servo_45):
    scene, _, free = rt70_servo_45
    locked = lin.locked_rotor(scene, free)
    by_name = {d.name: d for d in scene.description.drives}
    added = locked.K - free.K
    k_az = free.coordinates.index("platform_rz")
    # the azimuth drive is a torque drive: exactly C_r on its own coordinate, to the
    # rounding of the difference locked.K − free.K
    scale = abs(locked.K[k_az, k_az])
    assert_close(added[k_az, k_az], by_name["azimuth"].C_r, rel=1e-12, scale=scale)
    # the elevation sector's gradient is dominated by base_rx (= 1 on the undeformed
    # structure, the equilibrium sag changes it little)
    k_el = free.coordinates.index("base_rx")
    assert_close(added[k_el, k_el], by_name["elevation"].C_r, rel=1e-3)
    assert_close(added, added.T, rel=1e-12)
    assert np.linalg.matrix_rank(added, tol=1e-9 * np.abs(added).max()) == 2


def test_locked_rotor_spectrum_lies_between_free_and_clamped(rt70_servo_45):
    """Adding two springs raises each eigenvalue, no higher than clamping the drive angles.

    Clamped: the two constraints ``g_d·δq = 0`` (the reducers rigid), imposed by a basis
    T of their null space, ``Tᵀ M T``, ``Tᵀ K T``.
    """
    import scipy.linalg

    from rt70.textbook.drives import drive_force

    scene, _, free = rt70_servo_45
    locked = lin.locked_rotor(scene, free)
    G = np.array(
        [
            drive_force(scene.textbook, scene.textbook_data, free.q0, d)[1]
            for d in scene.description.drives
        ]
    )
    T = scipy.linalg.null_space(G)
    f_free = modal.modes(free.M, free.K).freq_hz
    f_locked = modal.modes(locked.M, locked.K).freq_hz
    f_clamped = modal.modes(T.T @ free.M @ T, T.T @ free.K @ T).freq_hz
    assert modal.modes(locked.M, locked.K).rigid.sum() == 0
    assert modal.modes(free.M, free.K).rigid.sum() == 1  # azimuth is free
    # the eigenvalues ω² ∝ f² round on the scale of the largest: compare f², with that slack
    slack = tolerance(1e-12, f_free.max() ** 2)
    assert np.all(f_locked**2 >= f_free**2 - slack)
    # interlacing under two added constraints: f_locked[i] ≤ f_clamped[i] (40 modes)
    assert np.all(f_locked[:40] ** 2 <= f_clamped**2 + slack)


def test_rt70_modes_reports_the_locked_rotor_spectrum(capsys):
    assert main(["modes", "rt70_servo", "--elevation", "45", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["locked_rotor"] is True
    kinds = {r["kind"] for r in out["modes"]}
    assert not kinds & {"rigid", "unstable"}
    assert main(["modes", "rt70", "--json"]) == 0  # no drives: the free axes as before
    out = json.loads(capsys.readouterr().out)
    assert out["locked_rotor"] is False
