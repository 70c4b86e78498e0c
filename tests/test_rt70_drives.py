"""The RT-70 drive data: rt70/scenes/rt70_drives.py agrees with docs/drives.md, the unit
conversions are right, and every derived number satisfies its stated derivation."""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import eigh

from rt70.errors import Rt70Error
from rt70.scenes import rt70_data as data
from rt70.scenes import rt70_drives as drv
from rt70.testing import MIN_REL, close
from rt70.units import RAD_PER_ARCSEC

DOC = Path(__file__).resolve().parents[1] / "docs" / "drives.md"
AXES = {"az": drv.AZIMUTH_DRIVE, "el": drv.ELEVATION_DRIVE}
KINDS = {"book", "cited", "derived"}


def _table() -> dict[str, dict]:
    """Rows of the table in docs/drives.md by key: SI value (float or None) and kind."""
    rows: dict[str, dict] = {}
    for line in DOC.read_text(encoding="utf-8").splitlines():
        if not line.startswith("| `"):
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        assert len(cells) == 7, f"row with {len(cells)} cells: {line}"
        key = cells[0].strip("`")
        assert key not in rows, f"duplicate row {key}"
        si = None if cells[3] == "—" else float(cells[3])
        rows[key] = {"si": si, "kind": cells[5], "source": cells[6]}
    return rows


TABLE = _table()

#: key suffix → (value of a drive, relative tolerance). Stored fields are compared to
#: rounding (float parsing of the page's number); computed properties to the table's 6
#: printed digits.
ROUNDING, PRINTED = MIN_REL, 1e-5
FIELDS = {
    "nominal_torque": (lambda d: d.nominal_torque, ROUNDING),
    "wind_torque": (lambda d: d.wind_torque, ROUNDING),
    "friction.static_torque": (lambda d: d.friction.static_torque, ROUNDING),
    "friction.top_speed_torque": (lambda d: d.friction.top_speed_torque, ROUNDING),
    "friction.slope": (lambda d: d.friction.slope, PRINTED),
    "reducer.ratio": (lambda d: d.reducer.ratio, ROUNDING),
    "reducer.stiffness": (lambda d: d.reducer.stiffness, ROUNDING),
    "reducer.damping": (lambda d: d.reducer.damping, ROUNDING),
    "motors_per_axis": (lambda d: d.motors_per_axis, ROUNDING),
    "trains.count": (lambda d: d.trains.count, ROUNDING),
    "trains.backlash": (lambda d: d.trains.backlash_half_width, ROUNDING),
    "trains.bias_torque": (lambda d: d.trains.bias_torque, ROUNDING),
    "axis.top_speed": (lambda d: d.friction.top_speed, ROUNDING),
    "reflected_inertia": (lambda d: d.reflected_motor_inertia, PRINTED),
    "reference_inertia": (lambda d: d.reference_inertia, ROUNDING),
    "clamped": (lambda d: d.clamped_hz, ROUNDING),
    "locked_rotor": (lambda d: d.locked_rotor_hz, ROUNDING),
    "sector_radius": (lambda d: d.sector_radius, ROUNDING),
    "servo.position_bandwidth": (lambda d: d.servo.position_bandwidth_hz, ROUNDING),
    "servo.rate_bandwidth": (lambda d: d.servo.rate_bandwidth_hz, ROUNDING),
    "servo.current_bandwidth": (lambda d: d.servo.current_bandwidth_hz, ROUNDING),
    "servo.rate_limit": (lambda d: d.servo.rate_limit, ROUNDING),
    "servo.acceleration_limit": (lambda d: d.servo.acceleration_limit, ROUNDING),
}
FIELDS |= {
    f"motor.{f.name}": ((lambda d, n=f.name: getattr(d.motor, n)), ROUNDING)
    for f in dataclasses.fields(drv.DcMotor)
}
CONSTANTS = {"*.kgf_m": drv.KGF_M, "*.arcsec": RAD_PER_ARCSEC}


def _close(a: float, b: float, rel: float) -> bool:
    """``a`` is ``b`` to ``rel`` of ``|b|`` (:func:`rt70.testing.close`)."""
    return close(a, b, rel=rel)


# --- the page and the module agree ----------------------------------------------------


