"""The errors of seamcl's jobs, as the command line's exit code 2 and the service's 4xx are."""


class InputError(ValueError):
    """Bad input: an option out of its bounds or of the wrong type, an unknown option, a scene
    that cannot be read. `field` names the option (or the scene file's JSON path) at fault, as
    the command line's message does; nothing was rendered."""

    def __init__(self, message: str, field: str):
        super().__init__(message)
        self.field = field


class OverBudgetError(InputError):
    """A job this machine cannot hold, refused before it allocates: `field` names the largest
    share of the estimate (size, msaa, scene, frames)."""


class Cancelled(RuntimeError):
    """A job stopped between two units of work at its caller's request."""
