"""Registries of the parts one module each declares (yield functions, kinds of tools): each
module names itself (NAME) and declares what its registry asks of it."""


def checked(modules: tuple, declares: tuple, what: str) -> dict:
    """NAME -> module, in the given order; TypeError where a module misses one of `declares` or
    a NAME is registered twice (errors of the code, not of a scene; `what` names the kind of
    part in the message)."""
    for m in modules:
        missing = [d for d in declares if not hasattr(m, d)]
        if missing:
            raise TypeError(f"{what} {m.__name__} does not declare {', '.join(missing)}")
    names = [m.NAME for m in modules]
    if len(set(names)) != len(names):
        raise TypeError(f"a {what}'s NAME is registered twice: {names}")
    return {m.NAME: m for m in modules}
