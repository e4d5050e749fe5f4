"""The test strategies themselves produce valid meshes and tags (no hybridsub needed)."""

import numpy as np
import pytest
from hypothesis import given, settings, HealthCheck
from hypothesis import strategies as st

import strategies as ms

SETTINGS = settings(max_examples=60, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


# ---------------------------------------------------------------- the checks themselves

def test_helpers_on_known_meshes():
    V, F = ms.tetrahedron()
    assert len(ms.edges_of(F)) == 6 and len(ms.boundary_edges(F)) == 0
    assert ms.euler(len(V), F) == 2
    assert ms.is_edge_manifold(F) and ms.is_consistently_oriented(F)
    E = ms.edges_of(F)
    assert np.all(E[:, 0] < E[:, 1])

    V, F = ms.single_triangle()
    assert ms.boundary_edges(F).tolist() == [[0, 1], [0, 2], [1, 2]]
    assert ms.euler(3, F) == 1

    # an edge in three faces
    assert not ms.is_edge_manifold(np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]]))
    # two faces traversing their common edge the same way
    assert not ms.is_consistently_oriented(np.array([[0, 1, 2], [0, 1, 3]]))
    assert ms.is_consistently_oriented(np.array([[0, 1, 2], [1, 0, 3]]))
    assert ms.has_degenerate_faces(np.array([[0, 1, 1]]))
    assert ms.has_duplicate_faces(np.array([[0, 1, 2], [1, 2, 0]]))
    # bow-tie: two triangles sharing vertex 0 only
    assert ms.bowtie_vertices(np.array([[0, 1, 2], [0, 3, 4]])) == [0]
    assert ms.bowtie_vertices(np.array([[0, 1, 2], [0, 2, 3]])) == []
    # unused vertices count in the Euler characteristic
    assert ms.euler(4, np.array([[0, 1, 2]])) == 2


@pytest.mark.parametrize("make, chi", [(ms.tetrahedron, 2), (ms.octahedron, 2),
                                       (ms.icosahedron, 2), (ms.single_triangle, 1)])
def test_fixed_meshes(make, chi):
    V, F = make()
    ms.check_mesh(V, F)
    assert ms.euler(len(V), F) == chi


def _outward(V, F):
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    c = V[F].mean(axis=1) - V.mean(axis=0)
    return np.einsum("ij,ij->i", n, c)


@pytest.mark.parametrize("make", [ms.tetrahedron, ms.octahedron, ms.icosahedron])
def test_platonic_outward(make):
    V, F = make()
    assert np.all(_outward(V, F) > 0)


def test_constructors():
    V, F = ms.grid(3, 2, np.array([[0, 1], [1, 0], [0, 0]], bool))
    ms.check_mesh(V, F)
    assert len(F) == 12 and len(V) == 12 and ms.euler(len(V), F) == 1
    V, F = ms.torus(4, 5)
    ms.check_mesh(V, F)
    assert len(ms.boundary_edges(F)) == 0 and ms.euler(len(V), F) == 0
    for k in (3, 4, 17, 64):
        V, F = ms.fan(k, closed=False)
        ms.check_mesh(V, F)
        assert len(np.unique(F[np.any(F == 0, axis=1)])) - 1 == k
        V, F = ms.fan(k, closed=True)
        ms.check_mesh(V, F)
        assert len(ms.boundary_edges(F)) == k and ms.euler(len(V), F) == 1
        V, F = ms.bipyramid(k)
        ms.check_mesh(V, F)
        assert len(ms.boundary_edges(F)) == 0 and ms.euler(len(V), F) == 2
        assert np.all(_outward(V, F) > 0)


# ---------------------------------------------------------------- strategies

def _check(V, F):
    ms.check_mesh(V, F)
    assert V.dtype == np.float64 and F.dtype == np.int64
    assert V.flags.c_contiguous and F.flags.c_contiguous
    assert 1 <= len(F) <= ms.MAX_FACES
    assert np.array_equal(np.unique(F), np.arange(len(V))), "unused vertices"


@SETTINGS
@given(ms.meshes("any"))
def test_any_meshes_valid(mesh):
    _check(*mesh)


@SETTINGS
@given(ms.meshes("closed"))
def test_closed_meshes(mesh):
    V, F = mesh
    _check(V, F)
    assert len(ms.boundary_edges(F)) == 0
    assert ms.euler(len(V), F) in (0, 2)