def test_table_rows_are_well_formed():
    assert len(TABLE) > 40
    assert {r["kind"] for r in TABLE.values()} == KINDS
    for key, row in TABLE.items():
        assert row["kind"] in KINDS, key
        assert row["source"], f"{key} has no source"
        assert re.fullmatch(r"(\*|az|el)\.[a-z_.]+", key), key


@pytest.mark.parametrize("key", sorted(TABLE))
def test_module_holds_the_table_value(key):
    si = TABLE[key]["si"]
    if key in CONSTANTS:
        assert _close(CONSTANTS[key], si, ROUNDING)
        return
    scope, suffix = key.split(".", 1)
    if si is None:  # a prose row: where the drive acts
        assert suffix == "acts_on"
        for d in AXES.values() if scope == "*" else [AXES[scope]]:
            assert d.acts_on
        return
    assert suffix in FIELDS, f"row {key} has no field in rt70_drives"
    value, rel = FIELDS[suffix]
    for d in AXES.values() if scope == "*" else [AXES[scope]]:
        assert _close(float(value(d)), si, rel), (key, d.name, value(d), si)


def test_every_field_has_a_row():
    """The reverse direction: no number in the module without its row (and source)."""
    for suffix in FIELDS:
        scopes = [s for s in ("*", "az", "el") if f"{s}.{suffix}" in TABLE]
        assert scopes, f"field {suffix} has no row in docs/drives.md"
        if "*" not in scopes and suffix != "sector_radius":
            assert set(scopes) == {"az", "el"}, suffix
    assert drv.AZIMUTH_DRIVE.sector_radius is None  # azimuth: a torque drive


def test_the_table_check_can_fail(monkeypatch):
    monkeypatch.setitem(TABLE, "az.reducer.stiffness", {**TABLE["az.reducer.stiffness"]})
    TABLE["az.reducer.stiffness"]["si"] *= 1.001
    with pytest.raises(AssertionError):
        test_module_holds_the_table_value("az.reducer.stiffness")


# --- unit conversions -----------------------------------------------------------------


def test_book_torques_are_converted_from_kgf_m():
    g = 9.80665
    assert drv.KGF_M == g
    d = drv.AZIMUTH_DRIVE
    assert _close(d.nominal_torque, 5e6 * g, 1e-14)
    assert _close(d.wind_torque, 5e5 * g, 1e-14)
    assert _close(d.friction.static_torque, 7e4 * g, 1e-14)
    assert _close(d.friction.top_speed_torque, 1.5e5 * g, 1e-14)  # mid of (1–2)·10⁵
    assert 1e5 * g <= d.friction.top_speed_torque <= 2e5 * g
    assert _close(d.trains.bias_torque, 2.85e5 * g, PRINTED)


def test_angle_and_speed_units():
    assert _close(RAD_PER_ARCSEC, math.radians(1 / 3600), 1e-14)
    assert _close(drv.AZIMUTH_DRIVE.trains.backlash_half_width, RAD_PER_ARCSEC, PRINTED)
    motor = drv.MOTOR
    assert _close(motor.rated_speed, 2 * math.pi * 3000 / 60, PRINTED)
    top = drv.AZIMUTH_DRIVE.friction.top_speed
    assert _close(top, motor.rated_speed / drv.REDUCER_RATIO, PRINTED)
    assert _close(math.degrees(top), 0.18, PRINTED)


# --- derivations ----------------------------------------------------------------------


def test_motor_derivation():
    m, d = drv.MOTOR, drv.AZIMUTH_DRIVE
    i_r, n = d.reducer.ratio, d.motors_per_axis
    assert _close(m.rated_torque, d.nominal_torque / (n * i_r), PRINTED)
    assert _close(m.back_emf_constant, 0.9 * m.rated_voltage / m.rated_speed, PRINTED)
    assert m.torque_constant == m.back_emf_constant  # SI gyrator
    assert _close(m.rated_current, m.rated_torque / m.torque_constant, PRINTED)
    assert _close(m.armature_resistance, 0.1 * m.rated_voltage / m.rated_current, PRINTED)
    assert _close(m.electrical_time_constant, 0.02, PRINTED)
    t_em = m.rotor_inertia * m.armature_resistance / (m.back_emf_constant * m.torque_constant)
    assert _close(t_em, 0.05, PRINTED)
    assert _close(m.viscous_friction, 0.01 * m.rated_torque / m.rated_speed, PRINTED)
    assert _close(m.peak_torque, 2 * m.rated_torque, PRINTED)
    # the electrical balance at the rated point: U = R I + c_e ω
    u = m.armature_resistance * m.rated_current + m.back_emf_constant * m.rated_speed
    assert _close(u, m.rated_voltage, PRINTED)
    print(f"rated power per motor {m.rated_torque * m.rated_speed / 1e3:.1f} kW")


