"""Errors a user can act on. Each message is one line naming the field and the fix."""


class WarpcausticsError(Exception):
    """Base class: the CLI prints these as one line, without a traceback."""


class ConfigError(WarpcausticsError):
    """A scene file or an override is malformed, unknown, of the wrong type or out of range."""


class DeviceError(WarpcausticsError):
    """The requested device is absent, or the scene does not fit in its memory."""
