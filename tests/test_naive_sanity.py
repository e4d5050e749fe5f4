"""Sanity tests of the slow reference implementation (tests/naive.py) on its own.

Nothing here imports hybridsub: these tests pin the reference to the documented rules
(docs/scheme.md), hand-computed cases and the CGAL / OpenSubdiv outputs in tests/data/, so
that the fast path can then be compared with it on random meshes.
"""

from math import cos, pi
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

try:
    from tests.naive import naive_refine, naive_step
except ImportError:  # tests/ not importable as a package
    from naive import naive_refine, naive_step

DATA = Path(__file__).parent / "data"


# ---------------------------------------------------------------------------
# helpers
# ---------------------------------------------------------------------------

def load_off(name):
    mesh = trimesh.load(DATA / f"{name}.off", process=False)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces, dtype=np.int64)


def dense_row(S, i):
    return np.asarray(S[i].todense()).ravel()


def expected_row(n, weights):
    row = np.zeros(n)
    for j, x in weights.items():
        row[j] += x
    return row


def canonical_triangles(F):
    """Rotate each triangle (keeping orientation) so its smallest index comes first."""
    out = set()
    for t in np.asarray(F):
        k = int(np.argmin(t))
        out.add(tuple(int(x) for x in np.roll(t, -k)))
    return out


def assert_same_mesh(V, F, V_ref, F_ref, tol):
    """Equal up to vertex order: one-to-one nearest-vertex matching, then same triangles."""
    assert V.shape == V_ref.shape
    assert F.shape == F_ref.shape
    diag = np.linalg.norm(V_ref.max(axis=0) - V_ref.min(axis=0))
    dist, idx = cKDTree(V_ref).query(V)
    assert dist.max() <= tol * diag, dist.max() / diag
    assert len(np.unique(idx)) == len(idx), "vertex matching is not one-to-one"
    assert canonical_triangles(idx[F]) == canonical_triangles(F_ref)


def edge_set(F):
    return {tuple(sorted((int(F[f, i]), int(F[f, (i + 1) % 3])))) for f in range(len(F))
            for i in range(3)}


def euler(n_vertices_used, F):
    return n_vertices_used - len(edge_set(F)) + len(F)


def assert_consistent(F):
    """Every directed halfedge at most once, every edge in at most two faces."""
    directed = [(int(F[f, i]), int(F[f, (i + 1) % 3])) for f in range(len(F)) for i in range(3)]
    assert len(directed) == len(set(directed))
    assert all(len(set(t)) == 3 for t in np.asarray(F).tolist())


