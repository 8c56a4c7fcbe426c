"""The channels of a trial log: every topic of :mod:`graspexp.record.schemas` on one ``foxglove.Context``."""

import foxglove
from foxglove.channels import (
    CameraCalibrationChannel,
    FrameTransformsChannel,
    PointCloudChannel,
    PoseInFrameChannel,
    RawImageChannel,
    SceneUpdateChannel,
)

from graspexp.core.bodies import FINGER_NAMES, GROUND_NAME, OBJECT_NAME, PALM_NAME, SUPPORT_NAME
from graspexp.record import schemas as S

BODY_NAMES: tuple[str, ...] = (OBJECT_NAME, SUPPORT_NAME, GROUND_NAME, PALM_NAME, *FINGER_NAMES)
"""The physics bodies that can touch, in /contacts index order."""


class Channels:
    """Every channel of a trial log on one ``foxglove.Context`` (its sinks: an MCAP file, a live server)."""

    def __init__(self, context: foxglove.Context, bodies: tuple[str, ...] = BODY_NAMES):
        self.context = context
        self.bodies = bodies
        """The /contacts body names, by index (a clutter round's have one per object)."""
        self.tf = FrameTransformsChannel(S.TOPIC_TF, context=context)
        self.contacts = PointCloudChannel(
            S.TOPIC_CONTACTS, metadata={"bodies": ",".join(bodies)}, context=context
        )
        self.scene = SceneUpdateChannel(S.TOPIC_SCENE, context=context)
        self.grasp_pose = PoseInFrameChannel(S.TOPIC_GRASP_POSE, context=context)
        self.json = {
            topic: foxglove.Channel(
                topic,
                schema=foxglove.Schema(name=name, encoding=S.SCHEMA_ENCODING, data=S.schema_bytes(name)),
                message_encoding=S.MESSAGE_ENCODING,
                context=context,
            )
            for topic, name in S.TOPIC_SCHEMAS.items()
            if name in S.SCHEMAS and topic not in S.CAMERA_TOPICS + S.LAZY_TOPICS
        }
        self._camera: CameraChannels | None = None

    def use_bodies(self, bodies: tuple[str, ...]) -> None:
        """Name the /contacts bodies of the next log on these channels (a live server's serve one trial or
        clutter round after another): the channel is re-created, with its new metadata, when they differ."""
        if bodies != self.bodies:
            self.contacts.close()
            self.contacts = PointCloudChannel(
                S.TOPIC_CONTACTS, metadata={"bodies": ",".join(bodies)}, context=self.context
            )
            self.bodies = bodies

    def lazy_json(self, topic: str) -> foxglove.Channel:
        """The JSON channel of one of :data:`graspexp.record.schemas.LAZY_TOPICS`, created on first use."""
        if topic not in self.json:
            name = S.TOPIC_SCHEMAS[topic]
            self.json[topic] = foxglove.Channel(
                topic,
                schema=foxglove.Schema(name=name, encoding=S.SCHEMA_ENCODING, data=S.schema_bytes(name)),
                message_encoding=S.MESSAGE_ENCODING,
                context=self.context,
            )
        return self.json[topic]

    @property
    def camera(self) -> "CameraChannels":
        """The camera's channels, created on first use (a trial without a camera has none)."""
        if self._camera is None:
            self._camera = CameraChannels(self.context)
        return self._camera


class CameraChannels:
    """The channels of :data:`graspexp.record.schemas.CAMERA_TOPICS`."""

    def __init__(self, context: foxglove.Context):
        self.depth = RawImageChannel(S.TOPIC_DEPTH, context=context)
        self.ids = RawImageChannel(S.TOPIC_IDS, context=context)
        self.calibration = CameraCalibrationChannel(S.TOPIC_CALIBRATION, context=context)
        self.cloud = PointCloudChannel(S.TOPIC_CLOUD, context=context)
        self.perception = foxglove.Channel(
            S.TOPIC_PERCEPTION,
            schema=foxglove.Schema(
                name=S.PERCEPTION, encoding=S.SCHEMA_ENCODING, data=S.schema_bytes(S.PERCEPTION)
            ),
            message_encoding=S.MESSAGE_ENCODING,
            context=context,
        )
