"""rt70's own URDF reader: standard-library XML to a validated, plain description.

Both sides of the cross-check read scenes through this package: the textbook side builds
its model from the description; the reference side lets Pinocchio parse the same file
for the dynamics and takes only the rt70 extension elements (springs, gravity, optical
points) from here. Nothing in this package imports Pinocchio.
"""

from rt70.urdf.coordinates import coordinate_names
from rt70.urdf.description import (
    Bushing,
    Drive,
    DriveSector,
    FrameRef,
    Inertial,
    InertiaRepair,
    Joint,
    JointSpring,
    Link,
    Mimic,
    OpticalPoint,
    RobotDescription,
    Wind,
)
from rt70.urdf.mount_record import Mount, MountAxis
from rt70.urdf.reader import read_urdf, read_urdf_string
from rt70.urdf.text import RT70_NS

__all__ = [
    "RT70_NS",
    "Bushing",
    "Drive",
    "DriveSector",
    "FrameRef",
    "Inertial",
    "InertiaRepair",
    "Joint",
    "JointSpring",
    "Link",
    "Mimic",
    "Mount",
    "MountAxis",
    "OpticalPoint",
    "RobotDescription",
    "Wind",
    "coordinate_names",
    "read_urdf",
    "read_urdf_string",
]
