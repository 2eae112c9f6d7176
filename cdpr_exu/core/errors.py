"""The project's own exception and warning types, and the exit code of the ``cdpr`` command for each."""

#: Exit codes of every ``cdpr`` command (the same convention everywhere).
EXIT_OK, EXIT_INTERNAL, EXIT_BAD_INPUT, EXIT_RUN_FAILED, EXIT_INTERRUPTED = 0, 1, 2, 3, 130

EXIT_CODES = """exit codes (every command):
  0    done
  1    internal error (a bug: please report it with the traceback); `cdpr view`: no display
  2    bad input: a scene field, an option, an unreachable pose or an unusable --out;
       refused before any simulation starts
  3    a run failed (for compare and sweep: at least one run failed); what was computed
       up to the failure is written
  130  interrupted (Ctrl-C); what was computed up to then is written
"""


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


class OutputError(CdprError, OSError):
    """An output path cannot be used (it names a file, or cannot be created); checked before any work."""


class RunInterrupted(CdprError, KeyboardInterrupt):
    """The user interrupted a run (Ctrl-C); carries the time reached and the partial result."""

    def __init__(self, message, time=None, partial_result=None):
        super().__init__(message)
        self.time = time
        self.partial_result = partial_result


class CdprWarning(UserWarning):
    """Base class of the project's warnings: a run goes on, but something is worth knowing."""


class CoarseOutputWarning(CdprWarning):
    """The output is sampled more coarsely than asked (its error figures come from fewer samples)."""


class SuspectAnswerWarning(CdprWarning):
    """A computation completed, but its answer is far from an independent one, or held by pushing elements."""


class UnphysicalResultWarning(CdprWarning):
    """A run recorded what no real cable robot can do: elements that push, or a platform above its exits
    (its summary says so too)."""
