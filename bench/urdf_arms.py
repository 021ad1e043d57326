"""Three real arms from their URDFs for ``make bench``: Franka Panda, UR5, KUKA LBR iiwa14.

The Panda's and the UR5's URDFs are the files example-robot-data ships (the ``bench`` extra:
``panda_description/urdf/panda.urdf`` and ``ur_description/urdf/ur5_robot.urdf``); example-robot-data
ships no iiwa, so the iiwa14's joints are written here as URDF (``IIWA14_URDF``), the xacro macro of
IFL-CAMP/iiwa_stack ``iiwa_description/urdf/iiwa14.xacro`` at commit 325f5bf60331a38df7b5c0bd6bb5dfa9e3c240c3
expanded by hand (checked against that file: every origin, axis and limit; ``${PI / 2}`` etc. as the doubles
xacro computes from math.pi; its ``iiwa_joint_ee`` has rpy ``${PI} ${PI} ${PI}``, a rotation equal to the
identity but for rounding; limits ±170°, ±120°, …, ±175° in radians, its max_effort 300 and max_velocity 10).
Its link offsets add up to KUKA's published lengths 0.36, 0.42, 0.4 and 0.126 m.

Each arm is read the same way by the three libraries: kinlib through ``robots.from_urdf_joints`` on the
joints from the base link to the tip link (:func:`urdf_joints`), Pinocchio through
``buildModelFromXML`` on the same XML, reduced to those joints (any other joint, e.g. the Panda's
fingers, locked at 0) with a frame at the tip link, the Robotics Toolbox through ``Robot.URDF`` on the same
XML (:class:`RtbArm`).
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
    <limit lower="-2.9670597283903604" upper="2.9670597283903604" effort="300" velocity="10"/></joint>
  <joint name="iiwa_joint_2" type="revolute"><parent link="iiwa_link_1"/><child link="iiwa_link_2"/>
    <origin xyz="0 0 0.2025" rpy="1.5707963267948966 0 3.141592653589793"/><axis xyz="0 0 1"/>
    <limit lower="-2.0943951023931953" upper="2.0943951023931953" effort="300" velocity="10"/></joint>
  <joint name="iiwa_joint_3" type="revolute"><parent link="iiwa_link_2"/><child link="iiwa_link_3"/>
    <origin xyz="0 0.2045 0" rpy="1.5707963267948966 0 3.141592653589793"/><axis xyz="0 0 1"/>
    <limit lower="-2.9670597283903604" upper="2.9670597283903604" effort="300" velocity="10"/></joint>
  <joint name="iiwa_joint_4" type="revolute"><parent link="iiwa_link_3"/><child link="iiwa_link_4"/>
    <origin xyz="0 0 0.2155" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.0943951023931953" upper="2.0943951023931953" effort="300" velocity="10"/></joint>
  <joint name="iiwa_joint_5" type="revolute"><parent link="iiwa_link_4"/><child link="iiwa_link_5"/>
    <origin xyz="0 0.1845 0" rpy="-1.5707963267948966 3.141592653589793 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.9670597283903604" upper="2.9670597283903604" effort="300" velocity="10"/></joint>
  <joint name="iiwa_joint_6" type="revolute"><parent link="iiwa_link_5"/><child link="iiwa_link_6"/>
    <origin xyz="0 0 0.2155" rpy="1.5707963267948966 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-2.0943951023931953" upper="2.0943951023931953" effort="300" velocity="10"/></joint>
  <joint name="iiwa_joint_7" type="revolute"><parent link="iiwa_link_6"/><child link="iiwa_link_7"/>
    <origin xyz="0 0.081 0" rpy="-1.5707963267948966 3.141592653589793 0"/><axis xyz="0 0 1"/>
    <limit lower="-3.0543261909900763" upper="3.0543261909900763" effort="300" velocity="10"/></joint>
  <joint name="iiwa_joint_ee" type="fixed"><parent link="iiwa_link_7"/><child link="iiwa_link_ee"/>
    <origin xyz="0 0 0.045" rpy="3.141592653589793 3.141592653589793 3.141592653589793"/></joint>
</robot>
"""


_H = 1.5707963267948966
#: the joints :func:`urdf_joints` reads from example-robot-data 6.0.0's ``panda.urdf`` (to ``panda_hand_tcp``) and
#: ``ur5_robot.urdf`` (to ``tool0``), for the tests (which run without the bench extra;
#: tests/core/test_native.py checks them against the files when example-robot-data is installed)
PANDA_JOINTS = [
    ("revolute", (0.0, 0.0, 0.333), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("revolute", (0.0, 0.0, 0.0), (-_H, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("revolute", (0.0, -0.316, 0.0), (_H, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("revolute", (0.0825, 0.0, 0.0), (_H, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("revolute", (-0.0825, 0.384, 0.0), (-_H, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("revolute", (0.0, 0.0, 0.0), (_H, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("revolute", (0.088, 0.0, 0.0), (_H, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("fixed", (0.0, 0.0, 0.107), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
    ("fixed", (0.0, 0.0, 0.0), (0.0, 0.0, -0.7853981633974483), (1.0, 0.0, 0.0)),
    ("fixed", (0.0, 0.0, 0.1034), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
]
_H11 = 1.57079632679  # the UR5 file's own digits
UR5_JOINTS = [
    ("fixed", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0)),
    ("revolute", (0.0, 0.0, 0.089159), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("revolute", (0.0, 0.13585, 0.0), (0.0, _H11, 0.0), (0.0, 1.0, 0.0)),
    ("revolute", (0.0, -0.1197, 0.425), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    ("revolute", (0.0, 0.0, 0.39225), (0.0, _H11, 0.0), (0.0, 1.0, 0.0)),
    ("revolute", (0.0, 0.093, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    ("revolute", (0.0, 0.0, 0.09465), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)),
    ("fixed", (0.0, 0.0823, 0.0), (-_H11, 0.0, 0.0), (1.0, 0.0, 0.0)),
]


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


class RtbArm:
    """The Robotics Toolbox's model of the same URDF (``Robot.URDF`` on the file) and the ETS of its path from the
    base link to ``tip``: the timed call is that ETS's compiled ``jacob0`` (rows [v; ω] of the tip origin in the
    base frame, i.e. the geometric Jacobian [ṗ; ω])."""

    def __init__(self, xml: str, tip: str):
        import tempfile

        import numpy as np
        import roboticstoolbox as rtb

        _, names = urdf_joints(xml, tip)
        root = ET.fromstring(xml)  # without the meshes (package:// paths RTB's xacro step cannot resolve)
        for link in root.findall("link"):
            for shape in link.findall("visual") + link.findall("collision"):
                link.remove(shape)
        with tempfile.TemporaryDirectory() as d:
            path = Path(d) / "arm.urdf"
            path.write_text(ET.tostring(root, encoding="unicode"), encoding="utf-8")
            robot = rtb.Robot.URDF(str(path))
        self.ets = robot.ets(end=tip)
        assert self.ets.n == len(names), (self.ets.n, names)
        self._np = np

    def geometric(self, q):
        """The timed call."""
        return self.ets.jacob0(q)

    def book(self, q):
        """The same in the book's order [ω_s; ṗ]."""
        return self._np.asarray(self.geometric(q))[[3, 4, 5, 0, 1, 2]]
