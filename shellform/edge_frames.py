"""Supports on curved and oblique edges: the slope and in-plane displacement DOFs of each
boundary vertex turned into the edge's own normal-tangent frame.

A support fixes, at each vertex of its edge (normal n, tangent s = n rotated by +90 degrees;
shellform.supports names the roles):

    w                  the deflection
    w,n / w,s          the slope along n / along s:   grad w . n = 0,  grad w . s = 0
    u_n / u_s          the in-plane displacement along n / along s

A vertex collects the directions d its edges fix for the slope pair (w_x, w_y) and for the
displacement pair (u, v). Two non-parallel directions fix the whole pair. One direction d that
is an axis fixes that component. Any other d turns the pair into the frame (d, d_perp):

    (a_x, a_y) = a_1 d + a_2 d_perp,   i.e.   q = R q',   R = [[d_x, -d_y], [d_y, d_x]] per pair,

and fixes a_1. The system becomes R^T K R q' = R^T f with the fixed rows and columns of q'
replaced by the identity, and q = R q'. Imposing w,s = 0 with the true tangent of a circle
(and leaving w,n free) is what makes a simply supported curved edge converge to the curved
plate, not to the polygon's (the Babuska paradox; a C1 element that fixed both slopes at the
vertices of the polygon would clamp it).

Normals: exact where the outline is known (BlankMesh.normals: the circle's rim), else the mean
of the unit outward normals of the group's facets at the vertex, summed over all ranks.
"""

import dolfinx.mesh
import numpy as np
from dolfinx import la
from mpi4py import MPI
from petsc4py import PETSc

from shellform import _jit as jit
from shellform.errors import InputError

_ROLES = {  # support -> roles fixed (linear plate and shell)
    "simply_supported": ("w", "w,s", "u_s"),
    "clamped": ("w", "w,n", "w,s", "u_n", "u_s"),
    "symmetry": ("w,n", "u_n"),
    "free": (),
}
_PAIRS = {"slope": ("w_x", "w_y"), "disp": ("u", "v")}


