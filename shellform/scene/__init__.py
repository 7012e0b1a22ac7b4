"""Scenes: what to simulate, read from TOML and checked before any computation.

    schema   the sections as dataclasses: keys, defaults, allowed names (tools: shellform.tools.kinds)
    read     Scene and its queries; TOML and parsed documents to a Scene, each key's type checked,
             then its values (``validate``); a changed Scene
    checks   the values across fields (``validate``), run whenever a Scene is read
    tool_checks, rules   the [tools] table's checks; the rules every check uses
    machine  what depends on the machine: the blank's file, the mesh's memory

Every bad value raises shellform.errors.InputError naming its field. A scene is changed only by
``Scene.changed``, which checks the new scene again. See docs/scenes.md for every key.
"""

from shellform.scene.checks import validate
from shellform.scene.read import Scene, changed, from_dict, load, settings, to_dict, to_toml
from shellform.scene.schema import *  # noqa: F403  (the sections and their allowed names)
