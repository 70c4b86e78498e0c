"""The RT-70 scenes on the 42-DOF listing of §4.2.3: as listed, as a control object, with a jack.

:func:`rt70_scene` is the listing (errata in ``docs/rt70-errata.md``);
:func:`rt70_servo_scene` the control object the drives hold, with the counterweight below the
elevation axis, its two drives (:func:`lumped_drive`) and its exposed bodies;
:func:`rt70_jack_scene` the listing with an elevation jack closing one loop.
Each returns the URDF text; :mod:`rt70.scenes.generate` writes them with every other
scene.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from rt70.control.geartrains import parallel_drive
from rt70.scenes import rt70_data, rt70_drives, rt70_state, rt70_wind
from rt70.scenes import urdf_writer as uw
from rt70.scenes.rt70_visuals import body_visual
from rt70.scenes.urdf_writer import ZERO3, check_name, fmt, fmt_vec
from rt70.urdf.beams import expand_beams
from rt70.urdf.description import DRIVE_PARAMETERS


def rt70_scene() -> str:
    """Build the 42-DOF nonlinear RT-70 of the §4.2.3 listing.

    Returns
    -------
    str
        URDF text: seven bodies, each on a 6-DOF pair (six 1-DOF joints) in pair order
        1..7, direct elastic pairs as bushings, the two strut packages, gravity and the
        optical points.
    """
    return _rt70_text(
        "rt70",
        "RT-70 radio telescope, 42-DOF nonlinear model (Dubarenko 2007, "
        "listing of section 4.2.3, errata in docs/rt70-errata.md)",
        rt70_data.LISTING_BODIES,
    )


def rt70_servo_scene() -> str:
    """Build the RT-70 the drives can hold: the listing with its counterweight below the axis.

    The listing puts the counterweight 16 m *above* the elevation axis, on the mirror's
    side, so nothing balances the swinging part: its gravity moment with the axis
    horizontal is 2.66 times the book's nominal drive torque (errata item 12). This
    scene is the listing with the counterweight's offset mirrored to ``[0, 0, −16]`` m
    (:data:`rt70_data.SERVO_BODIES`), the control object the drives hold, with its two
    drives (``<rt70:drive>``, :func:`_servo_drives`) and its four exposed bodies
    (``<rt70:wind>``, :func:`_servo_winds`).
    """
    return _rt70_text(
        "rt70_servo",
        "RT-70 radio telescope as a control object: the 42-DOF listing of section 4.2.3 "
        "with the counterweight below the elevation axis (errata item 12 in "
        "docs/rt70-errata.md) and the azimuth and elevation drives",
        rt70_data.SERVO_BODIES,
        drives=_servo_drives_and_winds,
        servos=True,
    )


def _servo_drives_and_winds(w: uw.Writer) -> None:
    """The servo scene's drives, then its wind elements."""
    _servo_drives(w)
    _servo_winds(w)


def _servo_winds(w: uw.Writer) -> None:
    """The RT-70's exposed bodies and the air (docs/wind.md, :mod:`rt70_wind`)."""
    w.comment(
        "Wind (section 4.1.6; docs/wind.md): exposed bodies, derived shapes; ISA sea-level "
        "air (the Suffa plateau, ~2.3 km: ~0.97 kg/m3)"
    )
    w.empty("rt70:air", ("density", fmt(1.225)))
    for e in rt70_wind.wind_elements():
        w.empty(
            "rt70:wind",
            ("name", e["name"]),
            ("link", e["link"]),
            ("shape", e["shape"]),
            ("area", fmt(e["area"])),
            ("length", fmt(e["length"])),
            ("xyz", fmt_vec(e["xyz"])),
            ("axis", fmt_vec(e["axis"])),
        )


def lumped_drive(axis: rt70_drives.AxisDrive) -> dict[str, float]:
    """One equivalent motor for an axis's ``n`` identical motors on one armature voltage.

    The motors drive the axis through their own gear trains with the same ratio, so
    they turn at one speed: ``n`` armatures in parallel carry ``n`` times the current of
    one, with the same EMF, and their rotors add up. The equivalent motor has
    ``L_a / n``, ``R_a / n``, the same ``c_m``, ``c_e``, and ``n J_m``, ``n D_m``
    (its nominal torque, ``c_m`` times ``n`` rated currents, is ``n`` motors' torque;
    its reflected inertia ``n J_m i_r²`` is docs/drives.md's ``*.reflected_inertia``).
    The reducer's stiffness and damping are the axis's (axis-referred, both trains).
    The counter-torque of the two trains (backlash remedy) is not modelled here.
    """
    p = parallel_drive(axis.motor_parameters(axis.reference_inertia), axis.motors_per_axis)
    return {key: getattr(p, key) for key in DRIVE_PARAMETERS}


