"""The scheme's rules as pure functions of a vertex's neighbourhood numbers.

Nothing here knows a mesh: every function takes valences, region codes or sharpness
values (scalars or arrays) and returns weights. The topology layer decides which rule
applies where; the matrix layer turns the weights into rows of S.
"""

from __future__ import annotations

import functools

import numpy as np
from numba import njit

# Vertex rules (OpenSubdiv's Sdc calls them the same). A dart (one crease edge) is SMOOTH.
SMOOTH = 0
CREASE = 1
CORNER = 2

# Regions of a smooth vertex: which scheme's faces surround it.
REGION_SQRT3 = 0
REGION_LOOP = 1
REGION_MIXED = 2

# Schemes, as the kernels see them.
SCHEME_CODES = {"hybrid": 0, "sqrt3": 1, "loop": 2}
SCHEME_HYBRID, SCHEME_SQRT3, SCHEME_LOOP = 0, 1, 2

# Edge kinds of one step.
EDGE_FLIP = 0  # sqrt3 edge flip: no point on it
EDGE_SPLIT = 1  # one edge point (crease or split-smooth)
EDGE_TRISECT = 2  # Kobbelt's even-step boundary: two points e1, e2
EDGE_KEEP = 3  # Kobbelt's odd-step boundary: kept as it is

#: Sharpness at or above this value is infinite (OpenSubdiv's SHARPNESS_INFINITE).
INFINITE_SHARPNESS = 10.0

#: Crease vertex mask (self, each of the two crease neighbours): Hoppe's B2 rule.
CREASE_MASK = (3.0 / 4.0, 1.0 / 8.0)
#: Kobbelt's even-step boundary vertex mask (self, each boundary neighbour).
KOBBELT_BOUNDARY_MASK = (19.0 / 27.0, 4.0 / 27.0)
#: Kobbelt's boundary trisection point e1 = (p_{i-1} + 16 p_i + 10 p_{i+1}) / 27.
KOBBELT_TRISECTION = (1.0 / 27.0, 16.0 / 27.0, 10.0 / 27.0)

LOOP_WEIGHTS = ("loop", "warren")


def kobbelt_alpha(n):
    """Kobbelt's √3 smoothing weight α_n = (4 − 2 cos(2π/n)) / 9.

    Examples
    --------
    >>> float(kobbelt_alpha(6))
    0.3333333333333333
    """
    n = np.asarray(n, dtype=np.float64)
    return (4.0 - 2.0 * np.cos(2.0 * np.pi / n)) / 9.0


def loop_beta(n, loop_weights="loop"):
    """Loop's per-neighbour weight β_n.

    ``"loop"``: β_n = (5/8 − (3/8 + 1/4 cos(2π/n))²) / n; ``"warren"``: 3/16 for n = 3,
    3/(8n) otherwise.

    Examples
    --------
    >>> float(loop_beta(6))
    0.0625
    >>> float(loop_beta(4, "warren"))
    0.09375
    """
    n = np.asarray(n, dtype=np.float64)
    if loop_weights == "loop":
        c = 3.0 / 8.0 + 0.25 * np.cos(2.0 * np.pi / n)
        return (5.0 / 8.0 - c * c) / n
    if loop_weights == "warren":
        return np.where(n == 3, 3.0 / 16.0, 3.0 / (8.0 * n))
    raise ValueError(f"loop_weights must be one of {LOOP_WEIGHTS}, got {loop_weights!r}")


def mixed_alpha(n):
    """Weight α of the neighbour average at a vertex where √3 and Loop faces meet.

    The paper's R3 table: 9/16 for n = 3 (3/16 per neighbour), 3/8 for n = 4, 5,
    Kobbelt's α_n for n ≥ 6.

    Examples
    --------
    >>> [float(a) for a in mixed_alpha([3, 4, 5])]
    [0.5625, 0.375, 0.375]
    """
    n = np.asarray(n, dtype=np.float64)
    return np.where(n == 3, 9.0 / 16.0, np.where(n < 6, 3.0 / 8.0, kobbelt_alpha(n)))


