"""Names of the simulated bodies: how the scene builds them and how the log records them (``/tf`` frames,
``/contacts`` pairs, scene entities)."""

OBJECT_NAME = "object"
SUPPORT_NAME = "support"
GROUND_NAME = "ground"
PALM_NAME = "palm"
FINGER_NAMES: tuple[str, str] = ("finger_left", "finger_right")
