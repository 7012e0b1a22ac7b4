"""The nonlinear sheet element: reference elements, carrier layout and the per-cell map Q.

Carrier (blocked P1, 9 values per vertex, all physical):

    (u, v, w, u_x, u_y, v_x, v_y, w_x, w_y)      U = (u, v, w), its gradient

Every displacement component has the C1-type interpolation of the quasi-conforming triangle
(shellform.elements.reduced_cubic), as the exact large-rotation kinematics need
(docs/large-rotation.md).

Two reference elements:
- ``hessian``: one component's weak Hessian, the bending-only hybrid element of issue 2
  (w reduced cubic, g P1 slopes, H and its multiplier Psi linear symmetric). Its constraint
  gives H = P q_c with a per-cell 9 x 9 matrix P (q_c: the component's 9 carrier values).
- ``energy``: U (the reduced cubic, blocked over 3 components) and H_1, H_2, H_3: the fields
  in which forms.kirchhoff_love writes the strains.

Per cell the energy element's coefficients are z = Q q (q: the cell's 27 carrier values),

    rows of U: the vertex values and reference slopes J^T grad U_i,
    rows of H_i: P q_i,

so the element force and tangent are r = Q^T r_z and K = Q^T K_z Q.
"""

from functools import cached_property

import basix
import basix.ufl
import numpy as np

from shellform.assembly.hybrid_element import HybridElement
from shellform.assembly import slope_map
from shellform.elements import reduced_cubic
from shellform import _jit as jit

COMPONENTS = ("u", "v", "w", "u_x", "u_y", "v_x", "v_y", "w_x", "w_y")
BS = len(COMPONENTS)
NDOF = 3 * BS  # carrier values of one cell


def slope_column(i: int, j: int) -> int:
    """Carrier component of dU_i/dx_j."""
    return 3 + 2 * i + j


class SheetElement:
    """Reference elements and index tables of the nonlinear sheet triangle."""

    def __init__(self, quadrature_degree: int = 4):
        self.quadrature_degree = quadrature_degree
        cubic = reduced_cubic.element()
        sym = basix.ufl.element("DG", "triangle", 1, shape=(2, 2), symmetry=True)
        self.U = basix.ufl.blocked_element(cubic, shape=(3,))
        self.energy = basix.ufl.mixed_element([self.U, sym, sym, sym])
        self.hessian = HybridElement(("bending",))
        self.sym_dim = sym.dim  # 9
        self.nz = self.energy.dim  # 27 + 3 * 9
        points, weights = basix.make_quadrature(basix.CellType.triangle, quadrature_degree)
        self.points, self.weights = points, weights
        self.nqp = points.shape[0]

    @cached_property
    def hessian_tables(self):
        """(cols, codes) of the component map carrier (w, w_x, w_y) -> hessian q (slope_map)."""
        return self.hessian.slope_map_tables()

    def q_map(self):
        """Index tables of Q's U rows: for energy row 3 j + c (cubic dof j = 3 v + k, comp c)
        up to two (carrier column, J-code) pairs, codes as in slope_map (1: one, 2+2a+b: J[a,b])."""
        cols = -np.ones((27, 2), dtype=np.int32)
        codes = np.zeros((27, 2), dtype=np.int32)
        for v in range(3):
            for c in range(3):
                slope_map.cubic_vertex_rows(cols, codes, [3 * (3 * v + k) + c for k in range(3)], BS * v + c,
                                            [BS * v + slope_column(c, j) for j in range(2)])
        return cols, codes

    @staticmethod
    def component_columns() -> np.ndarray:
        """(3, 9): carrier columns of component i in the hessian element's carrier order
        (per vertex: value, d/dx, d/dy)."""
        out = np.empty((3, 9), dtype=np.int32)
        for i in range(3):
            for v in range(3):
                out[i, 3 * v] = BS * v + i
                out[i, 3 * v + 1] = BS * v + slope_column(i, 0)
                out[i, 3 * v + 2] = BS * v + slope_column(i, 1)
        return out


@jit.njit
def build_q(J, P, cols, codes, comp_cols, Q):
    """Fill the dense (nz x 27) map Q of one cell (see the module docstring)."""
    Q[:, :] = 0.0
    for r in range(cols.shape[0]):
        for k in range(2):
            c = codes[r, k]
            if c == 1:
                Q[r, cols[r, k]] += 1.0
            elif c >= 2:
                a, b = (c - 2) // 2, (c - 2) % 2
                Q[r, cols[r, k]] += J[a, b]
    nh = P.shape[0]
    for i in range(3):
        for h in range(nh):
            for m in range(9):
                Q[27 + nh * i + h, comp_cols[i, m]] = P[h, m]


@jit.njit
def congruence(Kz, J, P, cols, codes, comp_cols, QtK, KQ, K):
    """K = Q^T Kz Q (27 x 27) without forming Q, from its structure: the rows of U hold at most
    two entries each (1 or an entry of J), the rows of H_i the 9 x 9 block P at the component's
    columns. Both products are row updates X[col, :] += v Y[r, :] over Q's nonzeros (r, col, v):
    Q^T Kz, then Q^T (Q^T Kz)^T = (Q^T Kz Q)^T. Scratch: QtK (27 x nz), KQ (nz x 27)."""
    nz = Kz.shape[0]
    _rows_of_qt(Kz, J, P, cols, codes, comp_cols, QtK)
    for a in range(NDOF):
        for j in range(nz):
            KQ[j, a] = QtK[a, j]
    _rows_of_qt(KQ, J, P, cols, codes, comp_cols, K)  # K^T
    for a in range(NDOF):
        for b in range(a):
            K[a, b], K[b, a] = K[b, a], K[a, b]


@jit.njit
def _rows_of_qt(Y, J, P, cols, codes, comp_cols, X):
    """X = Q^T Y, row by row: X[col, :] += v Y[r, :] for every nonzero Q[r, col] = v."""
    nu, nh, n = cols.shape[0], P.shape[0], Y.shape[1]
    X[:, :] = 0.0
    for r in range(nu):
        for k in range(2):
            c = codes[r, k]
            if c >= 1:
                v = 1.0 if c == 1 else J[(c - 2) // 2, (c - 2) % 2]
                col = cols[r, k]
                for j in range(n):
                    X[col, j] += v * Y[r, j]
    for i in range(3):
        for h in range(nh):
            r = nu + nh * i + h
            for m in range(9):
                v, col = P[h, m], comp_cols[i, m]
                for j in range(n):
                    X[col, j] += v * Y[r, j]
