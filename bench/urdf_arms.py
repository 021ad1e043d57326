"""Three real arms from their URDFs for ``make bench``: Franka Panda, UR5, KUKA LBR iiwa14.

The Panda's and the UR5's URDFs are the files example-robot-data ships (the ``bench`` extra:
``panda_description/urdf/panda.urdf`` and ``ur_description/urdf/ur5_robot.urdf``); example-robot-data
ships no iiwa, so the iiwa14's joint table is written here as data (``IIWA14_URDF``), transcribed from
IFL-CAMP/iiwa_stack, ``iiwa_description/urdf/iiwa14.xacro`` (PI = 3.1415926535897931; its link
offsets add up to KUKA's published lengths 0.36, 0.42, 0.4 and 0.126 m).

Each arm is read the same way by both libraries: kinlib through ``robots.from_urdf_joints`` on the
joints from the base link to the tip link (:func:`urdf_joints`), Pinocchio through
``buildModelFromXML`` on the same XML, reduced to those joints (any other joint, e.g. the Panda's
fingers, locked at 0) with a frame at the tip link.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

IIWA14_URDF = """<robot name="iiwa14">
  <link name="iiwa_link_0"/><link name="iiwa_link_1"/><link name="iiwa_link_2"/><link name="iiwa_link_3"/>
  <link name="iiwa_link_4"/><link name="iiwa_link_5"/><link name="iiwa_link_6"/><link name="iiwa_link_7"/>
  <link name="iiwa_link_ee"/>
  <joint name="iiwa_joint_1" type="revolute"><parent link="iiwa_link_0"/><child link="iiwa_link_1"/>
    <origin xyz="0 0 0.1575" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.97" upper="2.97" effort="320" velocity="1.48"/></joint>
  <joint name="iiwa_joint_2" type="revolute"><parent link="iiwa_link_1"/><child link="iiwa_link_2"/>
    <origin xyz="0 0 0.2025" rpy="1.5707963267948966 0 3.141592653589793"/><axis xyz="0 0 1"/>
    <limit lower="-2.09" upper="2.09" effort="320" velocity="1.48"/></joint>
  <joint name="iiwa_joint_3" type="revolute"><parent link="iiwa_link_2"/><child link="iiwa_link_3"/>
    <origin xyz="0 0.2045 0" rpy="1.5707963267948966 0 3.141592653589793"/><axis xyz="0 0 1"/>
    <limit lower="-2.97" upper="2.97" effort="176" velocity="1.75"/></joint>
  <joint name="iiwa_joint_4" type="revolute"><parent link="iiwa_link_3"/><child link="iiwa_link_4"/>
    <origin xyz="0 0 0.2155" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.09" upper="2.09" effort="176" velocity="1.31"/></joint>
  <joint name="iiwa_joint_5" type="revolute"><parent link="iiwa_link_4"/><child link="iiwa_link_5"/>
    <origin xyz="0 0.1845 0" rpy="-1.5707963267948966 3.141592653589793 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.97" upper="2.97" effort="110" velocity="2.27"/></joint>
  <joint name="iiwa_joint_6" type="revolute"><parent link="iiwa_link_5"/><child link="iiwa_link_6"/>
    <origin xyz="0 0 0.2155" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.09" upper="2.09" effort="40" velocity="2.36"/></joint>
  <joint name="iiwa_joint_7" type="revolute"><parent link="iiwa_link_6"/><child link="iiwa_link_7"/>
    <origin xyz="0 0.081 0" rpy="-1.5707963267948966 3.141592653589793 0"/><axis xyz="0 0 1"/>
    <limit lower="-3.05" upper="3.05" effort="40" velocity="2.36"/></joint>
  <joint name="iiwa_joint_ee" type="fixed"><parent link="iiwa_link_7"/><child link="iiwa_link_ee"/>
    <origin xyz="0 0 0.045" rpy="0 0 0"/></joint>