def _servo_drives(w: uw.Writer) -> None:
    """The RT-70's azimuth and elevation drives (book 4.1.7, Fig. 4.8; docs/drives.md).

    Azimuth: the reducer torque about ``platform_rz``'s axis, on the platform (4.143).
    Elevation: a gear sector of radius 16 m on the counterweight (4.150), meshing with a
    pinion on the platform at the counterweight's origin, 16 m below the elevation axis
    (``base_rx``): its tangent is the counterweight's +y, which a positive ``base_rx``
    turns positively about x, so a positive motor angle raises ``base_rx``.
    """
    w.comment("Drives (section 4.1.7; parameters: docs/drives.md, lumped motors)")
    az, el = rt70_drives.AZIMUTH_DRIVE, rt70_drives.ELEVATION_DRIVE
    for axis, joint in ((az, "platform_rz"), (el, "base_rx")):
        attrs = [("name", axis.name), ("joint", joint)]
        attrs += [(key, fmt(value)) for key, value in lumped_drive(axis).items()]
        if axis.sector_radius is None:
            w.empty("rt70:drive", *attrs)
            continue
        w.open("rt70:drive", *attrs)
        w.empty(
            "rt70:sector",
            ("link", "counterweight"),
            ("xyz", fmt_vec(ZERO3)),
            ("direction", "0 1 0"),
            ("axis", "1 0 0"),
            ("radius", fmt(axis.sector_radius)),
            ("stator", "platform"),
        )
        w.close("rt70:drive")


def _rt70_text(
    name: str,
    description: str,
    listing_bodies: Sequence[dict],
    drives: Callable[[uw.Writer], None] | None = None,
    servos: bool = False,
    column: bool = False,
) -> str:
    """The 42-DOF RT-70 URDF text with the given bodies (the listing's or a variant).

    ``drives`` writes the scene's ``<rt70:drive>`` elements (or other elements), after the
    optical points; ``servos`` gives the mount's axes their ``<rt70:servo>`` (on the
    drives :func:`_servo_drives` writes); ``column`` puts the counterreflector on its
    flexible column (:func:`_counterreflector_column`) instead of its 6-DOF pair.
    """
    d = rt70_data
    bodies = {b["name"]: b for b in listing_bodies}
    w = uw.Writer()
    uw.begin(w, name, description)
    for body in listing_bodies:
        if column and body["name"] == "counterreflector":
            _counterreflector_column(w, body)
            continue
        uw.six_dof_body(
            w,
            body["name"],
            body["parent"],
            body["offset"],
            body["mass"],
            body["moments"],
            body["com"],
            visual=body_visual(body),
        )
    w.blank()
    w.comment("Gravity (erratum 2: z up)")
    uw.gravity(w, d.LISTING_GRAVITY)
    w.comment("Direct elastic pairs: frame 1 = construction frame, frame 2 = body frame")
    for pair in d.LISTING_DIRECT_PAIRS:
        if column and pair["child"] == "counterreflector":
            continue
        child = bodies[pair["child"]]
        uw.bushing(
            w,
            pair["name"],
            pair["stiffness"],
            pair["damping"],
            child["parent"],
            child["name"],
            xyz1=child["offset"],
        )
    w.comment("Strut packages (erratum 7: mirrored attachment points, same inclination)")
    for package in d.LISTING_STRUT_PACKAGES:
        child = bodies[package["child"]]
        w.open(
            "rt70:strut_package",
            ("name", check_name(package["name"])),
            ("parent", check_name(child["parent"])),
            ("child", check_name(child["name"])),
            ("xyz", fmt_vec(child["offset"])),
            ("rpy", fmt_vec(ZERO3)),
        )
        for strut in package["struts"]:
            w.empty(
                "rt70:strut",
                ("name", check_name(strut["name"])),
                ("xyz", fmt_vec(strut["xyz"])),
                ("rpy", fmt_vec(strut["rpy"])),
                ("stiffness", fmt_vec(strut["stiffness"])),
                ("damping", fmt_vec(strut["damping"])),
            )
        w.close("rt70:strut_package")
    _optical_points(w)
    _mount(w, servos=servos)
    _optics(w)
    if drives is not None:
        drives(w)
    return uw.end(w)


def _optical_points(w: uw.Writer) -> None:
    """The listing's optical points (book 4.1.8)."""
    w.comment("Optical points (section 4.1.8)")
    for point in rt70_data.LISTING_OPTICAL_POINTS:
        w.empty(
            "rt70:optical_point",
            ("name", check_name(point["name"])),
            ("link", check_name(point["link"])),
            ("xyz", fmt_vec(point["xyz"])),
        )


