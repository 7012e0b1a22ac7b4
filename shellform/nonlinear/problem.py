"""A nonlinear sheet problem on a blank: mesh -> model -> supports -> loads -> driver.

    p = SheetProblem.on_rectangle(comm, lx, ly, region, n, material, thickness, effects,
                                  supports, loads, prescribed, controls)
    p = SheetProblem.on_blank(blank_mesh, material, thickness, effects, supports, ...)  # any outline
    p = SheetProblem.from_scene(scene)  # a nonlinear scene (`shellform run`)
    p.driver.run(1.0)
    p.value("w", x, y), p.reaction(side, "w")

`prescribed` maps (side, component) to the value reached at load factor 1 (displacement
control); those components are also held on the side. The side "all" holds the component at
every vertex, and a value may be a function of the initial (x, y) (a homogeneous deformation
imposed everywhere: a material test on the structural model, free of structural instability). Studies, tests and `shellform run` build
their problems here.
"""

from dataclasses import dataclass

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform import supports as named_supports
from shellform.edge_frames import SheetEdgeFrames
from shellform.loads import value_at
from shellform.mesh import blank, rectangle
from shellform.nonlinear.driver import Controls, Driver
from shellform.nonlinear.loads import EdgeMoment, NodalLoads, PointForce, SheetLoads
from shellform.nonlinear.model import SheetModel


def scene_controls(s) -> Controls:
    """The Newton driver's controls from a scene's [process]: the load-factor steps (initial,
    min, max), the iterations per increment and the residual tolerance; the rest at their
    defaults. A tool scene's load factor is the share of tools.stroke the punch has travelled,
    and its steps are given in mm of that travel: dlambda = step_mm / stroke. The one place a
    scene sets them, for the nonlinear sheet (SheetProblem.from_scene) and the tools
    (contact.problem.DrawingProblem.from_scene)."""
    pr = s.process
    if s.tools is not None:
        stroke = s.tools.stroke
        steps = (pr.initial_step_mm / stroke, pr.min_step_mm / stroke, pr.max_step_mm / stroke)
    else:
        steps = (pr.initial_step, pr.min_step, pr.max_step)
    return Controls(initial_step=steps[0], min_step=steps[1], max_step=steps[2],
                    max_iterations=pr.max_iterations, rtol=pr.rtol)


