"""A clamped elastic-plastic strip under pressure as scene text, the small nonlinear sheet scene
that tests of a run's stops (interrupts, a full disk) drive through the command line."""


def strip_scene(title: str, n: int, pressure: float, process: str, output: str) -> str:
    """The strip's TOML: 1 x 0.125 clamped at its left end, n cells along, a perfectly plastic
    sheet (Swift n = 0); `process` and `output`: the bodies of those tables."""
    return f"""title = "{title}"
effects = ["bending", "membrane", "plasticity"]
[geometry]
lx = 1.0
ly = 0.125
[mesh]
n = {n}
[material]
E = 1000.0
nu = 0.3
thickness = 0.02
hardening = "swift"
K = 1.0
eps0 = 1.0
n = 0.0
[supports]
left = "clamped"
top = "symmetry"
bottom = "symmetry"
[loads]
pressure = {pressure!r}
[process]
{process.strip()}
[output]
{output.strip()}
"""
