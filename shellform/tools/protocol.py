"""What every rigid tool gives (the Tool protocol), what the binder face gives beyond it, and a
surface of any tool for pictures and ParaView.

A tool is a rigid surface that travels along a unit axis. At points x (n, 3) of the scene, with
the tool moved by dz along its axis,

    gap(x, offset, dz) -> (g, n)   g = d(x) - offset, d the signed distance to the surface (> 0
                                   on the sheet's side), n = grad d the unit normal (n, 3): the
                                   direction in which the tool pushes the sheet;
    shape(x, offset, dz) -> H      H = dn/dx = the Hessian of d (n, 3, 3), symmetric, H n = 0,
                                   its eigenvalues the principal curvatures of d's level surface
                                   through x (> 0 convex seen from the sheet);
    axis                           the unit vector of its travel (the punch moves by -stroke
                                   along it).

The offset is half the sheet's thickness at a node: the sheet's surface lies that far from its
mid-surface. The binder face (the blank holder's, shellform.tools.analytic.BlankHolder) is a
tool that also gives its inner edge in plan, where the die's flat top begins:

    edge            distance(x, y), offset(x, y), reach(), length() (holder_edge.py)
    at_gap(gap, t)  the same face held `gap` over the die's (tools.holder = "gap"; the
                    channel's curved binder gives only this: channel.ChannelHolder)
    z_face          the height of its face
    edge_offset(x)  (s, j): the plan distance from the edge and the edge's length per unit
                    length of the offset line (holder_edge.py)

A kind of tools (shellform.tools.kinds) makes the three of a cup, {"punch", "die", "holder"},
from a scene's [tools].
"""

from typing import NamedTuple, Protocol, runtime_checkable

import numpy as np

from shellform.tools.analytic import rounded_square_sdf
from shellform.tools.travel import Capped, Linear


@runtime_checkable
class Tool(Protocol):
    axis: np.ndarray

    def gap(self, x, offset=0.0, dz: float = 0.0) -> tuple[np.ndarray, np.ndarray]: ...

    def shape(self, x, offset=0.0, dz: float = 0.0) -> np.ndarray: ...


@runtime_checkable
class Binder(Tool, Protocol):
    edge: object
    z_face: float

    def edge_offset(self, x) -> tuple[np.ndarray, np.ndarray]: ...

    def at_gap(self, gap: float, thickness: float) -> Tool: ...


def surface_mesh(tool, dz: float, bounds, z_range, above: bool, n: int = 96):
    """A triangulated surface of `tool` moved by dz along its axis, over the plan rectangle
    bounds = (x0, x1, y0, y1), for pictures and ParaView: (points (k, 3), triangles (m, 3)).

    Each point of an n x n plan grid takes the height where the tool's signed distance
    ``gap(x, 0, dz)`` is zero, found by bisection on z in z_range = (z_lo, z_hi): the sheet's
    side of a tool above it (above: punch, holder) is its lowest point, of a tool below it (die)
    its highest; the gap is monotone in z along such a vertical line. Where no point of the line
    lies on the tool (beside the punch's wall, over the die's opening) the height is the end of
    the range away from the sheet (z_hi above, z_lo below), so that the walls show as steep
    triangles one grid cell wide. Where the gap is infinite (the holder over the die's opening)
    the tool has no face: those triangles and their points are left out.
    """
    x0, x1, y0, y1 = bounds
    X, Y = np.meshgrid(np.linspace(x0, x1, n), np.linspace(y0, y1, n), indexing="xy")
    xy = np.column_stack([X.ravel(), Y.ravel()])
    z_lo, z_hi = map(float, z_range)

    def gap_at(z):
        return tool.gap(np.column_stack([xy, z]), 0.0, dz)[0]

    lo, hi = np.full(len(xy), z_lo), np.full(len(xy), z_hi)
    g_lo, g_hi = gap_at(lo), gap_at(hi)
    face = np.isfinite(g_lo) & np.isfinite(g_hi)
    crosses = face & ((g_lo > 0) != (g_hi > 0))
    for _ in range(48):  # the range / 2^48: below any tolerance of the sheet
        mid = 0.5 * (lo + hi)
        clear = gap_at(mid) > 0
        lo_side = clear if above else ~clear  # mid lies on z_lo's side of the surface
        lo = np.where(lo_side, mid, lo)
        hi = np.where(lo_side, hi, mid)
    z = np.where(crosses, 0.5 * (lo + hi), z_hi if above else z_lo)
    points = np.column_stack([xy, z])
    k = np.arange(n * n).reshape(n, n)
    a, b, c, d = k[:-1, :-1].ravel(), k[:-1, 1:].ravel(), k[1:, :-1].ravel(), k[1:, 1:].ravel()
    triangles = np.concatenate([np.column_stack([a, b, d]), np.column_stack([a, d, c])])
    triangles = triangles[face[triangles].all(axis=1)]
    used, triangles = np.unique(triangles, return_inverse=True)  # the points of the kept triangles only
    return points[used], triangles.reshape(-1, 3)


class BinderPlan(NamedTuple):
    """Where the die's flat top (and the holder's face) begins, as a scene gives it: the rounded
    square of half-width `half_width` and plan corner radius `corner_radius`, or across x only
    (`across` ("x",): the lines |x| = half_width of a channel running along y), and the keys that
    give it (named in the scene's messages: the blank must reach beyond it, drawbeads lie outside
    it)."""

    half_width: float
    corner_radius: float
    keys: str
    across: tuple = ("x", "y")

    def distance(self, x, y) -> np.ndarray:
        """The plan distance of points (x, y) from where the flat top begins (> 0 on it)."""
        if "y" not in self.across:
            return np.abs(np.asarray(x, dtype=float)) - self.half_width
        return rounded_square_sdf(x, y, self.half_width, self.corner_radius)[0]


def ram_travel(spec) -> dict:
    """The tools' paths (travel.py): the punch travels the stroke down its axis, the die stays,
    and the holder's face stays, or (binder_rise > 0: a curved binder's holder that starts
    raised) comes down with the punch by binder_rise and stops there (Capped)."""
    rise = spec.binder_rise
    holder = Capped(-spec.stroke, -rise) if rise > 0 else Linear(0.0)
    return {"punch": Linear(-spec.stroke), "die": Linear(0.0), "holder": holder}