def smooth_neighbour_weight(n, region, loop_weights="loop"):
    """Per-neighbour weight of the smooth vertex mask, by region; 0 where n = 0.

    The vertex keeps 1 − n · weight of itself.

    Examples
    --------
    >>> smooth_neighbour_weight([6, 6], [REGION_SQRT3, REGION_LOOP]).tolist()
    [0.05555555555555555, 0.0625]
    """
    n = np.asarray(n, dtype=np.int64)
    region = np.asarray(region)
    safe = np.maximum(n, 1)
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.where(
            region == REGION_SQRT3,
            kobbelt_alpha(safe) / safe,
            np.where(region == REGION_LOOP, loop_beta(safe, loop_weights), mixed_alpha(safe) / safe),
        )
    return np.where(n > 0, w, 0.0)


def smooth_weight_table(max_valence, loop_weights="loop"):
    """Per-neighbour smooth weights by region and valence: table[region, n], n = 0..max_valence.

    Examples
    --------
    >>> t = smooth_weight_table(6)
    >>> t.shape, float(t[REGION_LOOP, 6])
    ((3, 7), 0.0625)
    """
    size = max(32, 1 << int(max_valence).bit_length())  # tables of a few sizes, each computed once
    return _weight_table(size, loop_weights)[:, :max_valence + 1].copy()


@functools.lru_cache(maxsize=None)
def _weight_table(size: int, loop_weights: str) -> np.ndarray:
    n = np.arange(size + 1)
    return np.stack([smooth_neighbour_weight(n, r, loop_weights)
                     for r in (REGION_SQRT3, REGION_LOOP, REGION_MIXED)])


@njit(cache=True, inline="always")  # called per edge or vertex: a call costs more than the rule
def vertex_rule(crease_count, is_corner):
    """Rule of a vertex from its number of incident creases and its corner tag."""
    if is_corner or crease_count >= 3:
        return CORNER
    if crease_count == 2:
        return CREASE
    return SMOOTH


@njit(cache=True, inline="always")  # called per edge or vertex: a call costs more than the rule
def vertex_mask(n, rule_parent, rule_child, blend, smooth_w, cs, cn):
    """A vertex point's mask as four coefficients: (self, every neighbour, each neighbour
    along a crease of this level (s > 0), each neighbour along a crease of the next level
    (s > 1)).

    ``n`` is the valence, ``smooth_w`` the per-neighbour weight of the region's smooth mask,
    ``(cs, cn)`` the crease mask. Where the parent and child rules differ (semi-sharp creases
    decaying), the parent mask is blended with the child mask: ``blend · parent +
    (1 − blend) · child`` (OpenSubdiv's fractional weight).
    """
    if rule_parent == SMOOTH:
        return 1.0 - n * smooth_w, smooth_w, 0.0, 0.0
    if rule_child == rule_parent or blend >= 1.0:
        if rule_parent == CREASE:
            return cs, 0.0, cn, 0.0
        return 1.0, 0.0, 0.0, 0.0
    w = blend
    a = w * cs if rule_parent == CREASE else w
    p = w * cn if rule_parent == CREASE else 0.0
    if rule_child == CREASE:
        return a + (1.0 - w) * cs, 0.0, p, (1.0 - w) * cn
    return a + (1.0 - w) * (1.0 - n * smooth_w), (1.0 - w) * smooth_w, p, 0.0


@njit(cache=True, inline="always")  # called per edge or vertex: a call costs more than the rule
def edge_weights(s):
    """Edge point weights (each end, each opposite vertex) for an edge of sharpness s.

    s ≥ 1 (or inf): the crease midpoint (B1); s = 0: Loop's R4 (3/8, 1/8); in between the
    two blended, s · midpoint + (1 − s) · R4.
    """
    if s >= 1.0:
        return 0.5, 0.0
    return s * 0.5 + (1.0 - s) * 0.375, (1.0 - s) * 0.125


def child_sharpness(s):
    """Sharpness of a crease's children: s − 1, infinite stays infinite, ≤ 0 means smooth.

    Examples
    --------
    >>> child_sharpness(np.array([0.5, 2.5, np.inf])).tolist()
    [0.0, 1.5, inf]
    """
    s = np.asarray(s, dtype=np.float64)
    return np.where(np.isinf(s), s, np.maximum(s - 1.0, 0.0))


def normalize_sharpness(s):
    """Map user sharpness to the internal form: ≥ 10 → inf, ≤ 0 → 0."""
    s = np.asarray(s, dtype=np.float64)
    return np.where(s >= INFINITE_SHARPNESS, np.inf, np.maximum(s, 0.0))

