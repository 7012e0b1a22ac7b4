"""The closest-point engine of the tools whose surface is a set of patches (CAD faces:
surface_tool.py; a surface mesh's Nagata patches: mesh_tool.py): remembered points, the warm
start, the search and the signed pass, one flow for both; each tool supplies its patches.

For points x (n, 3), placed by the tool's translation and moved by dz along z, the tool's frame's
points are y = x - translation - dz e_z. A call

    given again   takes a point's remembered answer: the last call's point it is (the same
                  index where the call has as many points as the last, else by the point's
                  coordinates or the nearest remembered point, as the tool's Remembered finds
                  it) at distance 0. Every point given again: the remembered answers, no pass;
    steps         the tool's passes over the other points (the CAD tool: its faces' closed
                  forms, then the warm start; the mesh tool: the warm start), each from what
                  the remembered points hold (their closest points, patches, parameters and
                  lower bounds of the distance to the other patches: the distance is
                  1-Lipschitz, so a point moved by delta keeps them less delta), answering
                  the points whose closest point they prove;
    search        the points no step answered: the candidates that a spatial index of points
                  sampled on the patches gives (Samples), each projected, the nearest taken;
    signed pass   the signed distances d and normals n (and the mesh tool's H) at the closest
                  points of the points not given again;

then remembers the call's points with their answers (Remembered). `counts` counts the points
answered each way, all calls ("repeated", the steps' names, "searched").

What the tool gives from the answers (the Tool protocol, protocol.py):

    gap(x, offset, dz)    d - offset (> 0 clear), n;
    shape(x, offset, dz)  H = dn/dx (n, 3, 3): the tool's _hessian of its answers;
    closest(x, dz)        the closest points placed, d, n (and what the tool adds: _closest_extra).

A tool subclasses ClosestPointTool and supplies: _blank(npts) (the per-point arrays of a call:
Points), _steps() ((name, step) pairs), _search(y, rows, points), _signed(y, rows, points),
_hessian(points), and optionally _repeat (what a point given again copies beyond its arrays),
_evaluating() (a context around the passes: the CAD tool's gmsh model made current) and
_placed(c, dz).
"""

from contextlib import nullcontext

import numpy as np

NORMALS = ("outward", "inward")


def point_keys(y):
    """Each point's coordinates as one opaque key (its bytes: equal exactly where the point is)."""
    return np.ascontiguousarray(y).view(np.dtype((np.void, y.dtype.itemsize * 3))).ravel()


class Points:
    """A call's per-point arrays by name (each with the points along its first axis), and the
    tool's other state of the call (not per point: `extras`, copied by the tool's own hooks)."""

    def __init__(self, extras=(), **arrays):
        self.names = tuple(arrays)
        self.extras = tuple(extras)
        for name, value in arrays.items():
            setattr(self, name, value)

    def take(self, rows) -> "Points":
        """The arrays at `rows` (copies), as a Points of their own."""
        return Points(**{name: getattr(self, name)[rows] for name in self.names})

    def put(self, rows, other: "Points", ref) -> None:
        """Rows `rows` of every array set to other's at `ref`."""
        for name in self.names:
            getattr(self, name)[rows] = getattr(other, name)[ref]


class Remembered:
    """A call's points y (tool frame) and their answers (Points), and how a later call's points
    find their remembered point (references): row by row where the call has as many points as
    the remembered ones (and, with a `margin`, each lies within it of its own: a contact set's
    nodes, moved by an iterate), else (`by_bytes`) a point given again by its coordinates' bytes
    and the others by the nearest remembered point (a k-d tree), or every point by the nearest."""

    def __init__(self, y, points: Points, margin=None, by_bytes: bool = False):
        self.y, self.points, self.margin, self.by_bytes = y, points, margin, by_bytes
        self.tree = self.order = None

    def _tree(self):
        if self.tree is None:
            from scipy.spatial import cKDTree

            self.tree = cKDTree(self.y)
        return self.tree

    def references(self, y):
        """Each point's remembered point (its index) and the distance to it: 0 exactly where the
        point is given again."""
        if len(y) == len(self.y):
            r = y - self.y
            delta = np.sqrt(np.einsum("pi,pi->p", r, r))
            if self.margin is None or delta.max() <= self.margin:
                return np.arange(len(y)), delta
        if not self.by_bytes:
            delta, ref = self._tree().query(y)
            return ref, delta
        if self.order is None:
            self.keys = point_keys(self.y)
            self.order = np.argsort(self.keys)
        keys = point_keys(y)
        at = np.minimum(np.searchsorted(self.keys, keys, sorter=self.order), len(self.y) - 1)
        ref = self.order[at]
        delta = np.where(self.keys[ref] == keys, 0.0, np.inf)
        moved = np.flatnonzero(delta > 0.0)
        if moved.size:
            delta[moved], ref[moved] = self._tree().query(y[moved])
        return ref, delta