def _mount(w: uw.Writer, servos: bool) -> None:
    """The RT-70's pointing axes (``<rt70:mount>``), with their servos if it has drives.

    Azimuth A = ``platform_rz``, elevation E with ``base_rx = π/2 − E`` (q = 0 is the
    zenith); E from 0 (horizon) to 90° (zenith), A one turn either way (the ranges the
    command line holds).
    """
    w.comment("Pointing axes: q = 0 looks at the zenith; base_rx = 90 deg - E")
    w.open("rt70:mount", ("type", "az-el"))
    axes = (
        ("azimuth", rt70_state.AZIMUTH_COORDINATE, "0", "1", "-360", "360"),
        ("elevation", rt70_state.ELEVATION_COORDINATE, "90", "-1", "0", "90"),
    )
    for name, joint, zero, sign, low, high in axes:
        attrs = (
            ("name", name),
            ("joint", joint),
            ("zero_deg", zero),
            ("sign", sign),
            ("min_deg", low),
            ("max_deg", high),
        )
        if not servos:
            w.empty("rt70:axis", *attrs)
            continue
        w.open("rt70:axis", *attrs)
        w.empty("rt70:servo", *servo_attributes(rt70_drives.DRIVES[name]))
        w.close("rt70:axis")
    w.close("rt70:mount")


#: Position-loop bandwidths (Hz) chosen for the RT-70 (docs/servo-scenarios.md): the
#: azimuth loops sit below the 0.92 Hz locked-rotor resonance, the elevation loops
#: below its 2.77 Hz one; each loop five times faster than the one around it.
RT70_POSITION_HZ = {"azimuth": 0.2, "elevation": 0.5}


def servo_attributes(axis: rt70_drives.AxisDrive) -> tuple[tuple[str, str], ...]:
    """The ``<rt70:servo>`` of an RT-70 axis: its drive's limits and the chosen design.

    The torque limit is the axis's ``n`` motors at their peak torque through the
    reducer, ``n T_peak i_r``; the voltage limit the rated voltage (the scene's drive
    lumps the motors in parallel, :func:`lumped_drive`); the design inertia the
    listing's (docs/drives.md, ``*.reference_inertia``); the dry friction the book's.
    """
    m, f = axis.motor, axis.friction
    return (
        ("drive", axis.name),
        ("position_bandwidth_hz", fmt(RT70_POSITION_HZ[axis.name])),
        ("loop_ratio", "5"),
        ("rate_limit_deg_s", fmt(math.degrees(axis.servo.rate_limit))),
        ("torque_limit", fmt(axis.motors_per_axis * m.peak_torque * axis.reducer.ratio)),
        ("voltage_limit", fmt(m.rated_voltage)),
        ("nominal_torque", fmt(axis.nominal_torque)),
        ("reference_inertia", fmt(axis.reference_inertia)),
        ("static_friction", fmt(f.static_torque)),
        ("top_speed_friction", fmt(f.top_speed_torque)),
    )


def _optics(w: uw.Writer) -> None:
    """The RT-70's reflector system (``<rt70:optics>``, book 4.1.8).

    Gregorian: the counterreflector is an ellipsoid of revolution (book §4.1.8); the
    reference ring (OK) is the mirror base (body 4); the counterreflector's drive is on
    the rigel (body 6), its construction frame 7c parallel to the rigel's.
    """
    main_focus, main_vertex, cr_focus, cr_vertex = (
        p["name"] for p in rt70_data.LISTING_OPTICAL_POINTS
    )
    w.comment("Reflector system: Gregorian; reference ring = the mirror base")
    w.open("rt70:optics", ("type", "gregorian"), ("reference_link", "mirror_base"))
    w.empty("rt70:reflector", ("role", "primary"), ("focus", main_focus), ("vertex", main_vertex))
    w.empty(
        "rt70:reflector",
        ("role", "secondary"),
        ("focus", cr_focus),
        ("vertex", cr_vertex),
        ("support", "rigel"),
    )
    w.close("rt70:optics")


#: The elevation jack of the ``rt70_jack`` scene (the RT-70 with one closed loop).
#: The book's RT-70 drives the elevation through a gear sector; this jack is an
#: illustrative linkage of our own, not the telescope's: a hydraulic-cylinder-like pair
#: pinned on the alidade (``platform``) 16 m from the counterweight's origin along −y,
#: level with it, turning about x, a piston sliding along it, the piston's end pinned to
#: the counterweight (``<rt70:loop type="point">``, three rows). Uniform rods of steel
#: tube size, masses our assumption (negligible beside the 1570 t structure).
RT70_JACK = {
    "pivot": (0.0, -16.0, 36.0),  # on the platform, m: the counterweight's origin − 16 m y
    "cylinder": (8.0, 8000.0, 0.3),  # length m, mass kg, radius m
    "piston": (8.0, 4000.0, 0.2),  # its far end is 16 m from the pivot at q = 0
}