def facet_normals(blank, facets) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Vertices (n, 2), end points (n, 2, 2) and unit outward normals (n, 2) of boundary facets."""
    msh = blank.mesh
    top = msh.topology
    for d0, d1 in ((1, 0), (1, 2)):
        top.create_connectivity(d0, d1)
    f2v, f2c = top.connectivity(1, 0), top.connectivity(1, 2)
    x = msh.geometry.x[:, :2]
    facets = np.asarray(facets, dtype=np.int32)
    verts = f2v.array.reshape(-1, 2)[facets]
    ends = x[dolfinx.mesh.entities_to_geometry(msh, 1, facets)]
    t = ends[:, 1] - ends[:, 0]
    n = np.column_stack([t[:, 1], -t[:, 0]]) / np.hypot(t[:, 0], t[:, 1])[:, None]
    cells = np.array([f2c.links(f)[0] for f in facets], dtype=np.int32)
    centroid = x[dolfinx.mesh.entities_to_geometry(msh, 2, cells)].mean(axis=1)
    flip = np.sum(n * (ends.mean(axis=1) - centroid), axis=1) < 0
    n[flip] *= -1
    return verts, ends, n


def _vertex_blocks(V) -> np.ndarray:
    """Dof block of each local mesh vertex of the P1 carrier V."""
    top = V.mesh.topology
    c2v = top.connectivity(2, 0).array.reshape(-1, 3)
    out = np.empty(top.index_map(0).size_local + top.index_map(0).num_ghosts, dtype=np.int32)
    out[c2v.ravel()] = V.dofmap.list.ravel()
    return out


def group_vertex_normals(V, blank, group, ghosts: bool = False) -> dict[int, np.ndarray]:
    """Dof block -> unit outward normal, for the owned (and with `ghosts` the ghost) vertices of
    a boundary group."""
    facets = blank.facets(group)
    facets = facets[facets < blank.mesh.topology.index_map(1).size_local]  # owned: counted once
    verts, _, n = facet_normals(blank, facets)
    blocks = _vertex_blocks(V)
    acc = la.vector(V.dofmap.index_map, 3)
    a = acc.array.reshape(-1, 3)
    for k in (0, 1):
        np.add.at(a, blocks[verts[:, k]], np.column_stack([n, np.ones(len(n))]))
    acc.scatter_reverse(la.InsertMode.add)
    owned = V.dofmap.index_map.size_local
    if ghosts:
        acc.scatter_forward()
        owned += V.dofmap.index_map.num_ghosts
    hit = np.flatnonzero(a[:owned, 2] > 0)
    normal = a[hit, :2] / np.hypot(a[hit, 0], a[hit, 1])[:, None]
    exact = blank.normals.get(group)
    if exact is not None:
        xy = V.tabulate_dof_coordinates()[hit, :2]
        normal = np.column_stack(exact(xy[:, 0], xy[:, 1]))
    return dict(zip(hit.tolist(), normal))


def pair_constraint(directions: list[np.ndarray], tol: float) -> tuple[str, np.ndarray]:
    """What the directions d (a_d = grad . d = 0) fixed at one vertex do to a component pair
    (a_x, a_y): ("both", d) for two non-parallel ones, ("x", d) or ("y", d) for one along an
    axis, ("turn", d) for any other one (fix a_1 of a_x, a_y = a_1 d + a_2 d_perp)."""
    d = directions[0] / np.hypot(*directions[0])
    if any(abs(d[0] * e[1] - d[1] * e[0]) > tol for e in directions[1:]):
        return "both", d
    if abs(d[1]) <= tol:
        return "x", d
    if abs(d[0]) <= tol:
        return "y", d
    return "turn", d


class EdgeConstraints:
    """The supports {group: support} of a BlankMesh on the linear carrier V, in edge frames."""

    def __init__(self, V, components, blank, supports: dict[str, str], tol: float = 1e-10):
        self.V, self.bs = V, V.dofmap.index_map_bs
        col = {c: i for i, c in enumerate(components)}
        fixed: set[int] = set()
        directions: dict[tuple[int, str], list[np.ndarray]] = {}
        for group, support in supports.items():
            roles = _ROLES[support]
            if not roles:
                continue
            for block, n in group_vertex_normals(V, blank, group).items():
                s = np.array([-n[1], n[0]])
                for role in roles:
                    base, _, along = role.partition(",")
                    if role == "w" and "w" in col:
                        fixed.add(block * self.bs + col["w"])
                    elif base == "w" and along and "w_x" in col:
                        directions.setdefault((block, "slope"), []).append(n if along == "n" else s)
                    elif base in ("u_n", "u_s") and "u" in col:
                        directions.setdefault((block, "disp"), []).append(n if base == "u_n" else s)
        frames = {}
        for (block, pair), ds in directions.items():
            ix, iy = (block * self.bs + col[c] for c in _PAIRS[pair])
            kind, d = pair_constraint(ds, tol)
            fixed.update({"both": (ix, iy), "x": (ix,), "y": (iy,), "turn": (ix,)}[kind])
            if kind == "turn":  # a_1, the component along d, sits in the x slot
                frames[(ix, iy)] = d
        self.fixed = np.array(sorted(fixed), dtype=np.int32)  # owned local dofs, frame basis
        self.frames = frames
        self.rotation = None

    def _rotation(self, A):
        """R: identity but for the 2 x 2 frame blocks, in A's parallel layout (CSR of the owned rows)."""
        imap = self.V.dofmap.index_map
        start, n = imap.local_range[0] * self.bs, imap.size_local * self.bs
        cols = [[i] for i in range(n)]
        vals = [[1.0] for _ in range(n)]
        for (ix, iy), d in self.frames.items():
            cols[ix], vals[ix] = [ix, iy], [d[0], -d[1]]
            cols[iy], vals[iy] = [ix, iy], [d[1], d[0]]
        indptr = np.concatenate([[0], np.cumsum([len(c) for c in cols])]).astype(PETSc.IntType)
        indices = (start + np.concatenate(cols)).astype(PETSc.IntType)
        R = PETSc.Mat().createAIJ(A.getSizes(), csr=(indptr, indices, np.concatenate(vals)), comm=A.getComm())
        R.assemble()
        return R

    def apply(self, A, b):
        """The frame system R^T A R, R^T b with the fixed rows and columns set to the identity
        (A and b, unconstrained, are replaced)."""
        frames_anywhere = A.getComm().tompi4py().allreduce(len(self.frames)) > 0
        if frames_anywhere:
            self.rotation = self._rotation(A)
            Ar = A.PtAP(self.rotation)
            br = b.duplicate()
            self.rotation.multTranspose(b, br)
            A.destroy(), b.destroy()
            A, b = Ar, br
        rows = (self.V.dofmap.index_map.local_range[0] * self.bs + self.fixed).astype(PETSc.IntType)
        A.zeroRowsColumns(rows, diag=1.0)
        with b.localForm() as local:
            local.array[self.fixed] = 0.0
        return A, b

    def recover(self, q) -> None:
        """q = R q' in place (the carrier back in x, y components)."""
        if self.rotation is None:
            return
        v = q.x.petsc_vec
        out = v.duplicate()
        self.rotation.mult(v, out)
        out.copy(v)
        q.x.scatter_forward()
        out.destroy()


