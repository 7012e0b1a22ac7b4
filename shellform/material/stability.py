"""The stability of a section's membrane: where a material point may neck (diffuse necking).

A sheet necks where its material point can no longer carry more nominal force for more stretch:
the loss of positive definiteness of the tangent of the NOMINAL (first Piola-Kirchhoff)
membrane force with respect to the in-plane deformation gradient. In the measures of the sheet
(total Lagrangian over the flat blank's x, y axes): the mid-surface's in-plane deformation
gradient F (2 x 2), its Green-Lagrange strain E = (F^T F - I)/2 = (E11, E22, 2 E12), the
membrane resultant N = t0 sum_i w_i S_i conjugate to E (S_i the layers' second Piola-Kirchhoff
stresses, t0 the initial thickness, shellform.material.section) and its tangent
A = dN/dE = t0 sum_i w_i dS_i/dE at fixed curvature (the section tangent's membrane block; the
layers' consistent tangents, with finite strains the Hencky map's second-order term included).
The nominal membrane force is P = F N, and with dE = sym(F^T dF)

    dF : dP = dF : (dF N + F dN) = N : (dF^T dF) + dE : A : dE.

A rigid spin of the rate, dF = W F (W skew), adds tr(tau) |w|^2 with tau = F N F^T: negative
wherever the membrane is compressed in the mean, the membrane's own wrinkling, which the
shell's bending stiffness resists and which is no neck. So the spin is left out: on the
spin-free rates F^T dF = dE (dF = F^-T dE, one to one with dE) dF^T dF = dE C^-1 dE,
C = F^T F = I + 2E, and the second-order work is the quadratic form in dE

    w2 = dE : (A + G) : dE,    dE : G : dE = N : (dE C^-1 dE) = tr(N dE C^-1 dE),

G the geometric (stress) term of N. The material point is stable while A + G is positive
definite; its smallest eigenvalue (in Mandel's orthonormal components (dE11, dE22, sqrt 2 dE12),
so that it does not depend on the in-plane axes), divided by t0, is the point's stability in
stress units, and a cell's is the least over its quadrature points.

Uniaxial tension along x (F = diag(lambda, mu), N = diag(N1, 0)): dE11 = lambda dlambda,
dE : G : dE = N1 dE11^2 / lambda^2 = N1 dlambda^2, and with the lateral strain free
(dN2 = 0: the Schur complement over dE22) w2 = dlambda (lambda dN1 + N1 dlambda) =
dlambda dP1, P1 = lambda N1 the nominal force per unit initial width. With the Kirchhoff stress
tau = lambda^2 N1 / t0 and eps = ln lambda, P1 = t0 tau / lambda and

    dP1/dlambda = t0 (d tau/d eps - tau) / lambda^2:

A + G turns singular exactly at Considere's force maximum d tau / d eps = tau (Swift
rigid-plastic: eps = n - eps0; the power law eps/eps_y = (sigma/sigma_y)^N: eps = 1/N). In
shear the block of (dF12, dF21) stays positive definite in tension (its determinant is the
shear tangent times lambda^2 N1 > 0), so there the full tangent dP/dF and its spin-free part
lose definiteness together. With principal stretches along fixed axes the same steps give, in
the logarithmic strain and the Kirchhoff stress, w2 = t0 (d eps : d tau - tau : d eps^2): a
compressive principal stress adds to the stiffness (the compressed flange of a cup is not
reported), a tensile one takes from it.
"""

import math

import numpy as np

from shellform import _jit as jit

ROOT2 = math.sqrt(2.0)


@jit.njit
def smallest_eigenvalue(a00, a01, a02, a11, a12, a22):
    """The smallest eigenvalue of a symmetric 3 x 3 matrix (its upper triangle), in closed form
    (the trigonometric solution of the characteristic cubic, Smith 1961)."""
    q = (a00 + a11 + a22) / 3.0
    off = a01 * a01 + a02 * a02 + a12 * a12
    b00, b11, b22 = a00 - q, a11 - q, a22 - q
    p2 = (b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * off) / 6.0
    if p2 <= 0.0:
        return q
    p = math.sqrt(p2)
    det = b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02) + a02 * (a01 * a12 - b11 * a02)
    r = min(1.0, max(-1.0, det / (2.0 * p2 * p)))
    return q + 2.0 * p * math.cos(math.acos(r) / 3.0 + 2.0 * math.pi / 3.0)


