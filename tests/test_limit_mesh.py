"""The vertex lane and ``limit_mesh``: every vertex's limit position and normal from one pass
over the rings, the rest through the general plan on the faces around them.

Oracle: the general evaluation over the whole level (``evaluate_level``: every vertex
classified, its stationary masks as sparse rows, local refinement where it has none), which
does not go through the lane's kernel. ``limit_mesh`` itself must give what ``refine``,
``limit_positions`` and ``limit_normals`` give, bit for bit.
"""

import numpy as np
import pytest
import strategies as ms
from conftest import load_mesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hybridsub
from hybridsub._surface.level_eval import evaluate_level
from hybridsub._surface.limit_setup import walk_for_limit, with_halfedges
from hybridsub._surface.normals import one_side_sectors, vertex_normals
from hybridsub._surface.vertex_lane import MAX_LANE_VALENCE, level_limits

MESHES = ["fandisk", "cube-meshed", "mesh_with_border", "elephant-with-holes", "icosahedron", "tetrahedron"]


def _load(name):
    return hybridsub.load_example(name) if name == "fandisk" else load_mesh(name)


def _general(li, X, crease_normals):
    s = with_halfedges(li)
    L, _, _ = evaluate_level(s, li.scheme, "loop", None, True, 1e-12, 60)
    _, plan, nrm = evaluate_level(s, li.scheme, "loop", X, False, 1e-10, 60)
    N = vertex_normals(s.level, plan, nrm, X)
    if crease_normals == "one_side":
        first = one_side_sectors(s.level, plan.sectors)
        used = first >= 0
        N[used] = nrm[first[used]]
    return L @ X, N


def _tags(V, F, kind):
    fe = hybridsub.detect_features(V, F, 30)
    if kind == "creases":
        return dict(sharp_edges=fe.sharp_edges, corners=fe.corners)
    if kind == "semi-sharp":
        return dict(sharp_edges=fe.sharp_edges, sharpness=np.full(len(fe.sharp_edges), 1.5))
    return {}


def _agree(li, V, crease_normals):
    X = li.X
    P, N = level_limits(li, X, "loop", True, True, crease_normals, 1e-12, 1e-10, 60)
    Pg, Ng = _general(li, X, crease_normals)
    diag = np.linalg.norm(V.max(0) - V.min(0))
    assert np.abs(P - Pg).max() <= 1e-12 * diag
    assert np.abs(N - Ng).max() <= 1e-8


@pytest.mark.parametrize("name", MESHES)
@pytest.mark.parametrize("scheme", ["hybrid", "loop", "sqrt3"])
@pytest.mark.parametrize("kind", ["creases", "semi-sharp", "none"])
def test_lane_equals_the_general_evaluation(name, scheme, kind):
    V, F = _load(name)
    tags = {} if scheme == "sqrt3" else _tags(V, F, kind)
    for levels in (0, 1, 2):  # the defaults (limit_positions', limit_mesh's), and every new vertex regular
        li = walk_for_limit(V, F, tags.get("sharp_edges"), levels, scheme, tags.get("sharpness"), None,
                            tags.get("corners"), "loop")
        for crease_normals in ("average", "one_side"):
            _agree(li, V, crease_normals)


def _fan(k, z=0.0):
    """A closed cone of ``k`` faces around vertex 0 (apex at height ``z``), capped underneath."""
    t = 2 * np.pi * np.arange(k) / k
    V = np.r_[[[0.0, 0.0, z]], np.c_[np.cos(t), np.sin(t), np.zeros(k)], [[0.0, 0.0, -1.0]]]
    ring = np.arange(1, k + 1)
    F = np.r_[np.c_[np.zeros(k, int), ring, np.roll(ring, -1)], np.c_[np.full(k, k + 1), np.roll(ring, -1), ring]]
    return V, F


def test_lane_hands_over_what_it_cannot_take():
    # Valence beyond the tables, a vertex two fans share (a bowtie), an isolated vertex.
    V, F = _fan(MAX_LANE_VALENCE + 6, z=0.3)
    li = walk_for_limit(V, F, None, 0, "loop", None, None, None, "loop")
    _agree(li, V, "average")
    V1, F1 = _fan(5, z=0.5)
    V2, F2 = _fan(7, z=-0.5)
    V = np.r_[V1, V2[1:] + [0, 0, 0.0], [[5.0, 5, 5]]]
    F2 = np.where(F2 == 0, 0, F2 + len(V1) - 1)
    F = np.r_[F1, F2[:, ::-1]]  # the two fans meet at vertex 0 only
    for scheme in ("loop", "sqrt3", "hybrid"):
        for levels in (0, 1):
            li = walk_for_limit(V, F, None, levels, scheme, None, None, None, "loop")
            _agree(li, V, "average")
    N = hybridsub.limit_normals(V, F, scheme="loop")
    assert np.all(N[-1] == 0)  # the isolated vertex
    assert np.array_equal(hybridsub.limit_positions(V, F, scheme="loop")[-1], V[-1])


