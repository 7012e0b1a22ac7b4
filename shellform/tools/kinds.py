"""The registry of kinds of tools: what a scene's tools.shape names.

A kind is one module of shellform/tools/ that declares everything about itself:

    NAME                      its name in a scene (tools.shape)
    FIELDS                    its [tools] keys beyond the ones every kind takes, as (name, default,
                              what) in the order a scene lists them; a key two kinds take has one
                              default (the scene's ToolsSpec is made from these: schema.py)
    refuse(key, owners)       the message for a key only other kinds take (owners: their NAMEs)
    complete(spec)            the keys it derives from others (a round tool's half-width from
                              its radius), set on the scene's ToolsSpec when it is made
    check(scene)              its keys' checks (InputError naming the field, shellform.errors.
                              require); returns where the die's flat top begins
                              (protocol.BinderPlan), which the scene's checks of the blank's
                              reach and of the drawbeads use
    tools(spec, thickness)    the factory: {"punch", "die", "holder"} (protocol.Tool; the
                              holder a protocol.Binder) around a sheet of that thickness whose
                              mid-surface is z = 0
    travel(spec)              their paths along their axes (travel.py): {"punch", "die",
                              "holder"} (protocol.ram_travel: the punch travels the stroke)
    check_placement(tools, x, half, planes, comm, tolerance)   the tools against the blank's
                              nodes x before the run (InputError; nothing for analytic tools)
    LINES                     its output: the cup's thickness lines, name -> nodes on it
    RIM                       its output: whether the rim's ear profile is written (rim.csv, rim.png)
    picture_depth(spec)       its output: how far above and below its travelled height a tool's
                              surface picture reaches (protocol.surface_mesh)

Registering it is one line: its module's name in REGISTRY, whose order is the order of
tools.shape's names in messages and of the kinds' keys in a scene (docs/scenes.md: adding a
kind of tools).
"""

import importlib

from shellform import registry

REGISTRY = ("square", "round", "cad", "channel")  # modules of shellform.tools

DECLARES = ("NAME", "FIELDS", "refuse", "complete", "check", "tools", "travel", "check_placement", "LINES",
            "RIM", "picture_depth")


def _checked(modules: tuple) -> dict:
    """name -> module, in registry order (shellform.registry.checked); TypeError also where two
    kinds give one key different defaults (errors of the code, not of a scene)."""
    kinds = registry.checked(modules, DECLARES, "tool kind")
    defaults = {}
    for m in modules:
        for name, default, _ in m.FIELDS:
            if defaults.setdefault(name, default) != default:
                raise TypeError(f"tool kind {m.NAME} gives tools.{name} the default {default!r}, another "
                                f"{defaults[name]!r}")
    return kinds


MODULES = tuple(importlib.import_module(f"{__package__}.{name}") for name in REGISTRY)
KINDS = _checked(MODULES)  # NAME -> module, in registry order
SHAPES = tuple(KINDS)  # tools.shape's names


def kind(shape: str):
    """The module of the kind named `shape` (KeyError for a name no kind has: the scene's
    checks name it first)."""
    return KINDS[shape]


def fields() -> tuple:
    """Every kind's keys (name, default, what), each once, in registry order."""
    seen, out = set(), []
    for m in MODULES:
        for f in m.FIELDS:
            if f[0] not in seen:
                seen.add(f[0])
                out.append(f)
    return tuple(out)


def own_keys(shape: str) -> tuple:
    return tuple(name for name, _, _ in KINDS[shape].FIELDS)


def foreign_keys(shape: str) -> dict:
    """The keys other kinds take and `shape` does not, in registry order: key -> the message."""
    own = set(own_keys(shape))
    out = {}
    for name, _, _ in fields():
        if name not in own:
            owners = tuple(m.NAME for m in MODULES if name in own_keys(m.NAME))
            out[name] = KINDS[shape].refuse(name, owners)
    return out
