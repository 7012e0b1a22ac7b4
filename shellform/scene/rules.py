"""The rules every scene check uses: ``require`` (an InputError naming the field unless a
condition holds) and ``keys_of_effects`` (a key that takes a meaning only with an effect keeps
its default without it)."""

from shellform import effects as registry
from shellform.errors import require  # noqa: F401  (the scene checks' rule, shared with the tool kinds)

def sheet_effects() -> tuple[str, ...]:
    """The effects that select the nonlinear sheet."""
    return tuple(n for n, e in registry.EFFECTS.items() if e.route == registry.SHEET)

def keys_of_effects(s, section: str) -> None:
    """The keys of `section` that take a meaning only with an effect (shellform.effects, Effect.keys)
    keep their defaults unless that effect is on. (A whole table, as [tools] of 'contact', is
    checked with its table.)"""
    for e in registry.EFFECTS.values():
        for key in e.keys:
            table, _, name = key.partition(".")
            if e.name in s.effects or table != section or not name or getattr(s, table) is None:
                continue
            value, default = getattr(getattr(s, table), name), getattr(type(getattr(s, table))(), name)
            leave = "leave it unset" if default is None else f"leave the default {default!r}"
            require(value == default, key, f"{value!r} takes a meaning only with the effect {e.name!r}: switch it "
                    f"on, or {leave}")
