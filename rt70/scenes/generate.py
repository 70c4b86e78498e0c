"""Build the rt70 scene URDF files from the book's data.

Every scene is a function returning the URDF text; :data:`SCENES` maps scene names to
them and :func:`write_all` writes ``<name>.urdf`` files. The output is deterministic
(:mod:`rt70.scenes.urdf_writer`: fixed element and attribute order, two-space
indentation, numbers written as the shortest text that reads back as the same float,
and a final newline). The extension elements follow ``docs/urdf-extensions.md``.

Run ``python -m rt70.scenes.generate [DIR]`` to regenerate the files (default: the
repository's ``urdf/`` directory).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from pathlib import Path

from rt70.control.geartrains import parallel_drive
from rt70.guards.atomic import atomic_write_text
from rt70.scenes import mechanisms, rt70_data, rt70_drives, rt70_wind
from rt70.scenes import urdf_writer as uw
from rt70.scenes.loop_scenes import crank_slider_scene, four_bar_scene
from rt70.scenes.pairs import pair_joint_names
from rt70.scenes.urdf_writer import ROOT_LINK, ZERO3, check_name, fmt, fmt_vec
from rt70.urdf.description import DRIVE_PARAMETERS

#: Default output directory: ``urdf/`` at the repository root.
DEFAULT_DIRECTORY = Path(__file__).resolve().parents[2] / "urdf"


def _gamma_ends(row: Sequence[int], what: str) -> tuple[int | None, int]:
    """Return (i, j) of a topology-matrix row: −1 at i (None for the ground), +1 at j."""
    minus = [k for k, v in enumerate(row) if v == -1]
    plus = [k for k, v in enumerate(row) if v == 1]
    if len(plus) != 1 or len(minus) > 1 or len(minus) + len(plus) != sum(v != 0 for v in row):
        raise ValueError(f"{what}: topology row {row} is not one link")
    return (minus[0] if minus else None), plus[0]


# ---------------------------------------------------------------------------------------
# Scenes
# ---------------------------------------------------------------------------------------


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
    (:data:`rt70_data.SERVO_BODIES`), the control object of issue 10, with its two
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
) -> str:
    """The 42-DOF RT-70 URDF text with the given bodies (the listing's or a variant).

    ``drives`` writes the scene's ``<rt70:drive>`` elements, after the optical points.
    """
    d = rt70_data
    bodies = {b["name"]: b for b in listing_bodies}
    w = uw.Writer()
    uw.begin(w, name, description)
    for body in listing_bodies:
        uw.six_dof_body(
            w,
            body["name"],
            body["parent"],
            body["offset"],
            body["mass"],
            body["moments"],
            body["com"],
        )
    w.blank()
    w.comment("Gravity (erratum 2: z up)")
    uw.gravity(w, d.LISTING_GRAVITY)
    w.comment("Direct elastic pairs: frame 1 = construction frame, frame 2 = body frame")
    for pair in d.LISTING_DIRECT_PAIRS:
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
    w.comment("Optical points (section 4.1.8)")
    for point in d.LISTING_OPTICAL_POINTS:
        w.empty(
            "rt70:optical_point",
            ("name", check_name(point["name"])),
            ("link", check_name(point["link"])),
            ("xyz", fmt_vec(point["xyz"])),
        )
    if drives is not None:
        drives(w)
    return uw.end(w)


def _torsional_scene(
    name: str,
    description: str,
    nodes: Sequence[tuple[str, float]],
    links: Sequence[tuple[str, float]],
    gamma: Sequence[Sequence[int]],
) -> str:
    """Coaxial nodes rotating about z, joined by torsion springs (chapter 2).

    ``nodes`` are (name, I in kgf·s²·m), ``links`` (name, C in kgf·m/rad), one per row
    of ``gamma``; both are converted to SI here.
    """
    if len(links) != len(gamma) or any(len(row) != len(nodes) for row in gamma):
        raise ValueError(f"{name}: topology matrix does not match the tables")
    w = uw.Writer()
    uw.begin(w, name, description)
    for k, (node, inertia) in enumerate(nodes, start=1):
        izz = inertia * rt70_data.KGF
        uw.joint(w, f"node{k}", "revolute", ROOT_LINK, node, axis=(0, 0, 1))
        uw.massive_link(w, node, rt70_data.CHAPTER2_NODE_MASS, (izz, izz, izz))
    w.blank()
    uw.gravity(w, (0.0, 0.0, -9.81))
    w.comment("Torsion springs about z, one per row of the topology matrix")
    for (link, stiffness), row in zip(links, gamma, strict=True):
        i, j = _gamma_ends(row, f"{name} link {link}")
        first = ROOT_LINK if i is None else nodes[i][0]
        second = nodes[j][0]
        if link != f"{first}_{second}":
            raise ValueError(f"{name}: link {link!r} does not join {first!r} and {second!r}")
        uw.bushing(w, link, (0.0,) * 5 + (stiffness * rt70_data.KGF,), (0.0,) * 6, first, second)
    return uw.end(w)


#: The elevation jack of the ``rt70_jack`` scene (issue 12: the RT-70 with one closed
#: loop). The book's RT-70 drives the elevation through a gear sector; this jack is an
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
    w.comment("Elevation jack (issue 12 test linkage, not the book's drive): cylinder, piston")
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


def rt70_jack_scene() -> str:
    """The 42-DOF RT-70 with an elevation jack closing one loop (issue 12's cost target).

    Returns
    -------
    str
        URDF text: :func:`rt70_scene`'s bodies and elements and the jack of
        :data:`RT70_JACK` — 44 coordinates, 3 loop rows.
    """
    return _rt70_text(
        "rt70_jack",
        "RT-70 42-DOF model with an elevation jack closing one loop (an illustrative "
        "linkage for issue 12, not the book's gear-sector drive)",
        rt70_data.LISTING_BODIES,
        drives=_rt70_jack,
    )


def rt70_elevation_scene() -> str:
    """Build the chapter-2 elevation model (§2.4, 6 masses, Γβ).

    Returns
    -------
    str
        URDF text: six coaxial nodes, each on a revolute joint about z, and five torsion
        springs (Tables 2.3, 2.4 converted to SI).
    """
    d = rt70_data
    return _torsional_scene(
        "rt70_elevation",
        "RT-70 elevation model, 6 masses (Dubarenko 2007, section 2.4, Tables 2.3-2.4)",
        [(n["name"], n["I"]) for n in d.ELEVATION_NODES],
        [(c["name"], c["C"]) for c in d.ELEVATION_LINKS],
        d.GAMMA_BETA,
    )


def rt70_azimuth_scene() -> str:
    """Build the chapter-2 azimuth model at elevation 0° (§2.3, 7 masses, Γα).

    Returns
    -------
    str
        URDF text: seven coaxial nodes and six torsion springs (Tables 2.1, 2.2,
        elevation-0° columns, converted to SI); no spring to the ground.
    """
    d = rt70_data
    return _torsional_scene(
        "rt70_azimuth",
        "RT-70 azimuth model at elevation 0 deg, 7 masses (Dubarenko 2007, section 2.3, "
        "Tables 2.1-2.2)",
        [(n["name"], n["I_el0"]) for n in d.AZIMUTH_NODES],
        [(c["name"], c["C_el0"]) for c in d.AZIMUTH_LINKS],
        d.GAMMA_ALPHA,
    )


def rt70_azimuth_el90_scene() -> str:
    """Build the chapter-2 azimuth model at elevation 90° (§2.3, 7 masses, Γα).

    Returns
    -------
    str
        URDF text as :func:`rt70_azimuth_scene`, with the elevation-90° columns.
    """
    d = rt70_data
    return _torsional_scene(
        "rt70_azimuth_el90",
        "RT-70 azimuth model at elevation 90 deg, 7 masses (Dubarenko 2007, section 2.3, "
        "Tables 2.1-2.2)",
        [(n["name"], n["I_el90"]) for n in d.AZIMUTH_NODES],
        [(c["name"], c["C_el90"]) for c in d.AZIMUTH_LINKS],
        d.GAMMA_ALPHA,
    )


def double_pendulum_scene() -> str:
    """Build the planar 2R arm (companion sources, test mechanism 1).

    Returns
    -------
    str
        URDF text: two uniform rods on revolute joints about z, the second joint at the
        end of the first rod, gravity along −y.
    """
    d = mechanisms.DOUBLE_PENDULUM
    w = uw.Writer()
    uw.begin(
        w, "double_pendulum", "Planar 2R arm (double pendulum) in the x-y plane, gravity along -y"
    )
    parent, offset = ROOT_LINK, ZERO3
    for link in d["links"]:
        m, length = link["mass"], link["length"]
        i_c = m * length**2 / 12.0
        uw.joint(w, link["joint"], "revolute", parent, link["name"], xyz=offset, axis=(0, 0, 1))
        uw.massive_link(w, link["name"], m, (d["I_axial"], i_c, i_c), com=(length / 2.0, 0.0, 0.0))
        parent, offset = link["name"], (length, 0.0, 0.0)
    w.blank()
    uw.gravity(w, d["gravity"])
    return uw.end(w)


def three_masses_scene() -> str:
    """Build the §2.1 system of three point masses with elastic links (along x).

    Returns
    -------
    str
        URDF text: three point masses on prismatic joints along x at their rest
        positions, and one x-only spring/damper per row of the topology matrix (2.3).
    """
    d = mechanisms.THREE_MASSES
    masses = d["masses"]
    w = uw.Writer()
    uw.begin(
        w,
        "three_masses",
        "Three point masses with elastic links (Dubarenko 2007, "
        "section 2.1, Fig. 2.1, eq. 2.3), motion along x",
    )
    for mass in masses:
        uw.joint(
            w, mass["joint"], "prismatic", ROOT_LINK, mass["name"], xyz=mass["rest"], axis=(1, 0, 0)
        )
        moment = d["point_moment"]
        uw.massive_link(w, mass["name"], mass["mass"], (moment, moment, moment))
    w.blank()
    uw.gravity(w, d["gravity"])
    w.comment("Springs along x; frame 1 sits at the rest position of the second end")
    for row, stiffness in zip(d["gamma"], d["stiffness"], strict=True):
        i, j = _gamma_ends(row, "three_masses")
        second = masses[j]
        if i is None:
            first_link, name = ROOT_LINK, f"ground_{second['name']}"
            xyz1 = second["rest"]
        else:
            first = masses[i]
            first_link, name = first["name"], f"{first['name']}_{second['name']}"
            xyz1 = tuple(b - a for a, b in zip(first["rest"], second["rest"], strict=True))
        damping = d["damping_ratio"] * stiffness
        uw.bushing(
            w,
            name,
            (stiffness,) + (0.0,) * 5,
            (damping,) + (0.0,) * 5,
            first_link,
            second["name"],
            xyz1=xyz1,
        )
    return uw.end(w)


def two_body_gravity_scene() -> str:
    """Build the two 6-DOF bodies of §4.2.3, exercises 1–2.

    Returns
    -------
    str
        URDF text: body 1 on world and body 2 on body 1, each by six 1-DOF joints;
        joint springs on body 1's six coordinates, a bushing between the bodies,
        non-zero centre-of-mass offsets and a rotated inertia on body 2, gravity along −z.
    """
    d = mechanisms.TWO_BODY_GRAVITY
    bodies = {b["name"]: b for b in d["bodies"]}
    ratio = d["damping_ratio"]
    w = uw.Writer()
    uw.begin(
        w,
        "two_body_gravity",
        "Two 6-DOF bodies with springs in gravity (Dubarenko 2007, section 4.2.3, exercises 1-2)",
    )
    for body in d["bodies"]:
        uw.six_dof_body(
            w,
            body["name"],
            body["parent"],
            body["offset"],
            body["mass"],
            body["moments"],
            body["com"],
            body["inertia_rpy"],
        )
    w.blank()
    uw.gravity(w, d["gravity"])
    w.comment("C01, D01: springs on body 1's pair coordinates")
    ground = d["ground_springs"]
    for joint, stiffness in zip(pair_joint_names(ground["body"]), ground["stiffness"], strict=True):
        w.empty(
            "rt70:joint_spring",
            ("name", f"{joint}_spring"),
            ("joint", joint),
            ("stiffness", fmt(stiffness)),
            ("damping", fmt(ratio * stiffness)),
        )
    w.comment("C12, D12: bushing between body 1 and body 2")
    bushing = d["bushing"]
    child = bodies[bushing["child"]]
    uw.bushing(
        w,
        bushing["name"],
        bushing["stiffness"],
        [ratio * c for c in bushing["stiffness"]],
        child["parent"],
        child["name"],
        xyz1=child["offset"],
    )
    return uw.end(w)


def gear_reducer_scene() -> str:
    """Build the non-rigid gear reducer of §1.4 (Fig. 1.3, formalism Example 1a).

    Returns
    -------
    str
        URDF text: the load and four gears, each on a revolute joint about x from the
        ground (``beta_out``, ``beta_1`` … ``beta_4``) on three parallel shafts; the
        shafts C1 (load–gear 1), C2 (gears 2–3) and C3 (gear 4 to the held motor) as
        rx-only bushings; each mesh as a bushing between the two gears' points at the
        contact, stiff only along the common tangent (z), with ``C4/R1²`` (``C5/R3²``):
        the tangential slip ``R1 β1 + R2 β2 = R1 δ4`` stores ``½ C4 δ4²`` as the book's
        mesh spring does (and likewise the dampers). Gravity along −z acts on centres
        of mass on the fixed shafts: it does no work.
    """
    d = mechanisms.GEAR_REDUCER
    R1, R2, R3, R4 = d["radii"]
    C, D, dx = d["stiffness"], d["damping"], d["spacing"]
    axis_b, axis_c = R1 + R2, R1 + R2 + R3 + R4  # shaft positions along y
    gears = (
        ("load", "beta_out", d["load_inertia"], (0.0, 0.0, 0.0)),
        ("gear1", "beta_1", d["inertia"][0], (dx, 0.0, 0.0)),
        ("gear2", "beta_2", d["inertia"][1], (dx, axis_b, 0.0)),
        ("gear3", "beta_3", d["inertia"][2], (2 * dx, axis_b, 0.0)),
        ("gear4", "beta_4", d["inertia"][3], (2 * dx, axis_c, 0.0)),
    )
    w = uw.Writer()
    uw.begin(
        w,
        "gear_reducer",
        "Non-rigid gear reducer (Dubarenko 2007, section 1.4, Fig. 1.3): four gears, "
        "three shafts, two meshes, a free load; the motor shaft held",
    )
    for link, joint, inertia, xyz in gears:
        uw.joint(w, joint, "revolute", ROOT_LINK, link, xyz=xyz, axis=(1, 0, 0))
        uw.massive_link(w, link, 1.0, (inertia, inertia, inertia))
    w.blank()
    uw.gravity(w, (0.0, 0.0, -9.81))

    def rx_only(value: float) -> tuple[float, ...]:
        return (0.0, 0.0, 0.0, value, 0.0, 0.0)

    def z_only(value: float) -> tuple[float, ...]:
        return (0.0, 0.0, value, 0.0, 0.0, 0.0)

    w.comment("Shafts: torsion about x between frames on one axis")
    uw.bushing(w, "shaft_out", rx_only(C[0]), rx_only(D[0]), "load", "gear1", xyz1=(dx, 0, 0))
    uw.bushing(w, "shaft_23", rx_only(C[1]), rx_only(D[1]), "gear2", "gear3", xyz1=(dx, 0, 0))
    uw.bushing(w, "shaft_motor", rx_only(C[2]), rx_only(D[2]), ROOT_LINK, "gear4", xyz1=gears[4][3])
    w.comment("Meshes: along the common tangent (z) at the contact point, C4/R1², C5/R3²")
    uw.bushing(
        w,
        "mesh_12",
        z_only(C[3] / R1**2),
        z_only(D[3] / R1**2),
        "gear1",
        "gear2",
        xyz1=(0.0, R1, 0.0),
        xyz2=(0.0, -R2, 0.0),
    )
    uw.bushing(
        w,
        "mesh_34",
        z_only(C[4] / R3**2),
        z_only(D[4] / R3**2),
        "gear3",
        "gear4",
        xyz1=(0.0, R3, 0.0),
        xyz2=(0.0, -R4, 0.0),
    )
    return uw.end(w)


#: Scene name → function returning the scene's URDF text.
SCENES: dict[str, Callable[[], str]] = {
    "rt70": rt70_scene,
    "rt70_servo": rt70_servo_scene,
    "rt70_jack": rt70_jack_scene,
    "rt70_elevation": rt70_elevation_scene,
    "rt70_azimuth": rt70_azimuth_scene,
    "rt70_azimuth_el90": rt70_azimuth_el90_scene,
    "double_pendulum": double_pendulum_scene,
    "three_masses": three_masses_scene,
    "two_body_gravity": two_body_gravity_scene,
    "gear_reducer": gear_reducer_scene,
    "four_bar": four_bar_scene,
    "crank_slider": crank_slider_scene,
}


def write_all(directory: Path) -> list[Path]:
    """Write every scene as ``<name>.urdf`` into ``directory``.

    Each file is written to a temporary file in the same directory and moved into place
    with :func:`os.replace`, so a reader never sees a partial file.

    Parameters
    ----------
    directory : Path
        Output directory; created if missing.

    Returns
    -------
    list of Path
        The written files, in the order of :data:`SCENES`.
    """
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for name, build in SCENES.items():
        path = directory / f"{name}.urdf"
        atomic_write_text(path, build())
        written.append(path)
    return written


def main(argv: Sequence[str] | None = None) -> int:
    """Regenerate the scene files (command-line entry point).

    Parameters
    ----------
    argv : sequence of str, optional
        Arguments; default ``sys.argv[1:]``. One optional positional argument: the
        output directory (default :data:`DEFAULT_DIRECTORY`).

    Returns
    -------
    int
        Exit status 0.
    """
    parser = argparse.ArgumentParser(
        prog="python -m rt70.scenes.generate",
        description="Regenerate the rt70 scene URDF files from the book's data.",
    )
    parser.add_argument(
        "directory",
        nargs="?",
        type=Path,
        default=DEFAULT_DIRECTORY,
        help=f"output directory (default: {DEFAULT_DIRECTORY})",
    )
    args = parser.parse_args(argv)
    for path in write_all(args.directory):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
