"""A deep-drawing problem from its scene: blank mesh -> sheet model -> tools -> semi-inverse driver.

The punch is the first tool, the die the second; the blank holder is force-controlled. A quarter
blank carries a quarter of the blank-holder force, and its forces are reported for the whole
blank (times 4).
"""

from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from shellform import supports as named_supports
from shellform.contact.semi_inverse import ContactControls, SemiInverseDriver
from shellform.contact.tools import square_cup_tools
from shellform.mesh import rectangle
from shellform.nonlinear.driver import Controls
from shellform.nonlinear.model import SheetModel
from shellform.scene import Scene

PUNCH, DIE = 0, 1


@dataclass
class DrawingProblem:
    scene: Scene
    rect: object
    model: SheetModel
    driver: SemiInverseDriver
    symmetry: int  # 4 for a quarter blank, 1 for the whole blank

    @classmethod
    def from_scene(cls, s: Scene, comm=MPI.COMM_WORLD, checkpoint_dir=None, verbose=True):
        g, m, pr, t = s.geometry, s.mesh, s.process, s.tools
        rect = rectangle(comm, g.lx, g.ly, region=g.region, kind=m.kind, n=m.n, diagonal=m.diagonal,
                         refine=m.refine)
        model = SheetModel(rect.mesh, s.hill79().pack(), s.material.thickness, s.effects, pr.thickness_points)
        bcs = named_supports.boundary_conditions(model.V, model.components, rect.facet_tags, vars(s.supports),
                                                 fixed=named_supports.sheet_fixed_components)
        tools = square_cup_tools(t, s.material.thickness)
        symmetry = 4 if g.region == "quarter" else 1
        controls = Controls(initial_step=pr.initial_step, min_step=pr.min_step, max_step=pr.max_step,
                            max_iterations=pr.max_iterations, rtol=pr.rtol)
        mu = t.friction if "friction" in s.effects else 0.0
        driver = SemiInverseDriver(
            model, bcs, [tools["punch"], tools["die"]], [-t.stroke, 0.0], friction=mu, holder=tools["holder"],
            holder_force=t.blank_holder_force / symmetry, contact=ContactControls(1e-2 * s.material.thickness),
            controls=controls, checkpoint_dir=checkpoint_dir, verbose=verbose)
        return cls(s, rect, model, driver, symmetry)

    # -- measurements (whole blank) ------------------------------------------------------------
    @property
    def stroke(self) -> float:
        return self.driver.lam * self.scene.tools.stroke

    def tool_force(self, tool: int) -> np.ndarray:
        """Force of a tool on the sheet (x, y, z), whole blank: contact reactions of its nodes
        rotated back from their frames, plus their friction forces."""
        d = self.driver
        on = d.state.tool == tool
        r = d.reactions()[on]
        r = np.where(d.sym_fixed[on], 0.0, r)  # the symmetry planes' reactions are not the tool's
        F = d.frames[: d.n_owned][on]
        f = np.einsum("nji,nj->ni", F, r) + d._friction[on]
        total = d.model.mesh.comm.allreduce(f.sum(axis=0), op=MPI.SUM)
        return self.symmetry * total

    def punch_force(self) -> float:
        """The force the punch pushes with (N, > 0 when drawing), whole blank. In-plane
        components cancel by symmetry; a quarter model reports only z."""
        return -float(self.tool_force(PUNCH)[2])

    def holder_force(self) -> float:
        d = self.driver
        return self.symmetry * d.holder.total(d._fz_holder) if d.holder is not None else 0.0

    def max_penetration(self) -> float:
        """The deepest penetration of any node into any tool (>= 0), all ranks."""
        d = self.driver
        x = d.positions()
        worst = 0.0
        for gap, _ in d._gaps(x, d.lam):
            worst = max(worst, float(-gap.min(initial=0.0)))
        return d.model.mesh.comm.allreduce(worst, op=MPI.MAX)

    def nodal_values(self):
        """Owned nodes: initial (x, y), current position, thickness strain."""
        d = self.driver
        e33 = np.log(2 * d.half_thickness / self.model.thickness)
        return d.X[: d.n_owned, :2], d.positions(), e33

    def in_contact(self) -> dict:
        """Nodes on the punch, on the die and on neither (all ranks)."""
        on = self.driver.count_in_contact()
        total = self.model.V.dofmap.index_map.size_global
        return {"punch": on[f"tool{PUNCH}"], "die": on[f"tool{DIE}"], "free": total - sum(on.values())}