def test_reference_inertias_from_the_listing():
    bodies = {b["name"]: b for b in data.LISTING_BODIES}
    j_az = sum(b["moments"][2] for b in data.LISTING_BODIES)
    on_axis = (
        b["offset"][:2] == (0.0, 0.0) and b["com"] == (0.0, 0.0, 0.0) for b in bodies.values()
    )
    assert all(on_axis)
    assert _close(drv.AZIMUTH_DRIVE.reference_inertia, j_az, ROUNDING)

    def height_over_base(name: str) -> float:
        z = 0.0
        while name != "base":
            z += bodies[name]["offset"][2]
            name = bodies[name]["parent"]
        return z

    swinging = [n for n in bodies if n not in ("platform",)]
    j_el = sum(
        bodies[n]["moments"][0] + bodies[n]["mass"] * height_over_base(n) ** 2 for n in swinging
    )
    assert _close(drv.ELEVATION_DRIVE.reference_inertia, j_el, ROUNDING)
    assert _close(height_over_base("counterweight"), drv.ELEVATION_DRIVE.sector_radius, ROUNDING)


def _chapter2(axis: str) -> tuple[np.ndarray, np.ndarray, float]:
    """Stiffness, inertia (tables' numbers) and first free elastic frequency (Hz)."""
    if axis == "az":
        nodes, links, gamma = data.AZIMUTH_NODES, data.AZIMUTH_LINKS, data.GAMMA_ALPHA
        inertia = np.diag([n["I_el0"] for n in nodes])
        c = np.diag([link["C_el0"] for link in links])
    else:
        nodes, links, gamma = data.ELEVATION_NODES, data.ELEVATION_LINKS, data.GAMMA_BETA
        inertia = np.diag([n["I"] for n in nodes])
        c = np.diag([link["C"] for link in links])
    g = np.asarray(gamma, dtype=float)
    k = g.T @ c @ g
    free = np.sqrt(np.abs(eigh(k, inertia, eigvals_only=True))) / (2 * np.pi)
    return k, inertia, float(free[1])


def _locked_rotor_hz(axis: str, c_r: float) -> float:
    """Lowest frequency with the drive node (node 1) held by the reducer spring c_r."""
    k, inertia, _ = _chapter2(axis)
    if math.isinf(c_r):
        k, inertia = k[1:, 1:], inertia[1:, 1:]
    else:
        k = k.copy()
        k[0, 0] += c_r
    return float(np.sqrt(eigh(k, inertia, eigvals_only=True)[0]) / (2 * np.pi))


@pytest.mark.parametrize("axis", ["az", "el"])
def test_reducer_from_the_locked_rotor_target(axis):
    d = AXES[axis]
    clamped = _locked_rotor_hz(axis, math.inf)
    locked = _locked_rotor_hz(axis, d.reducer.stiffness)
    print(f"{axis}: clamped {clamped:.6g} Hz, locked rotor {locked:.6g} Hz")
    assert _close(d.clamped_hz, clamped, PRINTED)
    assert _close(d.locked_rotor_hz, locked, PRINTED)
    assert _close(locked / clamped, 0.95, 2e-4)  # C_r rounded to 4 digits
    # rounding C_r is what moves the ratio off 0.95: a 1 % stiffer reducer moves it more
    assert not _close(_locked_rotor_hz(axis, 1.01 * d.reducer.stiffness) / clamped, 0.95, 2e-4)
    # D_r from the §2.3 hypothesis δ = 0.1/Ω₁ at the locked-rotor frequency
    assert _close(d.reducer.damping, 0.1 * d.reducer.stiffness / (2 * np.pi * locked), PRINTED)


