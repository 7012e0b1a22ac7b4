"""A deep-drawing problem from its scene: blank mesh -> sheet model -> tools -> semi-inverse driver.

The punch is the first tool, the die the second; the blank holder is force-controlled. A quarter
blank carries a quarter of the blank-holder force, and its forces are reported for the whole
blank (times 4).
"""

import dataclasses
from dataclasses import dataclass

import numpy as np
from dolfinx import fem
from mpi4py import MPI

from shellform import supports as named_supports
from shellform.assembly.sheet_element import BS
from shellform.contact.drawbead import DrawbeadLine
from shellform.contact.semi_inverse import ContactControls, SemiInverseDriver
from shellform.contact.pinch_edge import edge_load
from shellform.material import hardening
from shellform.mesh import blank, outline
from shellform.nonlinear.model import SheetModel
from shellform.nonlinear.problem import SheetFields, scene_controls
from shellform.results import fields
from shellform.scene import Scene
from shellform.tools import kinds as tool_kinds

PUNCH, DIE, HOLDER = 0, 1, 2  # the open holder is the third tool of the contact set
GAP_HOLDER = 2  # a holder at a gap is the third rigid tool


@dataclass
class DrawingProblem(SheetFields):
    scene: Scene
    rect: object
    model: SheetModel
    driver: SemiInverseDriver
    symmetry: int  # 4 for a quarter blank, 1 for the whole blank
    _input_order: tuple | None = dataclasses.field(default=None, repr=False)

    @classmethod
    def from_scene(cls, s: Scene, comm=MPI.COMM_WORLD, checkpoint_dir=None, verbose=True, trace=False):
        pr, t = s.process, s.tools
        rect = blank(comm, s)
        material = s.hill79().pack()
        model = SheetModel(rect.mesh, material, s.material.thickness, s.effects, pr.thickness_points)
        bcs = named_supports.boundary_conditions(model.V, model.components, rect, s.supports,
                                                 fixed=named_supports.sheet_fixed_components)
        kind = tool_kinds.kind(t.shape)
        tools = kind.tools(t, s.material.thickness)
        planes = [outline.MIRROR_NORMALS[g] for g in outline.symmetry_lines(s.geometry)]
        kind.check_placement(tools, rect.mesh.geometry.x, s.material.thickness / 2, planes, comm,
                             1e-2 * s.material.thickness)
        symmetry = s.symmetry_copies
        controls = scene_controls(s)
        # the coefficient of each tool of the contact set, in its order: punch, die, the holder's face
        mu = tuple(t.friction_per_tool().values()) if "friction" in s.effects else 0.0
        beads = tuple(DrawbeadLine(tuple(map(tuple, b.points)), b.restraint, b.uplift) for b in t.drawbead)
        paths = kind.travel(t)
        if t.holder == "gap":  # a third rigid tool: the holder's face holder_gap above the die's top
            face = tools["holder"].at_gap(t.holder_gap, s.material.thickness)
            rigid, travel = [tools["punch"], tools["die"], face], [paths["punch"], paths["die"], paths["holder"]]
            holder, force, edge = None, 0.0, None
        else:
            rigid, travel, holder, force = [tools["punch"], tools["die"]], [paths["punch"], paths["die"]], \
                tools["holder"], t.blank_holder_force / symmetry
            edge = edge_load(material, s.material.thickness, tools["die"], tools["holder"])
        driver = SemiInverseDriver(
            model, bcs, rigid, travel, friction=mu, holder=holder, holder_force=force, drawbeads=beads, die=DIE,
            holder_edge=edge,
            contact=ContactControls(1e-2 * s.material.thickness, holder_spread=t.holder_spread, trace=trace),
            controls=controls, checkpoint_dir=checkpoint_dir, verbose=verbose, ironing="ironing" in s.effects)
        return cls(s, rect, model, driver, symmetry)

    # -- measurements (whole blank) ------------------------------------------------------------
    @property
    def stroke(self) -> float:
        return self.driver.lam * self.scene.tools.stroke

    def tool_force(self, tool: int, residual: np.ndarray | None = None) -> np.ndarray:
        """Force of a tool on the sheet (x, y, z), whole blank: contact reactions of its nodes
        rotated back from their frames, plus their friction forces. On the die this includes
        the nodes the closed holder pinches (their net force, die minus holder, and the
        friction of both faces); the open holder's are its own (HOLDER). With `residual` (owned
        rows, the nodes' frames: a Sensitivity's dR/dp of the sheet's forces, which on a tool's
        node are its reaction and the friction they balance, R0 n + f) the force's sensitivity:
        those rows turned back with the frames held, d(F^T R) = F^T dR exactly, the frames'
        own turn cancelling (the ironing's face left out: it has no derivatives)."""
        d = self.driver
        on = d.contact.on(tool)
        if residual is not None:
            r = np.asarray(residual)[: d.n_owned * BS].reshape(-1, BS)[on, :3]
            r = np.where(d.nodes.held[on, :3], 0.0, r)
            f = np.einsum("nji,nj->ni", d.frames[: d.n_owned][on], r)
            return self.symmetry * d.model.mesh.comm.allreduce(f.sum(axis=0), op=MPI.SUM)
        r = d.reactions()[on]
        r = np.where(d.nodes.held[on, :3], 0.0, r)  # the symmetry planes' reactions are not the tool's
        F = d.frames[: d.n_owned][on]
        f = np.einsum("nji,nj->ni", F, r) + d.friction.force[on]
        total = d.model.mesh.comm.allreduce(f.sum(axis=0), op=MPI.SUM)
        if d.ironing is not None:  # its face's push on the nodes it irons on another tool
            total = total + d.ironing.face_force(tool)
        return self.symmetry * total

    def punch_force(self, residual: np.ndarray | None = None) -> float:
        """The force the punch pushes with along its travel (N, > 0 when drawing), whole blank:
        the sheet's force from it along its axis, negated (the punch travels down its axis,
        +z for the analytic punch); with `residual`, its sensitivity (tool_force)."""
        return -float(self.tool_force(PUNCH, residual) @ self.driver.tools[PUNCH].axis)

    def holder_force(self) -> float:
        """The sum of the holder's nodal forces on the sheet (N, pressing down), whole blank: the
        closed holder's face forces, or the open holder's reactions (a node frozen on its face
        after its switches in an increment may pull it, which friction does not see)."""
        d = self.driver
        if self.scene.tools.holder == "gap":
            return -float(self.tool_force(GAP_HOLDER)[2])
        if d.holder is None:
            return 0.0
        if d.holder.is_open:
            return -float(self.tool_force(HOLDER)[2])
        return self.symmetry * d.holder.total()

    def holder_share(self) -> float:
        """The largest force one node takes from the holder, as a fraction of the holder's force."""
        d = self.driver
        if d.holder is None or d.holder.force <= 0:
            return 0.0
        return d.model.mesh.comm.allreduce(float(d.holder.face.max(initial=0.0)), op=MPI.MAX) / d.holder.force

    def holder_pressure(self) -> tuple[float, float]:
        """The holder's largest pressure on a node, h_i / a_i (MPa: its face force over a
        third of the current plan area of the cells around it), and the largest ratio of that
        pressure to the sheet's flow stress at the node, sigma_bar(p_i) with p_i the area-weighted
        mean of the cells' equivalent plastic strain around it (the reference flow curve), all
        ranks; zeros without a holder force. The face force is the closed holder's split of F or the
        open holder's contact force. The mesh-independent form of "how much of F one node
        takes": a face pressing harder than the flow stress would iron the flange through its
        thickness (docs/contact.md, "The holder's pressure")."""
        d = self.driver
        if d.holder is None or d.holder.force <= 0:
            return 0.0, 0.0
        m = d.model
        sums = d.nodes.cell_sums(m.cell_area * m.plastic_strain(), m.cell_area)
        pressure = np.divide(d.holder.face, d.nodes.current_area())
        pressed = np.flatnonzero(pressure > 0)
        flow = np.array([hardening.flow_stress(float(p), m.material)[0] for p in sums[pressed, 0] / sums[pressed, 1]])
        comm = m.mesh.comm
        return (comm.allreduce(float(pressure.max(initial=0.0)), op=MPI.MAX),
                comm.allreduce(float(np.max(pressure[pressed] / flow, initial=0.0)), op=MPI.MAX))

    def holder_held_down(self) -> tuple[float, float, float]:
        """The closed holder's (held down, edge load, off the band) as fractions of F (holder.py,
        held_down): the part of its force that holds pinched nodes down against the sheet's own
        lift, the edge's band included, the edge load's demand (> 1: it rides on its edge), and
        the holding-down off the edge's band. Zeros when the holder is open."""
        d = self.driver
        if d.holder is None or d.holder.force <= 0 or not d.holder.closed:
            return 0.0, 0.0, 0.0
        return d.holder.held_down(d.net_normal_forces())

    def holder_largest_at(self) -> tuple[float, float]:
        """Initial (x, y) of the node with the largest holder force (mm), all ranks."""
        d = self.driver
        comm = d.model.mesh.comm
        h = d.holder.face if d.holder is not None else np.zeros(0)
        i = int(np.argmax(h)) if h.size else -1
        mine = (float(h[i]), tuple(d.nodes.X[i, :2])) if i >= 0 else (-1.0, (np.nan, np.nan))
        _, xy = max(comm.allgather(mine), key=lambda c: c[0])
        return float(xy[0]), float(xy[1])

    def holder_height(self) -> float:
        """The holder's face: the highest top z + t/2 of the sheet under it (mm)."""
        d = self.driver
        if d.holder is None:
            return float("nan")
        x = d.positions()
        under = d.holder.under(x)
        top = float((x[under, 2] + d.nodes.half_thickness[under]).max(initial=-np.inf))
        return d.model.mesh.comm.allreduce(top, op=MPI.MAX)

    def holder_lift(self) -> float:
        """The open holder's lift above its closed position (mm; 0 when closed)."""
        d = self.driver
        return 0.0 if d.holder is None or d.holder.closed else float(d.holder.lift)

    def force_balance(self) -> float:
        """|sum of the tools' and the drawbeads' z-forces on the sheet| / punch force: the
        sheet's equilibrium along z (the symmetry planes carry no z-force)."""
        d = self.driver
        fz = sum(float(self.tool_force(k)[2]) for k in range(len(d.tools) + (d.holder is not None)))
        fz += float(self.drawbead_force()[2])
        return abs(fz) / max(abs(self.punch_force()), 1e-300)

    def drawbead_force(self) -> np.ndarray:
        """The drawbeads' force on the sheet (x, y, z), whole blank: their restraint and uplift."""
        d = self.driver
        if d.drawbeads is None:
            return np.zeros(3)
        return self.symmetry * d.drawbeads.total(d.model.mesh.comm)

    def max_penetration(self) -> float:
        """The deepest penetration of any node into any tool (>= 0), all ranks."""
        d = self.driver
        x = d.positions()
        worst = 0.0
        for gap, _ in d.contact.gaps(x, d.lam):
            worst = max(worst, float(-gap.min(initial=0.0)))
        return d.model.mesh.comm.allreduce(worst, op=MPI.MAX)

    def blank_bounds(self) -> tuple[float, float, float, float]:
        """x_min, x_max, y_min, y_max of the meshed blank (a quarter: from the symmetry lines)."""
        return tuple(self.rect.bounds)

    def blank_size(self) -> float:
        """The meshed blank's size (its larger side), the scale of its tolerances."""
        return float(self.rect.size)

    def displacements(self) -> np.ndarray:
        """(u, v, w) of every local node, the owned ones first (a view of the carrier)."""
        return self.driver.q.x.array.reshape(-1, BS)[:, :3]

    def initial_positions(self) -> np.ndarray:
        """(n_owned, 3) the owned nodes' initial positions."""
        return self.driver.nodes.X[: self.driver.n_owned]

    def nodal_values(self):
        """Owned nodes: initial (x, y), current position, thickness strain."""
        d = self.driver
        e33 = np.log(2 * d.nodes.half_thickness / self.model.thickness)
        return d.nodes.X[: d.n_owned, :2], d.positions(), e33

    def nodal_thickness_strain_derivative(self, de33: np.ndarray) -> np.ndarray:
        """Owned nodes: d/dp of nodal_values()'s e33 = ln(2 h_i / t), h_i'/h_i, from the cells'
        d e33/dp (a Sensitivity's thickness_strain; SheetNodes.half_thickness_derivative)."""
        nodes = self.driver.nodes
        return nodes.half_thickness_derivative(de33) / nodes.half_thickness

    def rim(self) -> np.ndarray:
        """Owned nodes on the blank's outer edge: those of the boundary groups the scene leaves
        free (the tools hold the blank there; a quarter's symmetry lines are not its edge), as a
        boolean mask over the owned nodes of nodal_values()."""
        V, n = self.model.V, self.driver.n_owned
        on = np.zeros(n, dtype=bool)
        fdim = self.rect.facet_tags.dim
        for group in self.rect.groups:
            if self.scene.supports.get(group, "free") == "free":
                nodes = fem.locate_dofs_topological(V, fdim, self.rect.facets(group))
                on[nodes[nodes < n]] = True
        return on

    def in_contact(self) -> dict:
        """Nodes on the punch, on the die (of which pinched by the holder), on the open holder's
        face and on none (all ranks)."""
        on = self.driver.count_in_contact()
        total = self.model.V.dofmap.index_map.size_global
        holder = on.get(f"tool{HOLDER}", 0)
        return {"punch": on[f"tool{PUNCH}"], "die": on[f"tool{DIE}"], "pinched": on["pinched"], "holder": holder,
                "free": total - on[f"tool{PUNCH}"] - on[f"tool{DIE}"] - holder}

    def free_under_holder(self) -> int:
        """Nodes under the closed holder that are not pinched (all ranks; 0 when it is open)."""
        d = self.driver
        if d.holder is None or not d.holder.closed:
            return 0
        loose = d.holder.under(d.positions()) & ~d.holder.pinched
        return d.model.mesh.comm.allreduce(int(loose.sum()), op=MPI.SUM)

    # -- the drawn sheet as the results read it (shellform.results.cup, "the drawn sheet") -----
    @property
    def comm(self):
        """The sheet's communicator: every measurement here is collective over it or local to a rank."""
        return self.model.mesh.comm

    @property
    def mesh(self):
        """The blank's mesh (the series' functions live on it)."""
        return self.rect.mesh

    @property
    def tools_kind(self):
        """The scene's kind of tools (shellform.tools.kinds: its LINES, RIM, picture_depth)."""
        return tool_kinds.kind(self.scene.tools.shape)

    @property
    def material(self):
        """The scene's [material] section (the forming-limit curve's data)."""
        return self.scene.material

    def picture_depth(self) -> float:
        """How deep the tools' surfaces are drawn in a picture or a series (the kind's own)."""
        return self.tools_kind.picture_depth(self.scene.tools)

    @property
    def num_cells(self) -> int:
        """The owned cells."""
        return self.model.num_cells

    def cell_thickness_strain(self) -> np.ndarray:
        """Per owned cell its thickness strain."""
        return self.model.thickness_strain()

    def volume_change(self) -> float:
        """(V - V0) / V0 of the whole sheet."""
        return self.model.volume_change()

    def resultants(self) -> np.ndarray:
        """(owned cells, quadrature points, 6) the stress resultants N and M of the last evaluation."""
        return self.model.resultants

    def input_order(self):
        """The owned nodes' and cells' indices in the mesh's input (results.fields.input_order),
        made once: the same files on any number of ranks."""
        if self._input_order is None:
            self._input_order = fields.input_order(self.model.V, self.model.num_cells)
        return self._input_order

    # -- what the results show -----------------------------------------------------------------
    CONTACT_STATES = ("free", "punch", "die", "holder", "pinched")  # contact_nodes()'s codes 0 to 4

    def contact_nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """Owned nodes: the contact state, an index into CONTACT_STATES (free, on the punch, on
        the die, on the open holder's face, pinched between the die and the closed holder), and
        the contact pressure (MPa): the normal force of the face the node lies on (the die's on
        a pinched node) over the node's tributary area in the initial blank."""
        d = self.driver
        state = d.contact.tool.astype(np.int8) + 1
        if d.holder is not None:
            state[d.holder.pinched] = self.CONTACT_STATES.index("pinched")
        on_holder = state == self.CONTACT_STATES.index("holder")  # the open holder's face carries their force
        face = d.holder.face if d.holder is not None else 0.0
        force = np.where(on_holder, face, d.contact.pressure)
        return state, force / d.nodes.area

    def tool_placements(self) -> dict:
        """The tools where they are now: name -> (tool, its travel along its axis from its initial
        position, whether it lies above the sheet). The punch has moved by its share of the stroke; the
        holder's face rests on the sheet's highest top under it (holder_height), or lies at its
        lift when open."""
        d = self.driver
        out = {name: (tool, float(path.at(d.lam)), name != "die")  # the gap holder is the third tool
               for name, tool, path in zip(("punch", "die", "blank_holder"), d.tools, d.paths)}
        if d.holder is not None:
            face = d.holder.tool
            top = self.holder_height()
            shift = self.holder_lift() if not np.isfinite(top) or not d.holder.closed else top - face.z_face
            out["blank_holder"] = (face, float(max(shift, 0.0)), True)
        return out
