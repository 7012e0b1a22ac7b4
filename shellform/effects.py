"""The effects a scene may switch on: one registry of what each one switches on and needs.

A scene simulates only the effects it lists. Each effect is one ``Effect`` record of ``EFFECTS``:

- ``part``: the dotted name of what it switches on: a form term of the linear shell's
  functional (forms/functional.py), an option of the linear element, a part of the nonlinear
  sheet (its strains, its layered section, its material) or a part of the contact with the tools;
- ``needs``: the effects it cannot do without (checked directly; a need's own needs are checked
  as its own entry is, so the closure holds);
- ``routes``: the solvers that know it, in ``ROUTES`` order. A scene is solved by the first route
  that knows every one of its effects (``route``): the linear shell (shellform.linear), the
  nonlinear sheet stepped through load factors (shellform.nonlinear) or the sheet drawn by the
  rigid tools (shellform.contact). An effect no route of the scene knows is an error;
- ``keys``: the scene keys that take a meaning only with it (docs/scenes.md);
- ``why`` and ``doc``: the phrase of its error messages and its line in docs/scenes.md.

Everything else is derived from the registry: the scene's checks (``check``, every error naming
``effects``), the canonical order of the linear element (``canonical``), the form terms that its
functional sums (``form_terms``), ``Scene.nonlinear`` and the table of docs/scenes.md
(``markdown_table``). Adding an effect is one entry here plus the part it names.
"""

import importlib
from dataclasses import dataclass

from shellform.errors import InputError

LINEAR, SHEET, TOOLS = "linear shell", "nonlinear sheet", "tools"
ROUTES = (LINEAR, SHEET, TOOLS)  # in order: each later route is a larger solver
ANY = ROUTES
KINDS = ("form term", "form option", "element option", "sheet part", "material data", "contact part")


@dataclass(frozen=True)
class Effect:
    name: str
    kind: str  # one of KINDS: what sort of thing `part` is
    part: str  # dotted name of the module or object it switches on
    routes: tuple[str, ...]  # the solvers that know it
    needs: tuple[str, ...] = ()
    why: str = ""  # "'name' WHY: it needs ..." in its error messages
    keys: tuple[str, ...] = ()  # scene keys that take a meaning only with it
    doc: str = ""

    @property
    def route(self) -> str:
        """The least solver that knows it."""
        return self.routes[0]


EFFECTS: dict[str, Effect] = {e.name: e for e in (
    Effect("membrane", "form term", "shellform.forms.functional.membrane_terms", ANY,
           doc="membrane energy and membrane-strain constraint; carrier u, v"),
    Effect("bending", "form term", "shellform.forms.functional.bending_terms", ANY,
           doc="bending energy, curvature constraint and string-net boundary terms; carrier w, w_x, w_y"),
    Effect("shallow_curvature", "form option", "shellform.forms.strains", ANY, ("bending", "membrane"),
           why="couples membrane and bending", keys=("surface.R1", "surface.R2", "surface.z0"),
           doc="the curvature terms of the strains: the 1/R (kappa0) terms of f^p and f^b, the reference "
               "surface z0 of the nonlinear sheet"),
    Effect("cubic_membrane", "element option", "shellform.assembly.hybrid_element.HybridElement", (LINEAR,),
           ("membrane",), why="interpolates the membrane",
           doc="u, v interpolated as w is (the reduced cubic) and the assumed membrane strain quadratic: "
               "a membrane that bends in plane (docs/locking.md)"),
    Effect("geometric_nonlinearity", "sheet part", "shellform.forms.kirchhoff_love", (SHEET, TOOLS),
           ("bending", "membrane"), why="is an effect of the nonlinear sheet, a full shell",
           doc="exact (total-Lagrangian Kirchhoff-Love) membrane and bending strains and the "
               "initial-stress stiffness"),
    Effect("deep_shell", "sheet part", "shellform.forms.kirchhoff_love", (SHEET, TOOLS), ("bending", "membrane"),
           why="is an effect of the nonlinear sheet, a full shell",
           doc="the Kirchhoff-Love sheet on the exact reference surface X0 = (x, y, z0), not shallow theory; "
               "its strains linearised unless geometric_nonlinearity is on: the linear deep shell"),
    Effect("plasticity", "sheet part", "shellform.material.section", (SHEET, TOOLS), ("bending", "membrane"),
           why="is an effect of the nonlinear sheet, a full shell",
           keys=("material.hardening", "material.yield_stress", "material.n", "material.K", "material.eps0",
                 "material.Q", "material.beta", "material.swift_weight", "material.flow_curve",
                 "material.extrapolation", "material.forming_limit_curve"),
           doc="elastic-plastic layers through the thickness (process.thickness_points), Hill 1979 with "
               "isotropic hardening"),
    Effect("anisotropy", "material data", "shellform.material.criteria", (SHEET, TOOLS), ("plasticity",),
           why="shapes the yield function",
           keys=("material.r", "material.m", "material.yield_function", "material.rolling_direction",
                 "material.r0", "material.r45", "material.r90", "material.r_b", "material.sigma0",
                 "material.sigma45", "material.sigma90", "material.sigma_b", "material.alpha", "material.a",
                 "material.fit_angles", "material.fit_r", "material.fit_sigma", "material.coefficients"),
           doc="r != 1 or m != 2 in the Hill 1979 yield function, or a planar-anisotropic one "
               "(material.yield_function, its parameters, material.rolling_direction); it adds no term"),
    Effect("finite_strain", "sheet part", "shellform.material.hencky", (SHEET, TOOLS),
           ("plasticity", "geometric_nonlinearity"), why="(logarithmic strains, thinning) acts on plastic layers "
                                                          "in large displacements",
           doc="the layers in logarithmic strains, a bending lever arm that thins with the sheet"),
    Effect("assumed_membrane", "sheet part", "shellform.assembly.assumed_membrane", (SHEET, TOOLS),
           ("bending", "membrane"), why="is an effect of the nonlinear sheet, a full shell",
           doc="the membrane strain tied to the element edges (the string net), against membrane locking "
               "of thin sheets that bend far (docs/locking.md)"),
    Effect("contact", "contact part", "shellform.contact.contact_set.ContactSet", (TOOLS,), ("geometric_nonlinearity",),
           why="with the tools moves the sheet far", keys=("tools",),
           doc="contact of the sheet with the rigid tools of [tools]"),
    Effect("friction", "contact part", "shellform.contact.friction.CoulombFriction", (TOOLS,), ("contact",),
           why="acts at the contact with the tools",
           keys=("tools.friction", "tools.punch_friction", "tools.die_friction", "tools.holder_friction"),
           doc="Coulomb friction at that contact, coefficient tools.friction on every tool or a tool's own "
               "(tools.punch_friction, die_friction, holder_friction), one > 0"),
    Effect("ironing", "contact part", "shellform.contact.ironing.Ironing", (TOOLS,), ("contact", "finite_strain"),
           why="bounds the thickness of a sheet that thins and thickens between the tools",
           doc="where two tools face each other across the sheet closer than its thickness (the punch's and "
               "the die's walls), their faces press it to the clearance: a through-thickness pressure in "
               "the section (docs/contact.md, Ironing)"),
    Effect("drawbeads", "contact part", "shellform.contact.drawbead.Drawbeads", (TOOLS,), ("contact",),
           why="act on the flange the tools hold", keys=("tools.drawbead",),
           doc="drawbeads on the flange, [[tools.drawbead]]: lines that restrain the flow across them and "
               "lift the sheet, per unit length (the equivalent drawbead model)"),
)}