def check_symmetry_lines(blank, supports: dict[str, str], tol: float = 1e-9) -> None:
    """A symmetry support needs a straight edge with the whole blank on one side of it. A line
    along an axis gets its nodes exactly on it (gmsh leaves y = -8e-17 on y = 0; the symmetric
    tools' normals then have components of 1e-18 across the plane)."""
    comm = blank.mesh.comm
    x = blank.mesh.geometry.x
    for group, support in supports.items():
        if support != "symmetry":
            continue
        _, ends, n = facet_normals(blank, blank.facets(group))
        ref = comm.allgather((n[0], ends[0, 0]) if len(n) else None)
        ref = next((r for r in ref if r is not None), None)
        if ref is None:
            continue
        n0, p0 = ref
        bent = len(n) and np.abs(n[:, 0] * n0[1] - n[:, 1] * n0[0]).max() > tol
        off = len(n) and np.abs((ends.reshape(-1, 2) - p0) @ n0).max() > tol * blank.size
        beyond = np.max((x[:, :2] - p0) @ n0, initial=-np.inf) > tol * blank.size
        bad = comm.allreduce(int(bool(bent) or bool(off)) | 2 * int(beyond), op=MPI.BOR)
        if bad & 1:
            raise InputError(f"supports.{group}", "a symmetry line must be straight: this edge is curved or bent")
        if bad & 2:
            raise InputError(f"supports.{group}", "the blank crosses this symmetry line: a symmetric part must "
                             "lie on one side of it")
        axis = int(np.argmax(np.abs(n0)))
        if abs(n0[1 - axis]) <= tol:  # the line x = c or y = c
            c = 0.0 if abs(p0[axis]) <= tol * blank.size else p0[axis]
            nodes = dolfinx.mesh.entities_to_geometry(blank.mesh, 1, blank.facets(group))
            x[nodes.ravel(), axis] = c