@SETTINGS
@given(ms.sphere_meshes())
def test_sphere_hulls_outward(mesh):
    V, F = mesh
    _check(V, F)
    assert ms.euler(len(V), F) == 2
    assert np.all(_outward(V, F) > 0)


@SETTINGS
@given(ms.meshes("open"))
def test_open_meshes(mesh):
    V, F = mesh
    _check(V, F)
    assert len(ms.boundary_edges(F)) > 0


@SETTINGS
@given(ms.open_meshes(bowties=False))
def test_open_meshes_without_bowties(mesh):
    V, F = mesh
    _check(V, F)
    assert ms.bowtie_vertices(F) == []


def test_open_meshes_can_have_bowties():
    # the strategy's removal can make bow-ties; find one deterministically
    V, F = ms.icosahedron()
    rng = np.random.default_rng(0)
    found = False
    for _ in range(50):
        V2, F2 = ms.remove_faces(V, F, rng.permutation(len(F)), 10, bowties=True)
        ms.check_mesh(V2, F2)
        found |= bool(ms.bowtie_vertices(F2))
    assert found


@SETTINGS
@given(ms.grid_meshes())
def test_grids(mesh):
    V, F = mesh
    _check(V, F)
    assert ms.euler(len(V), F) == 1


@SETTINGS
@given(ms.meshes("fan", shuffle=False))
def test_high_valence(mesh):
    V, F = mesh
    _check(V, F)
    val = len(np.unique(F[np.any(F == 0, axis=1)])) - 1
    assert 3 <= val <= 64


@SETTINGS
@given(ms.meshes("multi", shuffle=False))
def test_multi_component(mesh):
    V, F = mesh
    _check(V, F)
    import scipy.sparse as sp
    from scipy.sparse.csgraph import connected_components
    E = ms.edges_of(F)
    A = sp.coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(len(V),) * 2)
    k, _ = connected_components(A, directed=False)
    assert k >= 2


@SETTINGS
@given(ms.with_unused_vertices(ms.meshes("any")))
def test_unused_vertices(mesh):
    V, F = mesh
    ms.check_mesh(V, F)


@SETTINGS
@given(ms.meshes("any"), ms.rngs())
def test_relabel_keeps_validity(mesh, rng):
    V, F = mesh
    V2, F2 = ms.relabel(V, F, rng)
    ms.check_mesh(V2, F2)
    assert ms.euler(len(V2), F2) == ms.euler(len(V), F)
    assert np.allclose(np.sort(V2[F2].reshape(-1, 3), axis=0), np.sort(V[F].reshape(-1, 3), axis=0))


@SETTINGS
@given(st.data())
def test_tags(data):
    V, F, tags = data.draw(ms.tagged_meshes())
    ms.check_mesh(V, F)
    E = {tuple(e) for e in ms.edges_of(F)}
    if "sharp_edges" in tags:
        se = tags["sharp_edges"]
        assert se.dtype == np.int64 and se.ndim == 2 and se.shape[1] == 2
        assert all(tuple(sorted(e)) in E for e in se.tolist())
    if "sharpness" in tags:
        s = tags["sharpness"]
        assert s.shape == (len(tags["sharp_edges"]),) and np.all(s > 0)
        # duplicates carry equal sharpness
        d = {}
        for e, x in zip(map(tuple, np.sort(tags["sharp_edges"], axis=1).tolist()), s):
            assert d.setdefault(e, x) == x
    if "sharp_faces" in tags:
        sf = tags["sharp_faces"]
        if sf.dtype == bool:
            assert sf.shape == (len(F),)
        else:
            assert len(np.unique(sf)) == len(sf) and np.all((0 <= sf) & (sf < len(F)))
    if "corners" in tags:
        c = tags["corners"]
        assert len(np.unique(c)) == len(c) and np.all((0 <= c) & (c < len(V)))


def test_sharpness_mix():
    s = ms.random_sharpness(np.random.default_rng(1), 2000, "mixed")
    assert np.isinf(s).any()
    assert ((0 < s) & (s < 1)).any() and ((1 < s) & (s < 3)).any() and ((10 <= s) & np.isfinite(s)).any()
    assert (s == 1).any() and (s == 2).any()
    s0 = ms.random_sharpness(np.random.default_rng(1), 2000, "mixed0")
    assert (s0 == 0).any() and np.signbit(s0[s0 == 0]).any() and not (s0 < 0).any() and np.isinf(s0).any()
