"""The element-boundary terms: Green's theorem and the string-net interpolation, paper eq. (7).

For linear moments M (so div div M = 0), Green's theorem on the triangle K gives

    int_K M : (-grad grad w) dA = - oint (M n) . grad w ds + oint (div M . n) w ds.

Only the traces of w and grad w on the edges remain. pi_b replaces them by the inter-element
("string-net") interpolations built from the vertex values alone:

    w   -> w~      cubic Hermite in the end values of w and dw/ds (the trace of the reduced cubic)
    w,s -> dw~/ds
    w,n -> w~,n    linear between the end values of the normal slope (g . n, g the P1 nodal slopes)

so that the two elements sharing an edge see the same values and pi_b, eq. (11), holds
identically. What is left is the integral below: pi_a's boundary part minus pi_b.
"""

import ufl


def string_net_gradient(w, g, n):
    """grad w on an edge, built from the string-net traces: n w~,n + t dw~/ds."""
    t = ufl.as_vector([-n[1], n[0]])
    return n * ufl.dot(g, n) + t * ufl.dot(ufl.grad(w), t)


def bending_boundary(M, w, g, n):
    """oint_dK [ -(M n) . grad w~ + (div M . n) w~ ] ds, the Hessian part of int M : f^b."""
    return (-ufl.dot(ufl.dot(M, n), string_net_gradient(w, g, n)) + ufl.dot(ufl.div(M), n) * w) * ufl.ds