@pytest.mark.parametrize("axis", ["az", "el"])
def test_locked_rotor_is_below_the_first_free_elastic_frequency(axis):
    """Interlacing: holding the drive node can only lower the first elastic frequency."""
    _, _, first_free = _chapter2(axis)
    assert AXES[axis].clamped_hz < first_free
    if axis == "az":
        assert _close(first_free, 1.265, 8e-4)  # rt70-data.md §A: ±1 in the last digit
        assert AXES[axis].locked_rotor_hz < AXES[axis].servo.position_bandwidth_hz


@pytest.mark.parametrize("axis", ["az", "el"])
def test_acceleration_limit(axis):
    d = AXES[axis]
    assert _close(d.reflected_motor_inertia, 2 * drv.MOTOR.rotor_inertia * 1e10, 1e-14)
    available = d.nominal_torque - d.friction.top_speed_torque - d.wind_torque
    expected = available / (d.reference_inertia + d.reflected_motor_inertia)
    assert _close(d.servo.acceleration_limit, expected, PRINTED)
    assert d.servo.rate_limit == d.friction.top_speed
    assert _close(d.servo.rate_bandwidth_hz, 5 * d.servo.position_bandwidth_hz, ROUNDING)
    assert _close(d.servo.current_bandwidth_hz, 5 * d.servo.rate_bandwidth_hz, ROUNDING)
    assert d.servo.current_bandwidth_hz > 1 / (2 * np.pi * d.motor.electrical_time_constant)


def test_gravity_unbalance_of_the_listing():
    """docs/drives.md §3: the listing's swinging part outweighs the drive's torque."""
    bodies = {b["name"]: b for b in data.LISTING_BODIES}
    arms = {"counterweight": 16.0, "mirror_base": 11.0, "main_mirror": 31.0, "rigel": 38.0}
    arms["counterreflector"] = 44.0
    moment = sum(bodies[n]["mass"] * arm for n, arm in arms.items())
    torque = 9.81 * moment
    # the page's numbers, to ±1 in their last printed digit
    assert _close(torque, 1.30e8, 5e-3)
    assert _close(torque / drv.ELEVATION_DRIVE.nominal_torque, 2.66, 4e-3)
    mirrored = 9.81 * abs(moment - 2 * bodies["counterweight"]["mass"] * 16.0)
    assert _close(mirrored, 2.03e7, 5e-3)


# --- the dataclasses ------------------------------------------------------------------


def test_drives_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        drv.AZIMUTH_DRIVE.reducer.stiffness = 0.0  # type: ignore[misc]
    assert drv.DRIVES["elevation"] is drv.ELEVATION_DRIVE


def test_bad_values_name_the_field():
    with pytest.raises(Rt70Error, match="Reducer.stiffness"):
        dataclasses.replace(drv.AZIMUTH_DRIVE.reducer, stiffness=-1.0)
    with pytest.raises(Rt70Error, match="DcMotor.armature_resistance"):
        dataclasses.replace(drv.MOTOR, armature_resistance=math.nan)
    with pytest.raises(Rt70Error, match="top_speed_torque"):
        dataclasses.replace(drv.FRICTION, top_speed_torque=1.0)
    with pytest.raises(Rt70Error, match="GearTrains.count"):
        dataclasses.replace(drv.TRAINS, count=0)
    with pytest.raises(Rt70Error, match="3 motors for 2 gear trains"):
        dataclasses.replace(drv.AZIMUTH_DRIVE, motors_per_axis=3)
    with pytest.raises(Rt70Error, match="sector_radius"):
        dataclasses.replace(drv.ELEVATION_DRIVE, sector_radius=0.0)


def test_ratio_choice_numbers_of_the_page():
    """docs/drives.md §2: why 10⁵, and how much the rotors dominate the axis inertia."""
    m = drv.MOTOR
    slow = m.rated_speed / 1e6  # the book's upper ratio
    # the page's numbers, to ±1 in their last printed digit
    assert _close(math.degrees(slow), 0.018, PRINTED)
    assert _close(math.pi / slow / 3600, 2.78, 4e-3)  # hours for 180°
    refl = drv.AZIMUTH_DRIVE.reflected_motor_inertia
    assert _close(refl / drv.AZIMUTH_DRIVE.reference_inertia, 178.0, 6e-4)
    assert _close(refl / drv.ELEVATION_DRIVE.reference_inertia, 24.9, 4e-3)
    assert _close(m.rated_torque * m.rated_speed, 77.0e3, 7e-4)
