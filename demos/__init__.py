"""The demos' scenes as package data: this folder installs as shellform.demos.

    from shellform import demos
    demos.path("nakajima.toml")                    # the scene file, wherever shellform is installed
    demos.path("meshes/nakajima/specimen.geo")     # a mesh or CAD file a scene names

demos/ stays the one copy of the scenes (the README, `make demo` and the tests read it in the
clone); pyproject.toml maps it to the subpackage shellform.demos (package-dir, as forms/ is
shellform.forms) and ships its *.toml and meshes/** as package data, so that a wheel holds the
scenes the studies draw. `path` finds them beside this file: in the clone (an editable install
maps shellform.demos to demos/) and in site-packages alike, and never by walking up from the
package to a source tree.
"""

from pathlib import Path

HERE = Path(__file__).resolve().parent


def path(name: str) -> Path:
    """The file `name` of the demos (a scene such as "square_cup.toml", or a mesh or CAD file
    under "meshes/"), as an absolute path; FileNotFoundError naming the folder where none is."""
    found = HERE / name
    if not found.is_file():
        raise FileNotFoundError(f"no demo file {name!r} in {HERE}")
    return found