class SheetFields:
    """What a problem shows of its sheet per owned cell, read through to its SheetModel (`model`):
    the measurements the listeners of either route take (results/neck.py, results/fld.py)."""

    model: SheetModel

    def cell_fields(self) -> dict:
        """Per owned cell: equivalent plastic strain, thickness, major and minor strains (SheetModel)."""
        return self.model.cell_fields()

    def surface_strain_rates(self, dq: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
        """Per owned cell d/dp of the major and minor strains along the carrier's derivative dq
        (SheetModel.surface_strain_rates at the driver's carrier)."""
        return self.model.surface_strain_rates(self.driver.q.x.array, dq, step)

    def cell_centres(self) -> np.ndarray:
        """(owned cells, 2) the cells' initial centres."""
        return self.model.cell_centres()

    def membrane_stability(self) -> np.ndarray:
        """Per owned cell the least eigenvalue of its membrane's tangent (results/neck.py)."""
        return self.model.membrane_stability()


@dataclass
class SheetProblem(SheetFields):
    rect: object
    model: SheetModel
    driver: Driver
    prescribed_dofs: dict

    @classmethod
    def from_scene(cls, s, comm=MPI.COMM_WORLD, checkpoint_dir=None, verbose=True):
        """A nonlinear scene's problem: its blank (with vertices at the point loads), Hill 1979
        material, supports, pressure, point forces and edge moments, initial curvature, and
        the controls of its [process] (scene_controls)."""
        loads = SheetLoads(
            pressure=s.loads.pressure, pressure_field=s.pressure_field(),
            points=[PointForce(p.x, p.y, (p.fx, p.fy, p.fz)) for p in s.loads.point],
            moments=[EdgeMoment(mo.side, mo.m) for mo in s.loads.moment])
        controls, kappa0 = scene_controls(s), s.curvature()
        return cls.on_blank(blank(comm, s, [(p.x, p.y) for p in s.loads.point]), s.hill79(), s.material.thickness,
                            s.effects, s.supports, loads, controls=controls,
                            thickness_points=s.process.thickness_points, kappa0=kappa0,
                            checkpoint_dir=checkpoint_dir, verbose=verbose)

    @classmethod
    def on_rectangle(cls, comm, lx, ly, n, material, thickness, effects, supports, loads=None,
                     prescribed=None, controls=None, region="full", kind="structured", diagonal="right",
                     thickness_points=5, kappa0=None, checkpoint_dir=None, verbose=False, parts=()):
        points = [(p.x, p.y) for p in (loads or SheetLoads()).points]
        rect = rectangle(comm, lx, ly, region=region, kind=kind, n=n, diagonal=diagonal, points=points)
        return cls.on_blank(rect, material, thickness, effects, supports, loads, prescribed, controls,
                            thickness_points, kappa0, checkpoint_dir, verbose, parts)

    @classmethod
    def on_blank(cls, rect, material, thickness, effects, supports, loads=None, prescribed=None, controls=None,
                 thickness_points=5, kappa0=None, checkpoint_dir=None, verbose=False, parts=()):
        """The problem on a meshed blank (shellform.mesh.BlankMesh): supports on edges along x or
        y fix components; a clamped, sliding or simply supported curved or oblique edge is held in
        its own frame (shellform.edge_frames.SheetEdgeFrames). parts: callables model -> Part
        (shellform.nonlinear.parts) that the driver composes."""
        loads = loads or SheetLoads()
        mat = material.pack() if hasattr(material, "pack") else np.asarray(material, dtype=np.float64)
        model = SheetModel(rect.mesh, mat, thickness, effects, thickness_points, kappa0,
                           pressure_field=loads.pressure_field)
        V, comps = model.V, model.components
        straight, curved = named_supports.split_by_direction(rect, supports)
        bcs = named_supports.boundary_conditions(V, comps, rect, straight,
                                                 fixed=named_supports.sheet_fixed_components)
        frames = None
        if curved:
            frames = SheetEdgeFrames(V, rect, curved)
            bcs += frames.dirichlet(V)
        qbar = fem.Function(V)
        pdofs = {}
        xy = V.tabulate_dof_coordinates()
        for (side, comp), value in (prescribed or {}).items():
            sub = V.sub(comps.index(comp))
            if side == "all":
                dofs = (V.dofmap.index_map_bs * np.arange(xy.shape[0]) + comps.index(comp)).astype(np.int32)
            else:
                dofs = fem.locate_dofs_topological(sub, 1, rect.facets(side))
            at = xy[dofs // V.dofmap.index_map_bs]
            qbar.x.array[dofs] = value(at[:, 0], at[:, 1]) if callable(value) else value
            pdofs[(side, comp)] = dofs
            bcs.append(fem.dirichletbc(np.float64(0), dofs, sub))
        tol = 1e-9 * rect.size
        nodal = NodalLoads(V, rect.facet_tags, loads, tol) if (loads.points or loads.moments) else None
        driver = Driver(model, bcs, prescribed=qbar if prescribed else None, pressure=loads.pressure,
                        nodal=nodal, controls=controls or Controls(), checkpoint_dir=checkpoint_dir,
                        verbose=verbose, frames=frames, parts=[make(model) for make in parts])
        return cls(rect, model, driver, pdofs)

    def value(self, name: str, x: float, y: float, of: fem.Function | None = None) -> float:
        """The component `name` at the vertex (x, y) of the state (of `of`, a function on the
        carrier's space where given: a sensitivity's dq/dp)."""
        return value_at(self.driver.q if of is None else of, self.model.components, name, x, y, 1e-9 * self.rect.size)

    def reaction(self, side: str, comp: str, residual: np.ndarray | None = None) -> float:
        """Sum over the side of the internal force conjugate to a held component (of
        `residual`, owned rows, where given: a sensitivity's dR/dp gives the reaction's)."""
        dofs = self.prescribed_dofs.get((side, comp))
        if dofs is None:
            sub = self.model.V.sub(self.model.components.index(comp))
            dofs = fem.locate_dofs_topological(sub, 1, self.rect.facets(side))
        owned = self.model.V.dofmap.index_map.size_local * self.model.V.dofmap.index_map_bs
        R = self.driver.residual_full if residual is None else residual
        local = float(np.sum(R[dofs[dofs < owned]]))
        return self.model.mesh.comm.allreduce(local, op=MPI.SUM)
