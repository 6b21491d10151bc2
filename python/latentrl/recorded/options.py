"""The options of reading demonstrations as the command line gives them (`latentrl fit`, `train`,
`check`): one flag per field, and the `load_demos` keywords they make."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any


def joint_map(text: str) -> dict[str, str]:
    """``old=new,old2=new2,time=`` → {old: new, old2: new2, time: ""} (``old=``: the column is
    left out); a malformed entry is a ValueError."""
    renames: dict[str, str] = {}
    for entry in filter(None, (e.strip() for e in text.split(","))):
        old, eq, new = (part.strip() for part in entry.partition("="))
        if not eq or not old:
            raise ValueError(f"joint_map: expected old=new[,old=new…] (old= leaves a column out), got {entry!r} "
                             f"in {text!r}")
        if old in renames:
            raise ValueError(f"joint_map: {old!r} is renamed twice in {text!r}")
        renames[old] = new
    return renames


@dataclass(frozen=True)
class DemoOptions:
    """How demonstrations are read beyond their file (docs/demos.md)."""

    demos_key: str = ""
    """Where a recording keeps the joint positions: a LeRobot feature (default observation.state), a robomimic obs key (default robot0_joint_pos) or a ROS topic (default /joint_states)."""
    joint_names: str = ""
    """The joint names of a recording that names none, comma-separated (an HDF5 file without a joint_names attribute, a LeRobot feature without names)."""
    joint_map: str = ""
    """Renames of the demonstrations' joints before they are matched to the robot's, old=new[,old=new…]; old= (nothing after =) leaves that column out (a time stamp, a gripper)."""
    degrees: bool = False
    """The demonstrations' joint values are degrees: convert them to radians (train, check: the robot's revolute and continuous joints, a prismatic joint's metres kept; fit, which knows no robot: every column). Without it, a recorded joint beyond ±2π is refused as looking like degrees."""
    max_postures: int = 0
    """At most this many postures, chosen by farthest-point sampling in joint space from the first frame (0: all; docs/demos.md)."""

    def load_kwargs(self) -> dict[str, Any]:
        """The `load_demos` keywords of these options; ValueError naming a bad one."""
        if not isinstance(self.max_postures, int) or self.max_postures < 0:
            raise ValueError(f"max_postures: must be an int >= 0 (0: all postures), got {self.max_postures!r}")
        names = tuple(n.strip() for n in self.joint_names.split(",") if n.strip())
        return {"key": self.demos_key or None, "joint_names": names or None, "joint_map": joint_map(self.joint_map),
                "degrees": self.degrees, "max_postures": self.max_postures or None}