@jit.njit
def membrane_stiffness(E, N, A, M):
    """M (3 x 3) = T (A + G) T, the tangent of the nominal membrane force on spin-free rates in
    Mandel's components m (v = T m, T = diag(1, 1, sqrt 2): v^T (A + G) v = m^T M m), from the
    membrane strain E = (E11, E22, 2 E12), its resultant N = (N11, N22, N12) and tangent A (3 x 3,
    Voigt). With dE = [[a, c], [c, b]] and B = C^-1, tr(N dE B dE) is the quadratic form in
    (a, b, c) of

        H_aa = N11 B11,  H_bb = N22 B22,  H_cc = N11 B22 + N22 B11 + 2 N12 B12,
        H_ab = N12 B12,  H_ac = N11 B12 + N12 B11,  H_bc = N22 B12 + N12 B22,

    and m = (a, b, sqrt 2 c). Returns False where C = I + 2E is not positive definite."""
    c00, c11, c01 = 1.0 + 2.0 * E[0], 1.0 + 2.0 * E[1], E[2]
    det = c00 * c11 - c01 * c01
    if not (c00 > 0.0 and det > 0.0):
        return False
    b11, b22, b12 = c11 / det, c00 / det, -c01 / det  # C^-1
    n11, n22, n12 = N[0], N[1], N[2]
    r = 1.0 / ROOT2
    M[0, 0] = A[0, 0] + n11 * b11
    M[1, 1] = A[1, 1] + n22 * b22
    M[2, 2] = 2.0 * A[2, 2] + 0.5 * (n11 * b22 + n22 * b11 + 2.0 * n12 * b12)
    M[0, 1] = M[1, 0] = 0.5 * (A[0, 1] + A[1, 0]) + n12 * b12
    M[0, 2] = M[2, 0] = ROOT2 * 0.5 * (A[0, 2] + A[2, 0]) + r * (n11 * b12 + n12 * b11)
    M[1, 2] = M[2, 1] = ROOT2 * 0.5 * (A[1, 2] + A[2, 1]) + r * (n22 * b12 + n12 * b22)
    return True


def membrane_stability(strain, resultants, tangents, thickness, out, threads=1):
    """Per cell (out, cells): the least over its quadrature points of the smallest eigenvalue of
    membrane_stiffness over the initial thickness (stress units; <= 0: the material point may
    neck). strain (cells, points, 6), resultants (cells, points, 6) and tangents (cells, points,
    6, 6) of the sections (shellform.nonlinear.model.SheetModel); NaN where a point's C is not
    positive definite. On `threads` threads."""
    jit.over_threads(stability_share, threads, strain, resultants, tangents, thickness, out)


@jit.njit(nogil=True)
def stability_share(counter, strain, resultants, tangents, thickness, out):
    """membrane_stability on the cells, a chunk of them at a time from the threads' shared
    counter (jit.over_threads, jit.next_chunk)."""
    # the views taken below count no references (jit.borrowed)
    strain, resultants, tangents, out = jit.borrowed(strain), jit.borrowed(resultants), jit.borrowed(tangents), \
        jit.borrowed(out)
    M = np.empty((3, 3))  # scratch
    n = strain.shape[0]
    start = jit.next_chunk(counter)
    while start < n:
        for c in range(start, min(start + jit.CHUNK, n)):
            least = math.inf
            for g in range(strain.shape[1]):
                if not membrane_stiffness(strain[c, g, :3], resultants[c, g, :3], tangents[c, g, :3, :3], M):
                    least = math.nan
                    break
                least = min(least, smallest_eigenvalue(M[0, 0], M[0, 1], M[0, 2], M[1, 1], M[1, 2], M[2, 2]))
            out[c] = least / thickness
        start = jit.next_chunk(counter)
