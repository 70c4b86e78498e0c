"""The book's small models as scenes: the chapter-2 torsional models and the test mechanisms.

The RT-70's chapter-2 models (§2.3 azimuth at elevation 0° and 90°, §2.4 elevation:
coaxial nodes joined by torsion springs after a topology matrix Γ, Tables 2.1–2.4 in
SI), and the mechanisms of the book and its companion sources: the planar double
pendulum, the three masses of §2.1, the two 6-DOF bodies of §4.2.3's exercises and the
non-rigid gear reducer of §1.4. Each returns the URDF text;
:mod:`rt70.scenes.generate` writes them with every other scene.
"""

from __future__ import annotations

from collections.abc import Sequence

from rt70.scenes import mechanisms, rt70_data
from rt70.scenes import urdf_writer as uw
from rt70.scenes.pairs import pair_joint_names
from rt70.scenes.urdf_writer import ROOT_LINK, ZERO3, fmt


def _gamma_ends(row: Sequence[int], what: str) -> tuple[int | None, int]:
    """Return (i, j) of a topology-matrix row: −1 at i (None for the ground), +1 at j."""
    minus = [k for k, v in enumerate(row) if v == -1]
    plus = [k for k, v in enumerate(row) if v == 1]
    if len(plus) != 1 or len(minus) > 1 or len(minus) + len(plus) != sum(v != 0 for v in row):
        raise ValueError(f"{what}: topology row {row} is not one link")
    return (minus[0] if minus else None), plus[0]


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
