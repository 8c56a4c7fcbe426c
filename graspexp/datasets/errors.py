"""The one exception type of the datasets package."""


class DatasetError(ValueError):
    """A dataset problem a user can fix: unknown object, missing file, broken mesh, empty grasping area.

    The message always names what is wrong (the object, the full path, the spec file) and, for missing
    data, the command that downloads it.
    """