@pytest.mark.parametrize("scheme", ["hybrid", "loop", "sqrt3"])
def test_limit_mesh_is_refine_and_the_limit_functions(scheme):
    V, F = _load("fandisk")
    tags = {} if scheme == "sqrt3" else _tags(V, F, "creases")
    holes = np.arange(0, len(F), 97)
    m = hybridsub.limit_mesh(V, F, scheme=scheme, holes=holes, **tags)  # default: one level, normals
    assert np.array_equal(m.faces, hybridsub.subdivide(V, F, scheme=scheme, holes=holes, **tags)[1])
    assert np.array_equal(m.vertices, hybridsub.limit_positions(V, F, levels=1, scheme=scheme, holes=holes, **tags))
    assert np.array_equal(m.normals, hybridsub.limit_normals(V, F, levels=1, scheme=scheme, holes=holes, **tags))
    one = hybridsub.limit_mesh(V, F, levels=2, scheme=scheme, crease_normals="one_side", normals=True, **tags)
    assert np.array_equal(one.normals, hybridsub.limit_normals(V, F, levels=2, scheme=scheme,
                                                               crease_normals="one_side", **tags))
    bare = hybridsub.limit_mesh(V.astype(np.float32), F, scheme=scheme, normals=False, **tags)
    assert bare.normals is None and bare.vertices.dtype == np.float32


def test_limit_mesh_bad_input():
    V, F = load_mesh("tetrahedron")
    with pytest.raises(ValueError, match="crease_normals"):
        hybridsub.limit_mesh(V, F, crease_normals="left")
    with pytest.raises(ValueError, match="tol"):
        hybridsub.limit_mesh(V, F, normal_tol=0)
    with pytest.raises(TypeError, match="normals"):
        hybridsub.limit_mesh(V, F, normals="yes")
    with pytest.raises(hybridsub.MeshError, match="vertex 9"):
        hybridsub.limit_mesh(V, [[0, 1, 9]])
    with pytest.raises(hybridsub.MeshError, match="non-finite"):
        hybridsub.limit_mesh(np.where(np.arange(len(V))[:, None] == 1, np.nan, V), F)
    with pytest.raises(ValueError):
        hybridsub.limit_mesh(V[:, :2], F)
    with pytest.raises(ValueError, match="levels"):
        hybridsub.limit_mesh(V, F, levels=-1)
    V0, F0 = V.copy(), F.copy()
    hybridsub.limit_mesh(V, F, [[0, 1]], levels=2)
    assert np.array_equal(V, V0) and np.array_equal(F, F0)


@settings(max_examples=25, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much])
@given(st.data(), st.sampled_from(["hybrid", "sqrt3", "loop"]), st.sampled_from([0, 1, 2]))
def test_lane_on_generated_tagged_meshes(data, scheme, levels):
    # Creases, semi-sharp creases, sharp faces, corners, boundaries, several pieces, high
    # valences and vertices two fans share (bowties).
    V, F, tags = data.draw(ms.tagged_meshes(bowties=True))
    if scheme == "sqrt3":
        tags = {}
    elif scheme == "loop":
        tags.pop("sharp_faces", None)
    li = walk_for_limit(V, F, tags.get("sharp_edges"), levels, scheme, tags.get("sharpness"), tags.get("sharp_faces"),
                        tags.get("corners"), "loop")
    if len(li.faces):
        _agree(li, V, data.draw(st.sampled_from(["average", "one_side"])))


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_limit_mesh_with_semi_sharp_corners(scheme):
    # Positions alone refine the semi-sharp corners' stars; with normals the whole mesh is
    # refined until their sharpness is spent: the same limit either way.
    V, F = _load("fandisk")
    fe = hybridsub.detect_features(V, F, 30)
    kw = dict(scheme=scheme, sharp_edges=fe.sharp_edges, corners=fe.corners,
              corner_sharpness=np.linspace(0.5, 3.5, len(fe.corners)))
    P = hybridsub.limit_positions(V, F, levels=1, **kw)
    bare = hybridsub.limit_mesh(V, F, normals=False, **kw)
    full = hybridsub.limit_mesh(V, F, **kw)
    assert np.array_equal(bare.vertices, P)
    assert np.abs(full.vertices - P).max() <= 1e-12 * np.linalg.norm(V.max(0) - V.min(0))
    assert np.array_equal(full.normals, hybridsub.limit_normals(V, F, levels=1, **kw))
    assert np.array_equal(full.faces, hybridsub.subdivide(V, F, **kw)[1])


def test_one_thread_and_all_give_the_same_bits():
    import numba
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("one thread only: no threaded twin to compare")
    V, F = _load("fandisk")
    tags = _tags(V, F, "creases")
    assert len(hybridsub.refine(F, levels=2, scheme="loop", **tags).apply(V)) >= 65536  # the threaded twin's size
    many = hybridsub.limit_mesh(V, F, levels=2, scheme="loop", **tags)
    try:
        hybridsub.set_threads(1)
        one = hybridsub.limit_mesh(V, F, levels=2, scheme="loop", **tags)
    finally:
        hybridsub.set_threads()
    assert np.array_equal(one.vertices, many.vertices) and np.array_equal(one.normals, many.normals)
