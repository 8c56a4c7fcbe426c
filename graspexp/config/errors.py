"""The config package's exception type."""


class ConfigError(ValueError):
    """A composed config holds a value the job cannot use (the message is one line naming the key)."""