class Samples:
    """Points sampled on a tool's patches, each with its patch (`owner`) and its parameters
    (`params`), in a k-d tree: the spatial index of the search's candidates."""

    def __init__(self, points, owner, params=None):
        from scipy.spatial import cKDTree

        self.tree = cKDTree(points)
        self.owner, self.params = owner, params
        self.n = self.tree.n

    def query(self, y, k=1):
        return self.tree.query(y, k=k)

    def ball(self, y, radius):
        return self.tree.query_ball_point(y, radius, return_sorted=True)


class ClosestPointTool:
    """The flow of a call (module docstring); a tool subclasses it and supplies its patches'
    passes. `sign` turns the patches' normals ("inward"), `translation` places the tool."""

    axis = np.array([0.0, 0.0, 1.0])  # its travel dz is along z (placement.py turns and moves it)
    COUNTS = ("repeated", "searched")  # the counts' names, the steps' among them
    _margin = None  # Remembered's margin (None: row by row whenever the counts agree)
    BY_BYTES = False  # Remembered's way for other calls

    def __init__(self, translation=(0.0, 0.0, 0.0), normals: str = "outward"):
        if normals not in NORMALS:
            raise ValueError(f"normals must be one of {NORMALS}, got {normals!r}")
        self.sign = 1.0 if normals == "outward" else -1.0
        self.translation = np.asarray(translation, dtype=float).reshape(3)
        self._last = None  # the last call's points and their answers (Remembered)
        self.counts = {name: 0 for name in self.COUNTS}  # points answered each way, all calls

    # -- what the tool gives -----------------------------------------------------------------
    def gap(self, x, offset=0.0, dz: float = 0.0):
        """Signed distance minus offset (> 0 clear) and unit normal from the tool towards x."""
        p, _ = self._answers(x, dz)
        return p.d - np.broadcast_to(np.asarray(offset, dtype=float), p.d.shape), p.n + 0.0

    def shape(self, x, offset=0.0, dz: float = 0.0):
        """H = dn/dx (n, 3, 3) (the tool's module docstring)."""
        p, _ = self._answers(x, dz)
        return self._hessian(p) + 0.0

    def closest(self, x, dz: float = 0.0):
        """For points x (n, 3): the closest surface points (placed), the signed distances and
        the normals (and what the tool adds: _closest_extra)."""
        p, shift = self._answers(x, dz)
        return (self._placed(p.c, shift, dz), p.d.copy(), p.n.copy()) + self._closest_extra(p)

    def _placed(self, c, shift, dz):
        return c + shift

    def _closest_extra(self, p) -> tuple:
        return ()

    # -- the flow ----------------------------------------------------------------------------
    def _answers(self, x, dz):
        """The call's Points (c, d, n and the tool's arrays, tool frame) and the shift y = x -
        shift (module docstring)."""
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        shift = self.translation + np.array([0.0, 0.0, dz])
        y = x - shift
        npts = len(y)
        last = self._last if npts else None
        ref = delta = None
        if last is not None:
            ref, delta = last.references(y)
            if not delta.any():  # every point given again: the remembered points stay
                self.counts["repeated"] += npts
                return last.points.take(ref), shift
        points = self._blank(npts)
        todo = np.ones(npts, dtype=bool)
        if last is not None:
            same = np.flatnonzero(delta == 0.0)
            self._repeat(points, same, last, ref[same])
            todo[same] = False
            self.counts["repeated"] += same.size
        new = np.flatnonzero(todo)
        with self._evaluating():
            for name, step in self._steps():
                rows = step(y, todo, last, ref, delta, points)
                todo[rows] = False
                self.counts[name] += rows.size
            rest = np.flatnonzero(todo)
            self.counts["searched"] += rest.size
            if rest.size:
                self._search(y, rest, points)
            self._signed(y, new, points)
        if npts:
            self._last = Remembered(y, points, self._margin, self.BY_BYTES)
        return points, shift

    def _repeat(self, points, rows, last, ref):
        """Points `rows` given again: their remembered arrays (and the tool's state of them)."""
        points.put(rows, last.points, ref)

    def _evaluating(self):
        return nullcontext()

    # -- the tool's ---------------------------------------------------------------------------
    def _blank(self, npts) -> Points:
        raise NotImplementedError

    def _steps(self) -> tuple:
        return ()

    def _search(self, y, rows, points) -> None:
        raise NotImplementedError

    def _signed(self, y, rows, points) -> None:
        raise NotImplementedError

    def _hessian(self, points):
        raise NotImplementedError
