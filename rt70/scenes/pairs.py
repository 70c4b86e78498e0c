"""The book's 6-DOF elastic pair: its six 1-DOF joints and their names.

A body of the §4.2.3 listing hangs on its parent by six 1-DOF joints in series, the
pair coordinates ``[x, y, z, β, θ, α]`` of the book: three prismatic joints along x, y,
z, then three revolute joints about x, y, z. Both scene writers
(:mod:`rt70.scenes.urdf_writer`, :mod:`rt70.scenes.synthetic`) build pairs from
:data:`PAIR_JOINTS`, and :func:`pair_joint_names` names their coordinates.
"""

from __future__ import annotations

#: The six 1-DOF joints of an elastic pair, in the book's coordinate order
#: [x, y, z, β, θ, α]: ``(suffix, joint type, axis)``.
PAIR_JOINTS = (
    ("x", "prismatic", (1, 0, 0)),
    ("y", "prismatic", (0, 1, 0)),
    ("z", "prismatic", (0, 0, 1)),
    ("rx", "revolute", (1, 0, 0)),
    ("ry", "revolute", (0, 1, 0)),
    ("rz", "revolute", (0, 0, 1)),
)


def pair_joint_names(body: str) -> list[str]:
    """Return the names of the six joints of a body's elastic pair.

    Parameters
    ----------
    body : str
        The body (child link) name.

    Returns
    -------
    list of str
        ``<body>_x, <body>_y, <body>_z, <body>_rx, <body>_ry, <body>_rz``: the book's
        pair coordinates ``[x, y, z, β, θ, α]`` in order.
    """
    return [f"{body}_{axis}" for axis, _, _ in PAIR_JOINTS]
