"""The exception types of the datasets package."""


class DatasetError(ValueError):
    """A dataset problem a user can fix: unknown object, missing file, broken mesh, empty grasping area.

    The message always names what is wrong (the object, the full path, the spec file) and, for missing
    data, the command that downloads it.
    """


class ObjectError(DatasetError):
    """One object cannot be used (a broken or implausibly sized mesh, a bad sidecar or URDF, an empty
    area): that object fails alone, with this message as its recorded reason, while the others run."""
