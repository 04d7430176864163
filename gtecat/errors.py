"""Errors of the controller layer; the GT layer maps every one to a return code."""

from __future__ import annotations

from gtecat.eni.errors import GtecatError


class BusError(GtecatError):
    """The bus cannot do what was asked (not open, not in OP, slave missing...)."""


class ConfigMismatch(BusError):
    """The slaves found do not match the ENI (GT_InitEcatComm -8)."""


class NoEniError(BusError):
    """No configuration file where one was looked for (GT_InitEcatComm -9)."""


class NoSlavesError(BusError):
    """No slave answered the scan (GT_InitEcatComm -10)."""


class StateError(BusError):
    """A slave is not in the state a request needs."""

    def __init__(
        self,
        message: str,
        *,
        expected: object = None,
        actual: object = None,
        slave: int | None = None,
    ) -> None:
        super().__init__(message)
        self.expected = expected
        self.actual = actual
        self.slave = slave


class ParameterError(GtecatError):
    """An argument out of range (GT return code 7)."""


class CommandError(GtecatError):
    """A command whose conditions are not met (GT return code 1)."""