</robot>
"""


def _example_robot_data_urdf(relative: str) -> str | None:
    """The text of a URDF shipped by example-robot-data (files only, no Python module), or None."""
    from importlib import metadata

    try:
        dist = metadata.distribution("example-robot-data")
    except metadata.PackageNotFoundError:
        return None
    p = Path(dist.locate_file(f"cmeel.prefix/share/example-robot-data/robots/{relative}"))
    return p.read_text(encoding="utf-8") if p.is_file() else None


#: (name, where the URDF comes from, a function giving its XML or None, the tip link)
ARMS = [
    (
        "panda",
        "example-robot-data panda_description/urdf/panda.urdf",
        lambda: _example_robot_data_urdf("panda_description/urdf/panda.urdf"),
        "panda_hand_tcp",
    ),
    (
        "ur5",
        "example-robot-data ur_description/urdf/ur5_robot.urdf",
        lambda: _example_robot_data_urdf("ur_description/urdf/ur5_robot.urdf"),
        "tool0",
    ),
    ("iiwa14", "iiwa_stack iiwa14.xacro, transcribed (bench/urdf_arms.py)", lambda: IIWA14_URDF, "iiwa_link_ee"),
]


def _triple(text: str | None, default: str) -> tuple[float, float, float]:
    vals = [float(x) for x in (text or default).split()]
    assert len(vals) == 3, text
    return tuple(vals)


def urdf_joints(xml: str, tip: str) -> tuple[list, list[str]]:
    """The joints from the URDF's root link to ``tip`` as ``(type, xyz, rpy, axis)`` tuples (the input of
    ``robots.from_urdf_joints``; the typed decimals as floats) and the names of the movable ones."""
    root = ET.fromstring(xml)
    by_child = {j.find("child").get("link"): j for j in root.findall("joint")}
    chain, link = [], tip
    while link in by_child:
        j = by_child[link]
        chain.append(j)
        link = j.find("parent").get("link")
    chain.reverse()
    joints, names = [], []
    for j in chain:
        kind = j.get("type")
        if kind not in ("revolute", "continuous", "prismatic", "fixed"):
            raise ValueError(f"joint {j.get('name')}: type {kind} is not supported")
        o = j.find("origin")
        xyz = _triple(o.get("xyz") if o is not None else None, "0 0 0")
        rpy = _triple(o.get("rpy") if o is not None else None, "0 0 0")
        ax = j.find("axis")
        axis = _triple(ax.get("xyz") if ax is not None else None, "1 0 0")
        joints.append((kind, xyz, rpy, axis))
        if kind != "fixed":
            names.append(j.get("name"))
    return joints, names


def kinlib_chain(name: str, xml: str, tip: str):
    from kinlib import robots

    joints, _ = urdf_joints(xml, tip)
    return robots.from_urdf_joints(joints, name=f"{name}_urdf")


class PinArm:
    """Pinocchio's model of the same URDF, reduced to the chain's joints, and a frame at ``tip``."""

    def __init__(self, xml: str, tip: str):
        import numpy as np
        import pinocchio as pin

        _, names = urdf_joints(xml, tip)
        full = pin.buildModelFromXML(xml)
        lock = [full.getJointId(n) for n in full.names[1:] if n not in names]
        model = pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full
        assert list(model.names[1:]) == names, (list(model.names[1:]), names)
        self.pin, self.model, self.data = pin, model, model.createData()
        self.fid = model.getFrameId(tip)
        self._np = np

    def geometric(self, q):
        """The timed call: the frame Jacobian in LOCAL_WORLD_ALIGNED, rows [ṗ; ω]."""
        return self.pin.computeFrameJacobian(
            self.model, self.data, q, self.fid, self.pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        )

    def book(self, q):
        """The same in the book's order [ω_s; ṗ]."""
        return self._np.asarray(self.geometric(q))[[3, 4, 5, 0, 1, 2]]