def random_hybrid_case(F, seed, semi=True):
    """Random sharp faces, random creases (some semi-sharp) and a corner or two."""
    rng = np.random.default_rng(seed)
    m = len(F)
    edges = np.array(sorted(edge_set(F)))
    pick = rng.random(len(edges)) < 0.25
    se = edges[pick]
    se = np.where(rng.random((len(se), 1)) < 0.5, se, se[:, ::-1])      # any orientation
    se = np.concatenate([se, se[: len(se) // 4]])                        # duplicates
    if semi:
        s = rng.choice([0.0, 0.3, 0.5, 1.0, 1.7, 2.5, 12.0, np.inf], size=len(se))
        s[len(se) - len(se) // 4:] = s[: len(se) // 4]                  # duplicates agree
    else:
        s = None
    mask = rng.random(m) < 0.4
    corners = rng.choice(F.max() + 1, size=2, replace=False)
    return dict(sharp_edges=se, sharpness=s, sharp_faces=mask, corners=corners)


# ---------------------------------------------------------------------------
# worked examples of docs/scheme.md
# ---------------------------------------------------------------------------

def test_worked_example_hybrid_one_face():
    r = naive_step(np.array([[0, 1, 2]]), 3)
    S = r["S"].toarray()
    assert S.shape == (7, 3)
    np.testing.assert_array_equal(S[0], [0.75, 0.125, 0.125])
    np.testing.assert_array_equal(S[1], [0.125, 0.75, 0.125])
    np.testing.assert_array_equal(S[2], [0.125, 0.125, 0.75])
    np.testing.assert_array_equal(S[3], [0.5, 0.5, 0])
    np.testing.assert_array_equal(S[4], [0, 0.5, 0.5])
    np.testing.assert_array_equal(S[5], [0.5, 0, 0.5])
    np.testing.assert_allclose(S[6], [1 / 3] * 3, rtol=0, atol=1e-16)
    np.testing.assert_array_equal(
        r["faces"], [[6, 0, 3], [6, 3, 1], [6, 1, 4], [6, 4, 2], [6, 2, 5], [6, 5, 0]])
    assert euler(7, r["faces"]) == 1
    np.testing.assert_array_equal(r["face_parent"], [0] * 6)
    assert not r["sharp_faces"].any()
    assert r["sharp_edges"].shape == (0, 2)      # boundary creases are implicit
    assert r["corners"].shape == (0,)


def test_worked_example_sqrt3_one_face():
    r = naive_step(np.array([[0, 1, 2]]), 3, scheme="sqrt3", step=1)
    S = r["S"].toarray()
    np.testing.assert_array_equal(S[:3], np.eye(3))
    np.testing.assert_allclose(S[3], [1 / 3] * 3, rtol=0, atol=1e-16)
    np.testing.assert_array_equal(r["faces"], [[3, 0, 1], [3, 1, 2], [3, 2, 0]])


def test_sqrt3_even_step_one_face_after_odd():
    """Step 2 on the output of step 1 of a single triangle: trisection and apex rules."""
    r = naive_refine(np.array([[0, 1, 2]]), 3, 2, scheme="sqrt3")
    F1 = np.array([[3, 0, 1], [3, 1, 2], [3, 2, 0]])
    r2 = naive_step(F1, 4, scheme="sqrt3", step=2)
    # edges of F1 in order: (3,0) (0,1)b (1,3) (1,2)b (2,3) (2,0)b -> e1,e2 = 4,5 / 6,7 / 8,9
    S = r2["S"].toarray()
    assert S.shape == (10, 4)
    np.testing.assert_allclose(S[0], np.array([19, 4, 4, 0]) / 27, atol=1e-16)
    # the face point 3 is an interior valence-3 vertex: Kobbelt, alpha_3 = 5/9
    np.testing.assert_allclose(S[3], np.array([5, 5, 5, 12]) / 27, atol=1e-16)
    # e1 of 0->1: p_{i-1} = 2, e2: p_{i+2} = 2
    np.testing.assert_allclose(S[4], np.array([16, 10, 1, 0]) / 27, atol=1e-16)
    np.testing.assert_allclose(S[5], np.array([10, 16, 1, 0]) / 27, atol=1e-16)
    # no face has a face point; every face is trisected along its boundary halfedge
    # face 0 (3,0,1), boundary 0->1 (e1=4, e2=5): 3->0 twin in face 2 (3,2,0) along 2->0
    #   (e1=8, e2=9), twin 0->3 is face 2's w->x -> apex e2 = 9; own apex for x->u = e1 = 4;
    #   1->3 (own w->x: e2 = 5) has its twin 3->1 in face 1 (3,1,2), x->u there: e1 = 6
    np.testing.assert_array_equal(
        r2["faces"],
        [[3, 9, 4], [4, 5, 3], [1, 6, 5],
         [3, 5, 6], [6, 7, 3], [2, 8, 7],
         [3, 7, 8], [8, 9, 3], [0, 4, 9]])
    assert euler(10, r2["faces"]) == 1
    assert_consistent(r2["faces"])
    np.testing.assert_allclose(r["S"].toarray(), (r2["S"] @ naive_step(
        np.array([[0, 1, 2]]), 3, scheme="sqrt3")["S"]).toarray(), atol=1e-15)


# ---------------------------------------------------------------------------
# rules by hand
# ---------------------------------------------------------------------------

def test_tetrahedron_sqrt3_one_step():
    V, F = load_off("tetrahedron")
    r = naive_step(F, len(V), scheme="sqrt3")
    assert r["S"].shape == (8, 4)
    assert r["faces"].shape == (12, 3)
    V1 = r["S"] @ V
    for f in range(4):
        np.testing.assert_allclose(V1[4 + f], V[F[f]].mean(axis=0), rtol=0, atol=1e-15)
    a3 = (4 - 2 * cos(2 * pi / 3)) / 9
    np.testing.assert_allclose(dense_row(r["S"], 0), [1 - a3, a3 / 3, a3 / 3, a3 / 3], atol=1e-16)
    assert euler(8, r["faces"]) == 2
    assert_consistent(r["faces"])


def test_octahedron_loop_and_warren_weights():
    V, F = load_off("octahedron")
    b_loop = (5 / 8 - (3 / 8 + cos(2 * pi / 4) / 4) ** 2) / 4
    for weights, beta in (("loop", b_loop), ("warren", 3 / 32)):
        r = naive_step(F, 6, scheme="loop", loop_weights=weights)
        row = dense_row(r["S"], 0)
        np.testing.assert_allclose(row, [1 - 4 * beta, beta, beta, beta, beta, 0], atol=1e-16)
        # (1,0) is edge 0, opposite vertices 4 and 2
        np.testing.assert_allclose(dense_row(r["S"], 6), [3 / 8, 3 / 8, 1 / 8, 0, 1 / 8, 0],
                                   atol=1e-16)


def test_octahedron_mixed_vertex_and_r4():
    V, F = load_off("octahedron")
    mask = np.zeros(8, dtype=bool)
    mask[0] = True                       # face (1,0,4)
    r = naive_step(F, 6, sharp_faces=mask)
    S = r["S"]
    # 3 split-smooth edges (1,0),(0,4),(4,1) -> 6,7,8; face points of faces 1..7 -> 9..15
    assert S.shape == (16, 6)
    np.testing.assert_allclose(dense_row(S, 0), expected_row(6, {0: 5 / 8, 1: 3 / 32, 2: 3 / 32,
                                                                 3: 3 / 32, 4: 3 / 32}), atol=1e-16)
    a4 = 4 / 9
    np.testing.assert_allclose(dense_row(S, 5), expected_row(6, {5: 1 - a4, 1: a4 / 4, 2: a4 / 4,
                                                                 3: a4 / 4, 4: a4 / 4}), atol=1e-16)
    np.testing.assert_allclose(dense_row(S, 7), expected_row(6, {0: 3 / 8, 4: 3 / 8, 1: 1 / 8,
                                                                 3: 1 / 8}), atol=1e-16)
    assert len(r["faces"]) == 4 + 7 * 3 + 3
    np.testing.assert_array_equal(r["faces"][:4], [[1, 6, 8], [6, 0, 7], [8, 7, 4], [6, 7, 8]])
    # face 1 (4,0,3): 4->0 split (point 7); 0->3 flip with face 2; 3->4 flip with face 6
    np.testing.assert_array_equal(r["faces"][4:8], [[9, 4, 7], [9, 7, 0], [0, 10, 9], [3, 14, 9]])
    np.testing.assert_array_equal(r["sharp_faces"], [True] * 4 + [False] * 24)
    assert euler(16, r["faces"]) == 2
    assert_consistent(r["faces"])


def test_octahedron_semi_sharp_half():
    V, F = load_off("octahedron")
    r = naive_step(F, 6, sharp_edges=[[0, 1], [3, 0]], sharpness=[0.5, 0.5])
    S = r["S"]
    # edge (1,0) -> 6, (0,3) -> 7; both are split in the sqrt(3) region
    assert S.shape == (6 + 2 + 8, 6)
    np.testing.assert_allclose(dense_row(S, 6), expected_row(6, {0: 0.4375, 1: 0.4375,
                                                                 2: 0.0625, 4: 0.0625}), atol=1e-16)
    # vertex 0: parent rule crease (1, 3), child rule smooth, w = 0.5
    np.testing.assert_allclose(
        dense_row(S, 0),
        expected_row(6, {0: 0.375 + 5 / 18, 1: 1 / 16 + 1 / 18, 3: 1 / 16 + 1 / 18,
                         2: 1 / 18, 4: 1 / 18}), atol=1e-15)
    assert r["sharp_edges"].shape == (0, 2)
    np.testing.assert_array_equal(r["faces"][:4], [[8, 1, 6], [8, 6, 0], [0, 9, 8], [4, 15, 8]])
    assert_consistent(r["faces"])


def test_octahedron_semi_sharp_propagation():
    V, F = load_off("octahedron")
    r = naive_step(F, 6, sharp_edges=[[3, 0], [0, 1], [1, 0]], sharpness=[1.5, 2.5, 2.0])
    np.testing.assert_allclose(dense_row(r["S"], 0),
                               expected_row(6, {0: 0.75, 1: 0.125, 3: 0.125}), atol=1e-16)
    np.testing.assert_allclose(dense_row(r["S"], 6), expected_row(6, {0: 0.5, 1: 0.5}),
                               atol=1e-16)
    # parent edges in edge order, children in the owner's orientation: (1,0) then (0,3)
    np.testing.assert_array_equal(r["sharp_edges"], [[1, 6], [6, 0], [0, 7], [7, 3]])
    np.testing.assert_allclose(r["sharpness"], [1.5, 1.5, 0.5, 0.5])
    r2 = naive_step(r["faces"], r["S"].shape[0], sharp_edges=r["sharp_edges"],
                    sharpness=r["sharpness"])
    assert len(r2["sharp_edges"]) == 4                  # (1,6),(6,0) survive with 0.5
    np.testing.assert_allclose(r2["sharpness"], [0.5] * 4)


def test_infinite_sharpness_conventions_and_corners():
    V, F = load_off("octahedron")
    r = naive_step(F, 6, sharp_edges=[[0, 1], [0, 2], [0, 3]], sharpness=[10.0, np.inf, 0.0],
                   corners=[5, 5, 2])
    assert np.isinf(r["sharpness"]).all() and len(r["sharpness"]) == 4
    np.testing.assert_array_equal(r["corners"], [2, 5])
    np.testing.assert_array_equal(dense_row(r["S"], 5), np.eye(6)[5])
    np.testing.assert_array_equal(dense_row(r["S"], 2), np.eye(6)[2])
    # vertex 0: two creases (1 and 2; sharpness 0 is no crease)
    np.testing.assert_allclose(dense_row(r["S"], 0),
                               expected_row(6, {0: 0.75, 1: 0.125, 2: 0.125}), atol=1e-16)
    r3 = naive_step(F, 6, sharp_edges=[[0, 1], [0, 2], [0, 3]])
    np.testing.assert_array_equal(dense_row(r3["S"], 0), np.eye(6)[0])   # c = 3: corner


def test_unreferenced_vertex_identity():
    r = naive_step(np.array([[0, 2, 3]]), 5)
    np.testing.assert_array_equal(dense_row(r["S"], 1), np.eye(5)[1])
    np.testing.assert_array_equal(dense_row(r["S"], 4), np.eye(5)[4])
    assert r["S"].shape == (5 + 3 + 1, 5)


def test_sqrt3_rejects_tags():
    with pytest.raises(ValueError):
        naive_step(np.array([[0, 1, 2]]), 3, scheme="sqrt3", sharp_edges=[[0, 1]])


# ---------------------------------------------------------------------------
# invariants on random tags
# ---------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["octahedron", "icosahedron", "mesh_with_border"])
@pytest.mark.parametrize("seed", [0, 1])
def test_counts_rows_and_consistency(name, seed):
    V, F = load_off(name)
    if name == "mesh_with_border":
        F = F[:200]                                         # keep it quick
    n = len(V)
    used = len(np.unique(F))
    kw = random_hybrid_case(F, seed)
    r = naive_step(F, n, **kw)
    S = r["S"]
    np.testing.assert_allclose(np.asarray(S.sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-14)
    assert S.data.min() >= 0
    # counts: |V'| = |V| + |split edges| + |smooth faces|; faces = sum(3 + s) + 4 * sharp
    edges = edge_set(F)
    count = {}
    for f in range(len(F)):
        for i in range(3):
            key = tuple(sorted((int(F[f, i]), int(F[f, (i + 1) % 3]))))
            count[key] = count.get(key, 0) + 1
    tagged = {}
    for (p, q), s in zip(kw["sharp_edges"], kw["sharpness"]):
        key = (min(p, q), max(p, q))
        s = np.inf if s >= 10 else s
        tagged[key] = max(tagged.get(key, 0.0), s)
    crease = {e for e in edges if count[e] == 1 or tagged.get(e, 0) > 0}
    mask = kw["sharp_faces"]
    split = set(crease)
    for f in np.flatnonzero(mask):
        for i in range(3):
            split.add(tuple(sorted((int(F[f, i]), int(F[f, (i + 1) % 3])))))
    n_smooth = int((~mask).sum())
    assert S.shape == (n + len(split) + n_smooth, n)
    n_faces = 4 * int(mask.sum())
    for f in np.flatnonzero(~mask):
        n_faces += 3 + sum(tuple(sorted((int(F[f, i]), int(F[f, (i + 1) % 3])))) in split
                           for i in range(3))
    assert len(r["faces"]) == n_faces
    assert_consistent(r["faces"])
    assert euler(used + len(split) + n_smooth, r["faces"]) == euler(used, F)
    assert len(np.unique(r["faces"])) == used + len(split) + n_smooth
    assert r["sharp_faces"].sum() == 4 * mask.sum()
    np.testing.assert_array_equal(mask[r["face_parent"]], r["sharp_faces"])
    np.testing.assert_array_equal(r["corners"], np.unique(kw["corners"]))
    # child creases: two per surviving tagged interior crease, each an edge of the new mesh
    new_edges = edge_set(r["faces"])
    for (p, q) in r["sharp_edges"]:
        assert (min(p, q), max(p, q)) in new_edges
    survivors = [e for e, s in tagged.items() if count[e] == 2 and s > 1]
    assert len(r["sharp_edges"]) == 2 * len(survivors)


@pytest.mark.parametrize("scheme", ["hybrid", "loop", "sqrt3"])
def test_refine_composite_matches_chained_steps(scheme):
    V, F = load_off("mesh_with_border")
    F = F[:150]
    kw = {} if scheme == "sqrt3" else random_hybrid_case(F, 3)
    if scheme == "loop":
        kw.pop("sharp_faces")
    r = naive_refine(F, len(V), 3, scheme=scheme, **kw)
    Vk, Fk, parent = V, F, np.arange(len(F))
    state = dict(kw)
    for k in range(3):
        s = naive_step(Fk, len(Vk), scheme=scheme, step=k + 1, **state)
        Vk, Fk, parent = s["S"] @ Vk, s["faces"], parent[s["face_parent"]]
        if scheme != "sqrt3":
            state = dict(sharp_edges=s["sharp_edges"], sharpness=s["sharpness"],
                         corners=s["corners"])
            if scheme == "hybrid":
                state["sharp_faces"] = s["sharp_faces"]
    np.testing.assert_allclose(r["S"] @ V, Vk, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(r["faces"], Fk)
    np.testing.assert_array_equal(r["face_parent"], parent)
    np.testing.assert_allclose(np.asarray(r["S"].sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-13)
    assert_consistent(r["faces"])


def test_hybrid_reduces_to_sqrt3_on_closed_untagged():
    V, F = load_off("icosahedron")
    h = naive_refine(F, len(V), 3)
    s = naive_refine(F, len(V), 3, scheme="sqrt3")
    np.testing.assert_array_equal(h["faces"], s["faces"])
    assert abs(h["S"] - s["S"]).max() == 0


def test_hybrid_reduces_to_loop_with_every_face_sharp():
    V, F = load_off("mesh_with_border")
    F = F[:300]
    kw = random_hybrid_case(F, 5)
    kw.pop("sharp_faces")
    h = naive_refine(F, len(V), 2, sharp_faces=np.ones(len(F), dtype=bool), **kw)
    lo = naive_refine(F, len(V), 2, scheme="loop", **kw)
    for key in ("faces", "sharp_edges", "sharpness", "sharp_faces", "corners", "face_parent"):
        np.testing.assert_array_equal(h[key], lo[key])
    assert abs(h["S"] - lo["S"]).max() == 0


# ---------------------------------------------------------------------------
# external references (CGAL, OpenSubdiv)
# ---------------------------------------------------------------------------

def check_reference(name, tol=1e-12):
    d = np.load(DATA / f"{name}.npz")
    _, kind, level = name.split(".")
    kw = {"scheme": "sqrt3" if kind == "sqrt3" else "loop"}
    if kind in ("loop_creases", "loop_semisharp"):
        kw["sharp_edges"] = d["creases"]
        if kind == "loop_semisharp":
            kw["sharpness"] = d["sharpness"]
    r = naive_refine(d["F_in"], len(d["V_in"]), int(level[1:]), **kw)
    assert_same_mesh(r["S"] @ d["V_in"], r["faces"], d["V"], d["F"], tol)


def test_tetrahedron_loop_reference():
    d = np.load(DATA / "tetrahedron.loop.L1.npz")
    V, F = load_off("tetrahedron")
    np.testing.assert_array_equal(d["F_in"], F)
    r = naive_step(F, len(V), scheme="loop")
    assert_same_mesh(r["S"] @ V, r["faces"], d["V"], d["F"], 1e-12)


@pytest.mark.parametrize("name", [
    f"{mesh}.sqrt3.L{level}" for mesh in ("tetrahedron", "octahedron", "mesh_with_border")
    for level in (1, 2, 3)
    if (DATA / f"{mesh}.sqrt3.L{level}.npz").exists()
] + ["icosahedron.sqrt3.L3", "cube-meshed.sqrt3.L1"])
def test_sqrt3_references(name):
    check_reference(name)


@pytest.mark.parametrize("name", [
    "tetrahedron.loop.L2", "octahedron.loop.L2", "icosahedron.loop.L2",
    "mesh_with_border.loop.L1", "mesh_with_border.loop.L2", "cube-meshed.loop.L1",
    "cube-meshed.loop_creases.L1",
])
def test_loop_references(name):
    check_reference(name)


@pytest.mark.parametrize("name", ["cube-meshed.loop_semisharp.L1", "cube-meshed.loop_semisharp.L2"])
def test_loop_semisharp_references(name):
    # OpenSubdiv computes the semi-sharp transition weights in single precision
    check_reference(name, tol=1e-9)
