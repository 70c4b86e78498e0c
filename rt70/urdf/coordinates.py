"""The user's order of generalised coordinates, fixed by the URDF file alone.

Every result rt70 gives — from the textbook side, from the Pinocchio side, from the
linear models and the simulation — is a vector or matrix over the same coordinates in
the same order, so a user never needs to know how either side numbers its joints.
The order is the file's: a depth-first walk of the kinematic tree from the root link,
the child joints of a link in document order; every joint that moves contributes its
coordinates (``joint`` for a 1-DOF joint, ``joint:x`` … ``joint:rz`` for a floating
joint, ``joint:x``, ``joint:y``, ``joint:rz`` for a planar one); ``fixed`` joints and
``<mimic>`` joints (which follow their source, ``q = k q_s + o``) and the joints of a modal
body's interface chains (which follow its modes, :mod:`rt70.urdf.modal_interfaces`) have
none. The modal
coordinates of the modal bodies follow all of them, ``body:eta1`` … for each
``<rt70:modal_body>`` in document order.

The textbook side derives the same list itself while building its pairs (a test holds
the two equal); the Pinocchio side, whose parser numbers sibling joints its own way,
maps its coordinates to this order.
"""

from __future__ import annotations

from rt70.urdf.description import RobotDescription

#: Coordinate-name suffixes of the multi-coordinate joints, in coordinate order.
SUFFIXES = {
    "floating": (":x", ":y", ":z", ":rx", ":ry", ":rz"),
    "planar": (":x", ":y", ":rz"),
}


def coordinate_names(desc: RobotDescription) -> list[str]:
    """Names of the independent generalised coordinates of ``desc``, in the user's order.

    Parameters
    ----------
    desc : RobotDescription
        A validated description (a tree: :func:`rt70.urdf.read_urdf` checked it).

    Returns
    -------
    list of str
        One name per coordinate (see the module docstring for the order and the names).
    """
    children: dict[str, list] = {}
    for joint in desc.joints:
        children.setdefault(joint.parent, []).append(joint)
    names: list[str] = []
    following = desc.node_joints
    stack = list(reversed(children.get(desc.root, [])))
    while stack:  # depth-first, siblings in document order (no recursion: long chains)
        joint = stack.pop()
        if joint.type != "fixed" and joint.mimic is None and joint.name not in following:
            names.extend(joint.name + sfx for sfx in SUFFIXES.get(joint.type, ("",)))
        stack.extend(reversed(children.get(joint.child, [])))
    for body in desc.modal_bodies:
        names.extend(body.coordinate_names)
    return names