def check(effects) -> None:
    """Raise InputError('effects', ...) unless every effect is known, listed once, something is
    assembled, every effect's needs are on, and one route knows every effect."""
    effects = tuple(effects)
    for e in effects:
        if e not in EFFECTS:
            raise InputError("effects", f"unknown effect {e!r}; known effects: {', '.join(EFFECTS)}")
    if len(set(effects)) != len(effects):
        raise InputError("effects", "an effect is listed twice")
    terms = [n for n, e in EFFECTS.items() if e.kind == "form term"]
    if not any(e in terms for e in effects):
        raise InputError("effects", f"needs {' or '.join(map(repr, terms))} (nothing would be assembled)")
    for e in effects:
        require(e, effects)
    chosen = route(effects)
    for e in effects:
        if chosen not in EFFECTS[e].routes:
            raise InputError("effects", f"{e!r} is an effect of the {' and the '.join(EFFECTS[e].routes)} only; "
                             f"the scene's other effects make it a {chosen} scene")


def require(name: str, effects) -> None:
    """Raise InputError('effects', ...) if an effect that `name` needs is not in `effects`."""
    e = EFFECTS[name]
    missing = [n for n in e.needs if n not in effects]
    if missing:
        raise InputError("effects", f"{name!r} {e.why}: it needs {' and '.join(map(repr, e.needs))} "
                         f"(missing: {', '.join(missing)})")


def route(effects) -> str:
    """The solver of a scene: the first of ROUTES at or past every effect's least route."""
    return ROUTES[max((ROUTES.index(EFFECTS[e].route) for e in effects if e in EFFECTS), default=0)]


def canonical(effects) -> tuple[str, ...]:
    """`effects` in the registry's order (the linear element's fields follow it)."""
    return tuple(n for n in EFFECTS if n in effects)


def form_terms(effects) -> list:
    """The term builders of the linear shell's functional that `effects` switch on, in order."""
    out = []
    for n in canonical(effects):
        if EFFECTS[n].kind == "form term":
            module, _, attribute = EFFECTS[n].part.rpartition(".")
            out.append(getattr(importlib.import_module(module), attribute))
    return out


def markdown_table() -> str:
    """The effects table of docs/scenes.md, one row per registry entry."""
    rows = ["| effect | switches on | needs | solvers that know it | keys it gives a meaning | what it does |",
            "|---|---|---|---|---|---|"]
    for e in EFFECTS.values():
        rows.append(f"| `{e.name}` | {e.kind} `{e.part}` | {', '.join(e.needs) or '-'} | "
                    f"{' or '.join(e.routes) if e.routes != ANY else 'all'} | "
                    f"{', '.join(f'`{k}`' for k in e.keys) or '-'} | {e.doc} |")
    return "\n".join(rows)


if __name__ == "__main__":
    print(markdown_table())
