"""Limit and tangent masks as pure functions of a vertex's neighbourhood numbers.

The companion of ``_rules`` for the limit surface: nothing here knows a mesh. Every mask is
the dominant (or a sub-dominant) left eigenvector of the local subdivision matrix built from
the weights in ``_rules``, so that it agrees with the project's refinement exactly;
``tests/test_limit.py`` checks each one against a numerical eigenvector.

Ring conventions: an interior (smooth) vertex ``v`` has neighbours ``p_0 … p_{n−1}`` in
counter-clockwise order (faces ``(v, p_j, p_{j+1})``). A *sector* of ``k`` faces between two
crease edges (or boundary edges) has the ring ``q_0 … q_k``, ``q_0`` and ``q_k`` the ends of
the two crease edges, faces ``(v, q_j, q_{j+1})``.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from . import step_rules as R

#: Limit mask of a crease vertex (self, each crease neighbour): the cubic B-spline at a knot.
CREASE_LIMIT_MASK = (2.0 / 3.0, 1.0 / 6.0)


# --------------------------------------------------------------------------------------------
# Limit positions
# --------------------------------------------------------------------------------------------


def kobbelt_limit_beta(n):
    """Weight β_n of the neighbour average in Kobbelt's √3 limit mask.

    ``p∞ = (1 − β_n) p + β_n / n Σ p_i`` with ``β_n = 3 α_n / (1 + 3 α_n)``.

    Examples
    --------
    >>> float(kobbelt_limit_beta(6))
    0.5
    """
    a = R.kobbelt_alpha(n)
    return 3.0 * a / (1.0 + 3.0 * a)


def loop_limit_chi(n, loop_weights="loop"):
    """Per-neighbour weight χ_n of Loop's limit mask: ``p∞ = (1 − n χ) p + χ Σ p_i``.

    ``χ_n = 1 / (n + 3 / (8 β_n))`` with the vertex weight β_n of ``loop_weights``.

    Examples
    --------
    >>> float(loop_limit_chi(6))
    0.08333333333333333
    """
    n = np.asarray(n, dtype=np.float64)
    b = R.loop_beta(n, loop_weights)
    return 1.0 / (n + 3.0 / (8.0 * b))


def smooth_limit_weight(n, region, loop_weights="loop"):
    """Per-neighbour weight of the limit mask of a smooth vertex, by region.

    ``REGION_SQRT3``: β_n / n (Kobbelt), ``REGION_LOOP``: χ_n. Mixed vertices have no
    stationary mask: NaN there. 0 where n = 0.

    Examples
    --------
    >>> smooth_limit_weight([6, 6], [R.REGION_SQRT3, R.REGION_LOOP]).round(6).tolist()
    [0.083333, 0.083333]
    """
    n = np.asarray(n, dtype=np.int64)
    region = np.asarray(region)
    safe = np.maximum(n, 1)
    w = np.where(region == R.REGION_SQRT3, kobbelt_limit_beta(safe) / safe,
                 np.where(region == R.REGION_LOOP, loop_limit_chi(safe, loop_weights), np.nan))
    return np.where(n > 0, w, 0.0)


# --------------------------------------------------------------------------------------------
# Tangents
# --------------------------------------------------------------------------------------------


def smooth_tangent_weights(n, j):
    """Weights of ring neighbour ``p_j`` in the two tangent masks of a smooth vertex.

    ``t1 = Σ cos(2πj/n) p_j``, ``t2 = Σ sin(2πj/n) p_j`` (Loop's and Kobbelt's tangent masks:
    the left eigenvectors of the sub-dominant eigenvalue pair; the centre's weight is 0).
    ``t1 × t2`` points to the side the faces ``(v, p_j, p_{j+1})`` face.
    """
    t = 2.0 * np.pi * np.asarray(j, dtype=np.float64) / np.asarray(n, dtype=np.float64)
    return np.cos(t), np.sin(t)


# The local matrix of one sector with k faces (ring q_0 … q_k): the crease vertex and the two
# crease neighbours follow a curve rule, the interior ring points a rule with weights
# (centre, q_{j−1}, q_j, q_{j+1}). Per scheme: (centre row: self, each end), (end row: centre,
# own end, other end), (interior row: centre, side, middle), and whether it is two steps.
_SECTOR_RULES = {
    # Loop with Hoppe's crease rule, one step.
    "loop": ((3.0 / 4.0, 1.0 / 8.0), (1.0 / 2.0, 1.0 / 2.0, 0.0), (3.0 / 8.0, 1.0 / 8.0, 3.0 / 8.0)),
    # Kobbelt's √3 boundary, two steps (odd then even): the boundary is trisected once.
    "sqrt3": ((19.0 / 27.0, 4.0 / 27.0), (16.0 / 27.0, 10.0 / 27.0, 1.0 / 27.0),
              (5.0 / 9.0, 1.0 / 9.0, 2.0 / 9.0)),
}


def sector_matrix(k, scheme="loop"):
    """Local subdivision matrix of a crease (``"loop"``) or Kobbelt boundary (``"sqrt3"``,
    two steps) sector with ``k`` faces, order ``[v, q_0, …, q_k]``, shape (k + 2, k + 2).

    Examples
    --------
    >>> sector_matrix(1)
    array([[0.75 , 0.125, 0.125],
           [0.5  , 0.5  , 0.   ],
           [0.5  , 0.   , 0.5  ]])
    """
    k = int(k)
    if k < 1:
        raise ValueError(f"a sector has at least one face, got k={k}")
    (cv, ce), (ec, eo, ex), (ic, i1, i0) = _SECTOR_RULES[scheme]
    M = np.zeros((k + 2, k + 2))
    M[0, 0] = cv
    M[0, 1] = M[0, k + 1] = ce
    M[1, 0] = M[k + 1, 0] = ec
    M[1, 1] = M[k + 1, k + 1] = eo
    M[1, k + 1] += ex
    M[k + 1, 1] += ex
    for j in range(1, k):
        M[1 + j, 0] = ic
        M[1 + j, 1 + j] = i0
        M[1 + j, j] = i1
        M[1 + j, 2 + j] = i1
    return M


def sector_across_eigenvalue(k, scheme="loop"):
    """Eigenvalue of the across-tangent mode of a sector with ``k`` faces.

    ``"loop"``: ``3/8 + 1/4 cos(π/k)`` (k ≥ 2), 1/4 for k = 1; ``"sqrt3"`` (two steps):
    ``(2 + 2 cos(π/k)) / 9``, 1/9 for k = 1.
    """
    k = np.asarray(k, dtype=np.float64)
    (_, _), (_, _, _), (_, i1, i0) = _SECTOR_RULES[scheme]
    second = 0.25 if scheme == "loop" else 1.0 / 9.0
    c = np.cos(np.pi / np.maximum(k, 1.0))
    return np.where(k >= 2, i0 + 2.0 * i1 * c, second)


def sector_across_weights(k, scheme="loop"):
    """Across-tangent mask of a sector with ``k`` faces: weights of ``v``, of each end
    ``q_0``, ``q_k``, and the interior factor.

    Returns ``(a, b)``: the mask is ``a v + b (q_0 + q_k) + Σ_{j=1}^{k−1} sin(πj/k) q_j``, the
    left eigenvector of :func:`sector_matrix` for :func:`sector_across_eigenvalue` that is
    symmetric in the two ends. For ``k = 1`` it is ``q_0 + q_1 − 2 v``. It points from ``v``
    into the sector; with the crease tangent ``q_0 − q_k``, ``(q_0 − q_k) × across`` is the
    sector's normal on the side its faces face.
    """
    k = np.atleast_1d(np.asarray(k, dtype=np.int64))
    (cv, ce), (ec, eo, ex), (ic, i1, _) = _SECTOR_RULES[scheme]
    lam = sector_across_eigenvalue(k, scheme)
    kf = k.astype(np.float64)
    j_sum = np.where(k >= 2, 1.0 / np.tan(np.pi / (2.0 * np.maximum(kf, 1.0))), 0.0)  # Σ sin(πj/k)
    s1 = np.where(k >= 2, np.sin(np.pi / np.maximum(kf, 1.0)), 0.0)  # weight of q_1 (and q_{k−1})
    # Column v:   a cv + 2 b ec + ic Σ sin = λ a
    # Column q_0: a ce + b (eo + ex) + i1 sin(π/k) = λ b
    A11, A12, r1 = cv - lam, 2.0 * ec, -ic * j_sum
    A21, A22, r2 = ce, eo + ex - lam, -i1 * s1
    det = A11 * A22 - A12 * A21
    det = np.where(k == 1, 1.0, det)  # k = 1: λ = the curve's own eigenvalue, set below
    a = (r1 * A22 - A12 * r2) / det
    b = (A11 * r2 - A21 * r1) / det
    one = k == 1
    a = np.where(one, -2.0, a)
    b = np.where(one, 1.0, b)
    return a, b


# --------------------------------------------------------------------------------------------
# Darts in Loop regions: no closed form, a small eigenproblem per valence
# --------------------------------------------------------------------------------------------


def dart_matrix(n, loop_weights="loop"):
    """Local (n + 1)-square Loop matrix of a dart of valence n, crease edge to ``p_0``."""
    n = int(n)
    b = float(R.loop_beta(n, loop_weights))
    M = np.zeros((n + 1, n + 1))
    M[0, 0] = 1.0 - n * b
    M[0, 1:] = b
    M[1, 0] = M[1, 1] = 0.5
    for j in range(1, n):
        M[1 + j, 0] = 3.0 / 8.0
        M[1 + j, 1 + j] += 3.0 / 8.0
        M[1 + j, 1 + (j - 1) % n] += 1.0 / 8.0
        M[1 + j, 1 + (j + 1) % n] += 1.0 / 8.0
    return M


@lru_cache(maxsize=256)
def _dart_masks(n, loop_weights):
    M = dart_matrix(n, loop_weights)
    w, L = np.linalg.eig(M.T)
    w, L = w.real, L.real
    limit = L[:, int(np.argmin(np.abs(w - 1.0)))]
    limit = limit / limit.sum()
    # The reflection j -> -j fixes the crease; the tangents are its best symmetric and
    # antisymmetric eigenvectors (a degenerate pair, as at n = 6, is split by projection).
    perm = np.r_[0, 1 + (-np.arange(n)) % n]
    best = {}
    for i in np.argsort(-w):
        if abs(w[i] - 1.0) < 1e-9:
            continue
        for sign in (1.0, -1.0):
            part = 0.5 * (L[:, i] + sign * L[perm, i])
            if np.linalg.norm(part) > 1e-6 and sign not in best:
                best[sign] = part / np.linalg.norm(part)
    ts, ta = best[1.0], best[-1.0]
    # Orient: on the planar regular ring, t_sym × t_anti must point up (+z).
    ang = 2.0 * np.pi * np.arange(n) / n
    P = np.c_[np.r_[0.0, np.cos(ang)], np.r_[0.0, np.sin(ang)]]
    a, c = ts @ P, ta @ P
    if a[0] * c[1] - a[1] * c[0] < 0:
        ta = -ta
    for arr in (limit, ts, ta):
        arr.setflags(write=False)
    return limit, ts, ta


def dart_masks(n, loop_weights="loop"):
    """Limit mask and two tangent masks of a dart (one crease edge) in a Loop region.

    Returns three (n + 1,) arrays over ``[v, p_0, …, p_{n−1}]`` (``p_0`` the crease
    neighbour): the limit mask (the left eigenvector of eigenvalue 1 of
    :func:`dart_matrix`), and the best symmetric and antisymmetric sub-dominant left
    eigenvectors, oriented so that ``t_sym × t_anti`` points to the side the faces face.

    Examples
    --------
    >>> lim, ts, ta = dart_masks(6)
    >>> round(float(lim.sum()), 12), lim.shape
    (1.0, (7,))
    """
    return _dart_masks(int(n), str(loop_weights))


# --------------------------------------------------------------------------------------------
# Crease sectors in √3 regions of the hybrid scheme: valence grows, no tangent plane
# --------------------------------------------------------------------------------------------


@lru_cache(maxsize=1024)
def _sqrt3_sector_coeffs(k, terms=400):
    m = np.arange(terms, dtype=np.float64)
    g = 1.5 ** (m + 1.0)
    u = 0.25 ** m  # u_m / u_0: (e_0 + e_N) decays by 1/4 per step under the crease rule
    w = 0.5 ** m  # w_m / w_0: (e_0 − e_N) decays by 1/2
    N = k + m
    s = u / 8.0  # the crease vertex moves by s_m = u_m / 8
    # C_m(1) = (e_0 + e_N)/6 − s_m (N + 2); e_N = (u − w)/2
    c_u = u / 6.0 - s * (N + 2.0)
    # C'_m(1) = e_N (N + 1)/6 − s_m (N + 1)(N + 2)/2
    d_u = 0.5 * u * (N + 1.0) / 6.0 - s * (N + 1.0) * (N + 2.0) / 2.0
    d_w = -0.5 * w * (N + 1.0) / 6.0
    t1_u = float(np.sum(g * c_u))
    t2_u = float(np.sum(g * (d_u - (m + 1.0) / 2.0 * c_u)))
    t2_w = float(np.sum(g * d_w))
    return t1_u, t2_u, t2_w


def sqrt3_crease_sector_masks(k):
    """Two tangent-like masks of a crease sector of ``k`` smooth (√3) faces, hybrid scheme.

    At a crease vertex next to √3 faces the valence grows by one per step and the limit
    surface has no tangent plane (see ``docs/limit.md``). The normal of the refined control
    fan still converges, to ``T1 × T2`` with the two masks returned here, over
    ``[v, q_0, …, q_k]``, each of shape (k + 2,). Derivation: the ring offsets
    ``e_j = q_j − v`` evolve as ``e'_j = (e_{j−1} + e_j)/3 − s`` with crease ends
    ``e'_0 = e_0/2 − s``, ``s = (e_0 + e_k)/8``; with ``E_m(z) = Σ e_j z^j``,
    ``G_m = (3/(1+z))^m E_m`` converges, and ``G_∞(1) × G_∞'(1)`` is the limit direction of
    ``E_m(1) × E_m'(1)``, hence of the fan normal. ``T1 = G_∞(1)``, ``T2 = G_∞'(1)``.
    """
    k = int(k)
    t1_u, t2_u, t2_w = _sqrt3_sector_coeffs(k)
    j = np.arange(k + 1, dtype=np.float64)
    # E_0(1) = Σ q_j − (k+1) v ; E_0'(1) = Σ j q_j − k(k+1)/2 v ; u_0 = q_0 + q_k − 2v ; w_0 = q_0 − q_k
    T1 = np.r_[-(k + 1.0), np.ones(k + 1)]
    T2 = np.r_[-k * (k + 1.0) / 2.0, j]
    T1[0] -= 2.0 * t1_u
    T1[1] += t1_u
    T1[k + 1] += t1_u
    T2[0] -= 2.0 * t2_u
    T2[1] += t2_u + t2_w
    T2[k + 1] += t2_u - t2_w
    return T1, T2
