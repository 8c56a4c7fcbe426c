"""Names of the simulated bodies: how the scene builds them and how the log records them (``/tf`` frames,
``/contacts`` pairs, scene entities); and the floor's size, which the simulator builds and the camera sees."""

OBJECT_NAME = "object"
SUPPORT_NAME = "support"
GROUND_NAME = "ground"
FLOOR_HALF_SIZE_M = (10.0, 10.0, 0.05)
"""Half extents of the floor box (body :data:`GROUND_NAME`) whose top is z = 0, m (wide enough to catch
anything that falls off): the simulator's floor and the one the depth camera sees."""
PALM_NAME = "palm"
FINGER_NAMES: tuple[str, str] = ("finger_left", "finger_right")
TRAY_NAME = "tray"
"""The walls of the box a pile is dropped into (``mode=pile``), removed before the first attempt."""


def clutter_body(slot: int) -> str:
    """Name of the body of a clutter round's object ``slot`` (its /tf frame and /contacts name)."""
    return f"{OBJECT_NAME}_{slot}"