class SheetEdgeFrames:
    """Supports on curved and oblique edges of the nonlinear sheet (carrier U = (u, v, w) and its
    gradient), in the edge's frame.

    The carrier's pairs (u, v), (u_x, u_y), (v_x, v_y) and (w_x, w_y) turn as the slope pair of
    the linear route does (module docstring): per vertex, the directions d its edges fix in a pair
    (a . d = 0) fix the whole pair (two non-parallel), one axis component, or, turned as
    (a_x, a_y) = a_1 d + a_2 d_perp (q = Q q'), a_1. w itself is fixed where a support holds it.
    Per support, the directions fixed (n the edge's outward normal, s its tangent):

        clamped            w;  (u, v): n and s;  (w_x, w_y): n and s;  (u_x, u_y), (v_x, v_y): s
        clamped_sliding    w;  (u, v): n;        (w_x, w_y): n and s
        simply_supported   w;  (u, v): s;        (w_x, w_y): s

    Clamped holds u = v = w = 0 along the edge, hence grad w = 0 and the derivatives of u and v
    along it. The sliding and simply supported edges hold u_n and u_s at the vertices only: along
    a curved edge their derivatives along it couple to the other component through the edge's
    curvature (d u_n / ds = n . grad u s - kappa u_s), which no turn of a pair expresses, so the
    edge's displacement between vertices is the element's, converging with the mesh. The
    element arrays are turned before assembly (f' = Q^T f, K' = Q^T K Q on the turned pairs),
    the Newton correction back after the solve; the state stays in x, y components.
    """

    PAIRS = ((0, 1), (3, 4), (5, 6), (7, 8))  # (u, v), (u_x, u_y), (v_x, v_y), (w_x, w_y): COMPONENTS
    W = 2
    ROLES = {  # support -> (fixes w, per pair the directions fixed: "n", "s")
        "clamped": (True, ("ns", "s", "s", "ns")),
        "clamped_sliding": (True, ("n", "", "", "ns")),
        "simply_supported": (True, ("s", "", "", "s")),
    }

    def __init__(self, V, blank, supports: dict[str, str], tol: float = 1e-10):
        bs = V.dofmap.index_map_bs
        nblocks = V.dofmap.index_map.size_local + V.dofmap.index_map.num_ghosts
        npairs = len(self.PAIRS)
        self.Q = np.tile(np.eye(2), (nblocks, npairs, 1, 1))
        self.rotated = np.zeros((nblocks, npairs), dtype=np.bool_)
        fixed: set[int] = set()
        directions: dict[tuple[int, int], list[np.ndarray]] = {}
        for group, support in supports.items():
            holds_w, pairs = self.ROLES[support]
            for block, n in group_vertex_normals(V, blank, group, ghosts=True).items():
                s = np.array([-n[1], n[0]])
                if holds_w:
                    fixed.add(block * bs + self.W)
                for k, dirs in enumerate(pairs):
                    for d in dirs:
                        directions.setdefault((block, k), []).append(n if d == "n" else s)
        for (block, k), ds in directions.items():
            kind, d = pair_constraint(ds, tol)
            ix, iy = self.PAIRS[k]
            if kind == "turn":  # a_1, the component along d, sits in the x slot
                self.rotated[block, k] = True
                self.Q[block, k] = [[d[0], -d[1]], [d[1], d[0]]]
            fixed.update(block * bs + i for i in {"both": (ix, iy), "x": (ix,), "y": (iy,), "turn": (ix,)}[kind])
        self.dofs = np.array(sorted(fixed), dtype=np.int32)  # local, ghosts included, frame basis
        self.bs = bs
        self._slots = np.array([i for i, _ in self.PAIRS], dtype=np.int64)

    def dirichlet(self, V):
        """Homogeneous conditions on the held slots (frame basis), one per component."""
        from dolfinx import fem

        slot = self.dofs % self.bs
        return [fem.dirichletbc(np.float64(0), self.dofs[slot == k], V.sub(k)) for k in range(self.bs)
                if np.any(slot == k)]

    def to_frames(self, array: np.ndarray) -> np.ndarray:
        """q' = Q^T q on the turned pairs (a copy)."""
        return self._turned(array, np.swapaxes(self.Q, 2, 3))

    def from_frames(self, array: np.ndarray) -> np.ndarray:
        """q = Q q' on the turned pairs (a copy)."""
        return self._turned(array, self.Q)

    def _turned(self, array: np.ndarray, M: np.ndarray) -> np.ndarray:
        out = array.copy()
        d = out.reshape(-1, self.bs)
        for k, (i, j) in enumerate(self.PAIRS):
            idx = np.flatnonzero(self.rotated[: d.shape[0], k])
            d[np.ix_(idx, [i, j])] = np.einsum("nab,nb->na", M[idx, k], d[np.ix_(idx, [i, j])])
        return out

    def turn_cell_arrays(self, dofs, vectors, matrices, tangent: bool) -> None:
        """In place: f' = Q^T f, K' = Q^T K Q on the turned blocks' pairs."""
        _turn_pairs(dofs, self.rotated, self.Q, self._slots, vectors, matrices, tangent, self.bs)


@jit.njit
def _turn_pairs(dofs, rotated, Q, slots, vectors, matrices, tangent, bs):
    ncells, nv = dofs.shape
    n = vectors.shape[1]
    for c in range(ncells):
        for a in range(nv):
            b = dofs[c, a]
            for p in range(slots.shape[0]):
                if not rotated[b, p]:
                    continue
                q00, q01, q10, q11 = Q[b, p, 0, 0], Q[b, p, 0, 1], Q[b, p, 1, 0], Q[b, p, 1, 1]
                i, j = bs * a + slots[p], bs * a + slots[p] + 1
                fi, fj = vectors[c, i], vectors[c, j]
                vectors[c, i], vectors[c, j] = q00 * fi + q10 * fj, q01 * fi + q11 * fj
                if not tangent:
                    continue
                for k in range(n):  # rows: Q^T K
                    ki, kj = matrices[c, i, k], matrices[c, j, k]
                    matrices[c, i, k], matrices[c, j, k] = q00 * ki + q10 * kj, q01 * ki + q11 * kj
                for k in range(n):  # columns: K Q
                    ki, kj = matrices[c, k, i], matrices[c, k, j]
                    matrices[c, k, i], matrices[c, k, j] = ki * q00 + kj * q10, ki * q01 + kj * q11
