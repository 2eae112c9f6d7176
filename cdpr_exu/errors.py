"""The project's own exception types."""


class CdprError(Exception):
    """Base class of every error cdpr-exu raises on purpose."""


class SceneError(CdprError, ValueError):
    """A scene field or a function argument is invalid; the message names it and its value."""


class UnreachableError(CdprError, ValueError):
    """A pose or span the cables cannot reach, or a wrench they could only balance by pushing."""


class SolverFailure(CdprError, RuntimeError):
    """The time integration failed; carries the time, the cause and the partial result."""

    def __init__(self, message, time=None, partial_result=None):
        super().__init__(message)
        self.time = time
        self.partial_result = partial_result
