"""Errors shellform raises for bad input. Each names the offending field."""


class InputError(ValueError):
    """A scene or argument is invalid; raised before any computation starts."""

    def __init__(self, field: str, message: str):
        self.field, self.message = field, message
        super().__init__(f"{field}: {message}")


def require(cond, name: str, message: str) -> None:
    """Raise InputError(name, message) unless cond."""
    if not cond:
        raise InputError(name, message)
