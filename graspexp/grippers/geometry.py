"""The geometry of a parallel-jaw gripper, box model or URDF: the one description the planner's collision
checks, the simulated articulation, the log's scene and the figures all use (all lengths in metres).

Gripper frame (paper Fig. 9): +Z approach, +X main axis, +Y closing axis, origin midway between the finger
pads (the TCP). A box model's finger and palm boxes come from its config keys
(:class:`graspexp.config.GripperConfig`); a URDF gripper's convex pieces from its file
(:mod:`graspexp.grippers.urdf`).
"""

from dataclasses import dataclass

import numpy as np

from graspexp.config.gripper import GripperConfig
from graspexp.grippers.urdf import LEFT, PALM, RIGHT, HandMeshes, load_hand


@dataclass(frozen=True)
class Box:
    """An axis-aligned box: centre (3,) and full size (3,), m, in the frame its owner names."""

    center: tuple[float, float, float]
    size: tuple[float, float, float]


@dataclass(frozen=True)
class GripperGeometry:
    """The finger and palm boxes of a parallel-jaw gripper: the one description the planner's collision
    checks, the simulated articulation, the log's scene and the figures all use.

    Gripper frame: +Z approach, +X main axis, +Y closing axis, origin midway between the pads (the TCP).
    The fingers span ``root_z_m`` (the palm face) to ``tip_z_m`` (the fingertips) along Z; the palm box
    lies behind the palm face. A URDF gripper carries its convex pieces in ``hand``; its box values are
    the bounding boxes of its fingers and palm (the pads' reach: ``finger_width_m``, ``root_z_m``,
    ``tip_z_m``, ``finger_thickness_m``), and every volume check uses ``hand`` instead of the boxes.
    """

    finger_width_m: float
    """Along X, m."""
    finger_thickness_m: float
    """Along Y, m."""
    finger_length_m: float
    """Along Z, m."""
    palm_size_m: tuple[float, float, float]
    """Full size along X, Y, Z, m."""
    root_z_m: float
    """Z of the palm face, where the fingers start, m."""
    tip_z_m: float
    """Z of the fingertips, m (``tcp_from_tip_m`` in front of the TCP)."""
    hand: HandMeshes | None = None
    """The convex pieces and meshes of a URDF gripper (None: a box model)."""

    @classmethod
    def of(cls, g: GripperConfig) -> "GripperGeometry":
        """The geometry of gripper config ``g`` (a URDF's is read once per process, see :func:`hand_of`)."""
        hand = hand_of(g)
        if hand is not None:
            return cls.of_hand(hand)
        return cls(
            g.finger_width_m,
            g.finger_thickness_m,
            g.finger_length_m,
            tuple(float(v) for v in g.palm_size_m),
            g.tcp_from_tip_m - g.finger_length_m,
            g.tcp_from_tip_m,
        )

    @classmethod
    def of_hand(cls, hand: HandMeshes) -> "GripperGeometry":
        """The geometry of a URDF gripper: its pieces, and the bounding boxes of its palm and left finger."""
        finger = hand.part_vertices(LEFT)
        palm = hand.part_vertices(PALM)
        fingers = np.concatenate([finger, hand.part_vertices(RIGHT)])
        root, tip = float(fingers[:, 2].min()), float(fingers[:, 2].max())
        x_reach = float(np.abs(fingers[:, 0]).max())
        return cls(
            2.0 * x_reach,
            float(finger[:, 1].max() - finger[:, 1].min()),
            tip - root,
            tuple(float(v) for v in palm.max(axis=0) - palm.min(axis=0)),
            root,
            tip,
            hand,
        )

    def palm(self) -> Box:
        """The palm box in the gripper frame."""
        px, py, pz = self.palm_size_m
        return Box((0.0, 0.0, self.root_z_m - pz / 2), (px, py, pz))

    def finger(self, side: float) -> Box:
        """The box of one finger in its own link frame, whose origin is the centre of the pad face (the
        finger's inner face); ``side`` +1 for the left finger (+Y side), -1 for the right."""
        t, L = self.finger_thickness_m, self.finger_length_m
        return Box((0.0, side * t / 2, self.root_z_m + L / 2), (self.finger_width_m, t, L))

    def boxes(self, width_m: float) -> np.ndarray:
        """(3, 2, 3) float64 ``[lo, hi]`` corners of the left finger, right finger and palm in the gripper
        frame, pads ``width_m`` apart, m."""
        fw, t = self.finger_width_m, self.finger_thickness_m
        px, py, pz = self.palm_size_m
        root, tip, h = self.root_z_m, self.tip_z_m, width_m / 2
        return np.array(
            [
                [[-fw / 2, h, root], [fw / 2, h + t, tip]],
                [[-fw / 2, -h - t, root], [fw / 2, -h, tip]],
                [[-px / 2, -py / 2, root - pz], [px / 2, py / 2, root]],
            ]
        )


def hand_of(g: GripperConfig) -> HandMeshes | None:
    """The URDF gripper of config ``g`` (None for a box model); raises
    :class:`graspexp.grippers.urdf.UrdfError` for a file that is not a parallel gripper."""
    if g.urdf is None:
        return None
    joints = None if g.urdf_finger_joints is None else tuple(str(n) for n in g.urdf_finger_joints)
    tcp = None if g.urdf_tcp_m is None else tuple(float(v) for v in g.urdf_tcp_m)
    return load_hand(
        str(g.urdf),
        g.urdf_palm_link,
        joints,
        tuple(float(v) for v in g.urdf_approach_axis),
        tcp,
        float(g.tcp_from_tip_m),
    )
