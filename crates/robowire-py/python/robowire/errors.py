"""The exceptions robowire raises: one hierarchy under :class:`Error`.

Where a builtin fits, the class is that builtin too, so existing ``except ValueError`` or
``except OSError`` blocks keep working.
"""

import builtins

__all__ = [
    "Error",
    "ArgumentError",
    "ClosedError",
    "BindError",
    "PortError",
    "NoStateError",
    "TimeoutError",
    "DecodeError",
    "CrcError",
    "ServiceError",
]


class Error(Exception):
    """Base of every robowire exception."""


class ArgumentError(Error, ValueError):
    """An argument is NaN, infinite, out of its documented range or the wrong length.

    Nothing was sent: the previous command stays in force.
    """


class ClosedError(Error):
    """The object is closed, or was never started (``initRobot`` not called)."""


class BindError(Error, OSError):
    """A UDP socket could not be bound; the message lists this host's IPv4 addresses."""


class PortError(Error, OSError):
    """A serial port could not be opened, or failed."""


class NoStateError(Error):
    """No state from the robot: none has arrived yet, or it went silent (watchdog)."""


class TimeoutError(Error, builtins.TimeoutError):
    """A wait ran out of time."""


class DecodeError(Error, ValueError):
    """Bytes that are not the message they should be (length, header, padding)."""


class CrcError(DecodeError):
    """The CRC a message carries (``found``) is not the CRC of its bytes (``expected``)."""

    def __init__(self, message: str, expected: int, found: int) -> None:
        super().__init__(message)
        self.expected = expected
        self.found = found


class ServiceError(Error):
    """A robot service answered with an error code (``code``) or not at all."""

    def __init__(self, message: str, service: str, api_id: int, code: int) -> None:
        super().__init__(message)
        self.service = service
        self.api_id = api_id
        self.code = code
