"""Semi-sharp creases as properties (SCHEME.md, "Semi-sharp creases"), on random meshes.

The hand-computed rules (s = 0.5 edge points, transition blends, corner -> crease) are in
``tests/test_rules_exact.py``; the OpenSubdiv ``loop_semisharp`` references in
``tests/test_reference.py``. Here: what follows from the rules for every mesh —

- s = inf (or >= 10) is the core's infinitely sharp crease, bit for bit;
- s = 1 is infinitely sharp for exactly one level, then no crease at all;
- fractional sharpness counts down by one per level, and the crease ends after ceil(s) levels;
- after ceil(max s) levels no crease is left, and the hybrid goes on as plain √3;
- s -> 0+ tends to plain Loop in ``"loop"``; in the hybrid to the level's split-smooth (R4)
  edge, flipped from the next level on.
"""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hybridsub
import strategies as ms
from hybridsub._input import arrays as val
from hybridsub._refiner.stencils import step_matrix
from hybridsub._topology import checked_level, child_level, plan_step


def cfg(n):
    return settings(max_examples=n, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def tagged(kind="any", sharpness="none"):
    """A mesh with at least one crease edge, and maybe sharp faces and corners."""
    return ms.tagged_meshes(kind, sharpness=sharpness).filter(lambda m: len(m[2].get("sharp_edges", ())) > 0)


def levels_for(m, scheme, cap=3, budget=5000):
    growth = 4 if scheme == "loop" else 3.5
    return max(1, min(cap, int(math.log(max(budget / max(m, 1), 1.0), growth))))


def without(tags, *names):
    return {k: v for k, v in tags.items() if k not in names}


def dense_diff(A, B):
    return abs(A - B).max() if (A - B).nnz else 0.0


# ---------------------------------------------------------------------------- s = inf, s = 1


@cfg(40)
@given(st.data(), st.sampled_from(["hybrid", "loop"]))
def test_infinite_sharpness_is_the_core_bit_for_bit(data, scheme):
    V, F, tags = data.draw(tagged())
    E = tags["sharp_edges"]
    L = data.draw(st.integers(1, levels_for(len(F), scheme)))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    # any value >= 10 is infinite (OpenSubdiv's convention); duplicates keep one value per edge
    big = rng.choice([np.inf, 10.0, 12.5, 1e6], size=len(E))
    core = hybridsub.refine(F, E, L, n_vertices=len(V), scheme=scheme, **without(tags, "sharp_edges"))
    Vc, Fc = hybridsub.subdivide(V, F, E, L, scheme=scheme, **without(tags, "sharp_edges"))
    for s in (np.full(len(E), np.inf), big):
        r = hybridsub.refine(F, E, L, n_vertices=len(V), scheme=scheme, sharpness=s, **without(tags, "sharp_edges"))
        np.testing.assert_array_equal(r.faces, core.faces)
        np.testing.assert_array_equal(r.sharp_edges, core.sharp_edges)
        assert np.isinf(r.sharpness).all()
        assert dense_diff(r.matrix, core.matrix) == 0.0
        V2, F2 = hybridsub.subdivide(V, F, E, L, scheme=scheme, sharpness=s, **without(tags, "sharp_edges"))
        np.testing.assert_array_equal(F2, Fc)
        assert np.array_equal(V2, Vc), "s = inf must reproduce the core bit for bit"


@cfg(40)
@given(st.data(), st.sampled_from(["hybrid", "loop"]))
def test_sharpness_one_is_infinite_for_exactly_one_level(data, scheme):
    V, F, tags = data.draw(tagged())
    E = tags["sharp_edges"]
    rest = without(tags, "sharp_edges")
    ones = np.ones(len(E))
    # level 1: the same as infinitely sharp (midpoints, w = 1 -> the parent's crease/corner mask)
    V1, F1 = hybridsub.subdivide(V, F, E, 1, scheme=scheme, sharpness=ones, **rest)
    r1 = hybridsub.refine(F, E, 1, n_vertices=len(V), scheme=scheme, **rest)
    np.testing.assert_array_equal(F1, r1.faces)
    assert np.array_equal(V1, r1.apply(V))
    assert len(hybridsub.refine(F, E, 1, n_vertices=len(V), scheme=scheme, sharpness=ones, **rest).sharp_edges) == 0
    # level 2: the children have s = 0: no crease; the step is the untagged one on level 1
    V2, F2 = hybridsub.subdivide(V, F, E, 2, scheme=scheme, sharpness=ones, **rest)
    V2b, F2b = hybridsub.subdivide(V1, F1, None, 1, scheme=scheme, sharp_faces=r1.sharp_faces,
                                   corners=tags.get("corners"))
    np.testing.assert_array_equal(F2, F2b)
    assert np.array_equal(V2, V2b)


def test_fractional_sharpness_counts_down_one_per_level():
    # Octahedron equator with s = 0.25, 1.5, 2.75, 0.5: children carry s - 1 while it is > 0
    V, F = ms.octahedron()
    E = [[0, 2], [2, 1], [1, 3], [3, 0]]
    r = hybridsub.refine(F, E, 4, n_vertices=len(V), sharpness=[0.25, 1.5, 2.75, 0.5])
    got = [sorted(np.asarray(s.sharpness).tolist()) for s in r.steps]
    assert got == [[0.5, 0.5, 1.75, 1.75], [0.75] * 4, [], []]
    assert [len(s.sharp_edges) for s in r.steps] == [4, 4, 0, 0]


# ---------------------------------------------------------------------------- decay to √3


@cfg(25)
@given(st.data())
def test_finite_creases_decay_after_ceil_max_s_then_plain_sqrt3(data):
    V, F = data.draw(ms.closed_meshes(max_points=30))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    E = ms.edges_of(F)
    E = E[rng.random(len(E)) < data.draw(st.sampled_from([0.1, 0.3, 0.6]))]
    if not len(E):
        E = ms.edges_of(F)[:1]
    s = ms.random_sharpness(rng, len(E), "finite")
    K = math.ceil(s.max())
    r_before = hybridsub.refine(F, E, K - 1, n_vertices=len(V), sharpness=s)
    assert len(r_before.sharp_edges) > 0 and (r_before.sharpness <= 1).all()
    r = hybridsub.refine(F, E, K, n_vertices=len(V), sharpness=s)
    assert len(r.sharp_edges) == 0 and len(r.sharpness) == 0
    J = data.draw(st.integers(1, 2))
    VK = r.apply(V)
    Vh, Fh = hybridsub.subdivide(V, F, E, K + J, sharpness=s)
    Vs, Fs = hybridsub.subdivide(VK, r.faces, None, J, scheme="sqrt3")
    np.testing.assert_array_equal(Fh, Fs)
    np.testing.assert_allclose(Vh, Vs, rtol=0, atol=1e-14 * max(1.0, np.abs(V).max()))


@cfg(25)
@given(st.data(), st.sampled_from(["hybrid", "loop"]))
def test_finite_creases_decay_then_untagged_rules_anywhere(data, scheme):
    # open meshes, sharp faces, corners: after ceil(max s) levels the steps are the untagged ones
    V, F, tags = data.draw(tagged())
    E = tags["sharp_edges"]
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    s = ms.random_sharpness(rng, len(E), "semisharp")
    rest = without(tags, "sharp_edges")
    K = math.ceil(s.max())
    if len(F) * (4 if scheme == "loop" else 3.5) ** (K + 1) > 20000:
        return
    r = hybridsub.refine(F, E, K, n_vertices=len(V), scheme=scheme, sharpness=s, **rest)
    assert len(r.sharp_edges) == 0
    V1, F1 = hybridsub.subdivide(V, F, E, K + 1, scheme=scheme, sharpness=s, **rest)
    V2, F2 = hybridsub.subdivide(r.apply(V), r.faces, None, 1, scheme=scheme, sharp_faces=r.sharp_faces,
                                 corners=tags.get("corners"))
    np.testing.assert_array_equal(F1, F2)
    assert np.array_equal(V1, V2)


# ---------------------------------------------------------------------------- s -> 0+


def _scaled(data):
    """A tagged mesh and sharpness values u in (0, 1]: the creases get s = t u for t in (0, 1]."""
    V, F, tags = data.draw(tagged())
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    u = rng.uniform(0.05, 1.0, size=len(tags["sharp_edges"]))
    return V, F, tags, u


@cfg(40)
@given(st.data())
def test_loop_tends_to_plain_loop_as_sharpness_goes_to_zero(data):
    # For s in (0, 1] the matrix is affine in s (edge points linear in s, blend weight w the
    # mean of s), so S(0+) = 2 S(t) - S(2t) exactly, and it must be plain Loop's matrix.
    V, F, tags, u = _scaled(data)
    E, rest = tags["sharp_edges"], without(tags, "sharp_edges")
    L = data.draw(st.integers(1, levels_for(len(F), "loop", cap=2)))

    def S(t):
        return hybridsub.refine(F, E, L, n_vertices=len(V), scheme="loop", sharpness=t * u, **rest)

    plain = hybridsub.refine(F, None, L, n_vertices=len(V), scheme="loop", **rest)
    assert_limit_at_zero(S, plain.matrix, plain.faces)


def assert_limit_at_zero(S, limit_matrix, limit_faces):
    """``S(t)`` (the refinement with sharpness ``t u``) has the faces of the limit for every
    t in (0, 1], is affine in t there (so ``2 S(t) - S(2t)`` is the limit itself), and tends to
    it linearly."""
    a, b = S(0.25), S(0.5)
    np.testing.assert_array_equal(a.faces, limit_faces)
    assert dense_diff(2 * a.matrix - b.matrix, limit_matrix) < 1e-13
    err = [dense_diff(S(t).matrix, limit_matrix) for t in (1e-3, 1e-6, 1e-9)]
    assert err[1] <= 2e-6 and err[1] <= 1e-2 * max(err[0], 1e-300) + 1e-15 and err[2] < 1e-8


def _r4_step(V, F, E, tags):
    """One hybrid step with the edges E split by R4 between smooth faces and not creases:
    the s -> 0+ limit of SCHEME.md (built from the layers below ``refine``)."""
    Fi, n = val.as_faces(F, len(V))
    face_sharp, _ = val.as_face_mask(tags.get("sharp_faces"), len(Fi))
    corner = val.as_corner_mask(tags.get("corners"), n)
    none = np.empty((0, 2), np.int64)
    level = checked_level(Fi, n, none).tag(none, np.empty(0), face_sharp)
    want = {frozenset(map(int, e)) for e in np.asarray(E)}
    force = np.array([frozenset((int(Fi[h // 3, h % 3]), int(Fi[h // 3, (h % 3 + 1) % 3]))) in want
                      for h in range(3 * len(Fi))])
    plan = plan_step(level, corner, "hybrid", 1, "loop", force_split=force)
    _, child, _ = child_level(level, plan)
    return step_matrix(level, plan), child.faces, child.face_sharp


@cfg(40)
@given(st.data())
def test_hybrid_tends_to_the_split_smooth_edge_as_sharpness_goes_to_zero(data):
    V, F, tags, u = _scaled(data)
    E, rest = tags["sharp_edges"], without(tags, "sharp_edges")
    L = data.draw(st.integers(1, levels_for(len(F), "hybrid", cap=2)))

    def S(t):
        return hybridsub.refine(F, E, L, n_vertices=len(V), sharpness=t * u, **rest)

    S1, F1, sharp1 = _r4_step(V, F, E, tags)
    if L == 1:
        limit_matrix, limit_faces = S1, F1
    else:  # from level 2 on: no crease left; the former creases' children are flipped
        after = hybridsub.refine(F1, None, L - 1, n_vertices=S1.shape[0], sharp_faces=sharp1,
                                 corners=tags.get("corners"))
        limit_matrix, limit_faces = (after.matrix @ S1).tocsr(), after.faces
    assert_limit_at_zero(S, limit_matrix, limit_faces)