def _rt70_jack(w: uw.Writer) -> None:
    """The elevation jack (:data:`RT70_JACK`): two bodies and the loop on the counterweight."""
    from rt70.scenes.loop_scenes import loop

    jack = RT70_JACK
    w.comment("Elevation jack (closed-chain test linkage, not the book's drive): cylinder, piston")
    pivot = jack["pivot"]
    uw.joint(w, "jack_pivot", "revolute", "platform", "jack_cylinder", pivot, axis=(1, 0, 0))
    length, mass, radius = jack["cylinder"]
    transverse = mass * length**2 / 12.0
    axial = 0.5 * mass * radius**2
    uw.massive_link(
        w, "jack_cylinder", mass, (transverse, axial, transverse), com=(0.0, length / 2.0, 0.0)
    )
    uw.joint(w, "jack_stroke", "prismatic", "jack_cylinder", "jack_piston", axis=(0, 1, 0))
    p_length, p_mass, p_radius = jack["piston"]
    reach = -jack["pivot"][1]
    p_transverse = p_mass * p_length**2 / 12.0
    uw.massive_link(
        w,
        "jack_piston",
        p_mass,
        (p_transverse, 0.5 * p_mass * p_radius**2, p_transverse),
        com=(0.0, reach - p_length / 2.0, 0.0),
    )
    loop(w, "jack_counterweight", "jack_piston", "counterweight", xyz1=(0.0, reach, 0.0))


def rt70_flexible_scene() -> str:
    """The RT-70 control object with its counterreflector on a flexible column.

    :func:`rt70_servo_scene` (drives, servos, wind) with the listing's direct pair
    rigel–counterreflector replaced by a steel column of rigid finite elements
    (``<rt70:beam>``, :data:`rt70_data.COUNTERREFLECTOR_COLUMN`, docs/beams.md), written
    out in the file (:func:`rt70.urdf.beams.expand_beams`) so that Pinocchio's parser and
    URDF viewers see the column's segments too.
    """
    text = _rt70_text(
        "rt70_flexible",
        "RT-70 radio telescope as a control object (rt70_servo) with the counterreflector "
        "on a flexible steel column of rigid finite elements instead of its 6-DOF pair",
        rt70_data.SERVO_BODIES,
        drives=_servo_drives_and_winds,
        servos=True,
        column=True,
    )
    return expand_beams(text, "rt70_flexible")  # written out: any URDF reader sees the column


def _counterreflector_column(w: uw.Writer, body: dict) -> None:
    """The counterreflector on its column: the beam along the rigel's z, the body at its end.

    The beam runs along its own x, turned onto the rigel's z by ``rpy = (0, −π/2, 0)``;
    the counterreflector is fixed to the beam's end with the inverse turn, so its frame is
    parallel to the rigel's, ``offset`` above it, as in the listing.
    """
    c = rt70_data.COUNTERREFLECTOR_COLUMN
    length = float(np.linalg.norm(body["offset"]))
    if not np.allclose(body["offset"], (0.0, 0.0, c["length"])):
        raise ValueError(f"the column runs along z for {c['length']} m, not to {body['offset']}")
    w.comment(
        f"{body['name']}: on a flexible column from {body['parent']} (COUNTERREFLECTOR_COLUMN)"
    )
    uw.massive_link(
        w, body["name"], body["mass"], body["moments"], body["com"], visual=body_visual(body)
    )
    w.empty(
        "rt70:beam",
        ("name", "column"),
        ("parent", check_name(body["parent"])),
        ("length", fmt(length)),
        ("rpy", fmt_vec((0.0, -np.pi / 2.0, 0.0))),
        ("segments", str(int(c["segments"]))),
        *((key, fmt(c[key])) for key in ("E", "G", "rho", "A", "Iy", "Iz", "J", "damping")),
    )
    uw.joint(w, "column_tip", "fixed", "column_end", body["name"], rpy=(0.0, np.pi / 2.0, 0.0))


def rt70_jack_scene() -> str:
    """The 42-DOF RT-70 with an elevation jack closing one loop (the closed chains' cost target).

    Returns
    -------
    str
        URDF text: :func:`rt70_scene`'s bodies and elements and the jack of
        :data:`RT70_JACK` — 44 coordinates, 3 loop rows.
    """
    return _rt70_text(
        "rt70_jack",
        "RT-70 42-DOF model with an elevation jack closing one loop (an illustrative "
        "linkage for the closed-chain tests, not the book's gear-sector drive)",
        rt70_data.LISTING_BODIES,
        drives=_rt70_jack,
    )
