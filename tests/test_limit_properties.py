"""Property tests of LimitSurface over generated meshes (issue 14): rational parameters are the
refined vertices' limits, the two faces of an edge see one surface, derivatives are the
surface's. Every scheme and tag the generators make (creases, semi-sharp creases, sharp faces,
corners, boundaries, several pieces, high valences)."""

import numpy as np
import strategies as ms
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hybridsub

SETTINGS = settings(max_examples=20, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                           HealthCheck.filter_too_much])


def _tagged(data, scheme):
    V, F, tags = data.draw(ms.tagged_meshes(bowties=False))
    if scheme == "sqrt3":
        tags = {}
    elif scheme == "loop":
        tags.pop("sharp_faces", None)
    return V, F, dict(tags, scheme=scheme)


def _diag(V):
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0))) or 1.0


@SETTINGS
@given(st.data(), st.sampled_from(["hybrid", "sqrt3", "loop"]))
def test_refined_vertices_are_their_limit_positions(data, scheme):
    V, F, kw = _tagged(data, scheme)
    r = hybridsub.refine(F, levels=1, n_vertices=len(V), **kw)
    face, bary = r.vertex_origin
    used = face >= 0
    got = hybridsub.LimitSurface(V, F, depth=2, **kw).evaluate(face[used], bary[used])
    want = hybridsub.limit_positions(V, F, levels=1, **kw)[used]
    assert np.abs(got - want).max(initial=0) <= 1e-12 * _diag(V)


def _edge_points(F, rng, k):
    """``k`` points on random interior edges: (face, bary) from each of the edge's two faces."""
    h = np.stack([F, np.roll(F, -1, axis=1)], -1).reshape(-1, 2)  # halfedge 3f + i: F[f, i] → F[f, i + 1]
    where = {(int(a), int(b)): i for i, (a, b) in enumerate(h)}
    pairs = [(i, where[(b, a)]) for (a, b), i in where.items() if (b, a) in where and a < b]
    if not pairs:
        return None
    pick = rng.integers(0, len(pairs), k)
    t = rng.uniform(0.05, 0.95, k)
    f1, f2, b1, b2 = [], [], np.zeros((k, 3)), np.zeros((k, 3))
    for j, (p, q) in enumerate(np.array(pairs)[pick]):
        f1.append(p // 3)
        f2.append(q // 3)
        b1[j, p % 3], b1[j, (p % 3 + 1) % 3] = 1 - t[j], t[j]  # a → b
        b2[j, (q % 3 + 1) % 3], b2[j, q % 3] = 1 - t[j], t[j]  # b → a: the same point
    return np.array(f1), b1, np.array(f2), b2


@SETTINGS
@given(st.data(), st.sampled_from(["hybrid", "sqrt3", "loop"]), ms.seeds)
def test_both_faces_of_an_edge_see_one_surface(data, scheme, seed):
    V, F, kw = _tagged(data, scheme)
    pts = _edge_points(F, np.random.default_rng(seed), 6)
    if pts is None:
        return
    f1, b1, f2, b2 = pts
    s = hybridsub.LimitSurface(V, F, **kw)  # the default depth: each side's last interpolation to 1e-12
    assert np.abs(s.evaluate(f1, b1) - s.evaluate(f2, b2)).max() <= 1e-11 * _diag(V)


@SETTINGS
@given(st.data(), st.sampled_from(["hybrid", "sqrt3", "loop"]), ms.seeds)
def test_derivatives_are_the_surfaces(data, scheme, seed):
    """Central differences in (u, v) at points well inside faces (a fifth of a face from
    every edge). Beside creases of √3 faces the chart is not smooth (its third derivatives
    grow like 1/distance², ``docs/limit.md``), so differences of step 1e-4 are off by 1e-4
    there (a flat 1 × 2 grid, boundary creases all round); at 1e-6, by 1e-6. A wrong chain
    rule, a swapped or flipped direction would be off by O(1)."""
    V, F, kw = _tagged(data, scheme)
    rng = np.random.default_rng(seed)
    k = 6
    face = rng.integers(0, len(F), k)
    bary = 0.2 + 0.4 * rng.dirichlet([1, 1, 1], k)
    s = hybridsub.LimitSurface(V, F, **kw)  # the default depth: derivatives to ~1e-7
    _, Du, Dv = s.evaluate(face, bary, derivatives=True)
    h = 1e-6
    for D, step in ((Du, [-h, h, 0]), (Dv, [-h, 0, h])):
        fd = (s.evaluate(face, bary + step) - s.evaluate(face, bary - step)) / (2 * h)
        scale = np.abs(D).max() + 1e-12 * _diag(V)
        assert np.abs(fd - D).max() <= 1e-4 * scale
