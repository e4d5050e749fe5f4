"""Bad input gets a clear error, odd-but-valid input a correct result; the caller's arrays are
never modified. One test per entry of the issue's catalog (shapes, types, tags, options);
docs/errors.md lists the same errors."""

import re

import numpy as np
import pytest

import hybridsub
from hybridsub import MeshError

import strategies as ms


def square():
    """Two triangles sharing edge (0, 2), plus vertex 4 that no face uses."""
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [5, 5, 5]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    return V, F


def test_imports_worktree():
    # the tests exercise this checkout, not an installed copy
    import os

    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    assert os.path.dirname(os.path.dirname(os.path.abspath(hybridsub.__file__))) == here


# ----------------------------------------------------------------- V: shape and type


def test_V_two_columns_says_so():
    V, F = square()
    with pytest.raises(MeshError, match=r"V must have shape \(n, 3\), got \(5, 2\).*2-D points.*zero z"):
        hybridsub.subdivide(V[:, :2], F)


@pytest.mark.parametrize("V", [np.zeros(15), np.zeros((5, 4)), np.zeros((5, 3, 1))])
def test_V_wrong_shape(V):
    with pytest.raises(MeshError, match=re.escape(f"V must have shape (n, 3), got {V.shape}")):
        hybridsub.subdivide(V, square()[1])


@pytest.mark.parametrize("V", [np.zeros((5, 3), complex), np.zeros((5, 3), bool), np.full((5, 3), "0"),
                               np.array([[None] * 3] * 5)])
def test_V_wrong_dtype(V):
    with pytest.raises(TypeError, match="V must be a real numeric array"):
        hybridsub.subdivide(V, square()[1])


def test_V_ragged_list():
    with pytest.raises(MeshError, match=r"V must have shape \(n, 3\).*vertex 1 has 2 entries"):
        hybridsub.subdivide([[0, 0, 0], [1, 0], [0, 1, 0]], [[0, 1, 2]])


@pytest.mark.parametrize("dtype", [np.float32, np.float16, np.float64, np.longdouble])
def test_V_float_dtype_kept_computed_in_float64(dtype):
    V, F = square()
    V2, F2 = hybridsub.subdivide(V.astype(dtype), F, levels=2)
    ref, _ = hybridsub.subdivide(V.astype(dtype).astype(np.float64), F, levels=2)
    assert V2.dtype == dtype
    # computed in float64 from the caller's values, rounded once at the end
    assert np.array_equal(V2, ref.astype(dtype))


@pytest.mark.parametrize("dtype", [np.int32, np.int64, np.uint8])
def test_V_integer_positions_give_float64(dtype):
    V, F = square()
    V2, _ = hybridsub.subdivide(V.astype(dtype), F)
    assert V2.dtype == np.float64
    assert np.array_equal(V2, hybridsub.subdivide(V.astype(dtype).astype(float), F)[0])


# ----------------------------------------------------------------- F: shape and type


def test_F_quads_point_to_triangulation():
    V, _ = square()
    with pytest.raises(MeshError, match=r"got \(1, 4\).*triangulate polygons first"):
        hybridsub.subdivide(V, [[0, 1, 2, 3]])


def test_F_mixed_polygons_point_to_triangulation():
    V, _ = square()
    with pytest.raises(MeshError, match="face 1 has 4 entries.*triangulate"):
        hybridsub.subdivide(V, [[0, 1, 2], [0, 2, 3, 4]])


@pytest.mark.parametrize("F", [np.array([0, 1, 2]), np.array([[0, 1], [1, 2]]), np.zeros((1, 3, 1), int)])
def test_F_wrong_shape(F):
    with pytest.raises(MeshError, match=r"F must have shape \(m, 3\)"):
        hybridsub.subdivide(square()[0], F)


@pytest.mark.parametrize("F, what", [(np.ones((2, 3), bool), "boolean"), (np.full((2, 3), "1"), "dtype <U1"),
                                     (np.ones((2, 3), complex), "dtype complex128")])
def test_F_wrong_dtype(F, what):
    with pytest.raises(TypeError, match=f"F must .*{what}"):
        hybridsub.subdivide(square()[0], F)


@pytest.mark.parametrize("bad, why", [(0.5, r"integer vertex indices; face 1 is \[0.0, 2.0, 3.5\]"),
                                      (np.nan, "integer vertex indices; face 1"),
                                      (np.inf, "integer vertex indices; face 1")])
def test_F_non_integer(bad, why):
    V, F = square()
    G = F.astype(float)
    G[1, 2] = 3 + bad if bad == 0.5 else bad
    with pytest.raises(MeshError, match=why):
        hybridsub.subdivide(V, G)


def test_F_float_holding_integers_is_fine():
    V, F = square()
    a = hybridsub.subdivide(V, F.astype(np.float32), levels=2)
    b = hybridsub.subdivide(V, F, levels=2)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]) and a[1].dtype == np.int64


@pytest.mark.parametrize("dtype", [np.int8, np.int16, np.int32, np.uint32, np.int64, np.uint64])
def test_F_integer_dtypes(dtype):
    V, F = square()
    a = hybridsub.subdivide(V, F.astype(dtype), levels=2)
    b = hybridsub.subdivide(V, F, levels=2)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1]) and a[1].dtype == np.int64


def test_F_negative_index():
    V, F = square()
    with pytest.raises(MeshError, match=r"face 1 = \[0, -2, 3\] has a negative vertex index"):
        hybridsub.subdivide(V, [[0, 1, 2], [0, -2, 3]])


@pytest.mark.parametrize("F", [[[0, 1, 2], [0, 2, 5]], np.array([[0, 1, 2], [0, 2, 5]], np.uint64)])
def test_F_index_out_of_range(F):
    V, _ = square()
    with pytest.raises(MeshError, match=r"face 1 = \[0, 2, 5\] refers to vertex 5, but there are only 5 "
                                        r"vertices \(valid indices 0..4\)"):
        hybridsub.subdivide(V, F)


def test_F_huge_indices():
    V, _ = square()
    for F in (np.array([[0, 1, 2**64 - 1]], np.uint64), np.array([[0, 1, 1e30]])):
        with pytest.raises(MeshError, match="face 0 .* refers to vertex"):
            hybridsub.subdivide(V, F)
    with pytest.raises(MeshError, match="face 0 .* too large an index"):
        hybridsub.refine(np.array([[0, 1, 2**63 - 1]]))


# ----------------------------------------------------------------- arrays in odd forms


def test_lists_instead_of_arrays():
    V, F = square()
    a = hybridsub.subdivide(V.tolist(), F.tolist(), [[0, 2]], 2, sharp_faces=[1], corners=[1])
    b = hybridsub.subdivide(V, F, np.array([[0, 2]]), 2, sharp_faces=np.array([1]), corners=np.array([1]))
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


def test_tuples_and_nested_tuples():
    V, F = square()
    a = hybridsub.subdivide(tuple(map(tuple, V)), tuple(map(tuple, F)), ((2, 0),), 1)
    b = hybridsub.subdivide(V, F, [[0, 2]], 1)
    assert np.array_equal(a[0], b[0])


def test_non_contiguous_and_read_only_inputs():
    V, F = square()
    big_V = np.zeros((5, 6))
    big_V[:, ::2] = V
    Vs = big_V[:, ::2]  # strided view
    Ff = np.asfortranarray(F)
    E = np.array([[0, 2, 9], [9, 9, 9]])[:1, :2]
    sf = np.array([True, True, False, False])[::2]
    for a in (Vs, Ff, E, sf, big_V):
        a.flags.writeable = False
    got = hybridsub.subdivide(Vs, Ff, E, 2, sharp_faces=sf)
    want = hybridsub.subdivide(V, F, [[0, 2]], 2, sharp_faces=[True, False])
    assert not Vs.flags.c_contiguous and not Ff.flags.c_contiguous
    assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])


def _arrays_of(call):
    return [np.array(x, copy=True) for x in call]


@pytest.mark.parametrize("scheme", ["hybrid", "loop", "sqrt3"])
@pytest.mark.parametrize("levels", [0, 1, 2])
def test_callers_arrays_never_modified(scheme, levels):
    V, F = ms.octahedron()
    V = V.astype(np.float32)
    tags = {} if scheme == "sqrt3" else dict(
        sharp_edges=np.array([[0, 2], [4, 0]]), sharpness=np.array([0.5, 20.0]),
        sharp_faces=np.array([True] + [False] * 7), corners=np.array([5]))
    before = _arrays_of([V, F] + list(tags.values()))
    V2, F2, S = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, return_matrix=True, **tags)
    r = hybridsub.refine(F, levels=levels, scheme=scheme, **{k: v for k, v in tags.items()})
    X = np.random.default_rng(0).normal(size=(len(V), 2))
    Xc = X.copy()
    Y = r.apply(X)
    after = [V, F] + list(tags.values())
    for a, b in zip(before, after):
        assert np.array_equal(a, b)
    assert np.array_equal(X, Xc)
    # results never share memory with the inputs (levels=0 included: copies)
    for out in (V2, F2, Y, r.faces, r.sharp_edges, r.sharpness, r.sharp_faces, r.corners):
        for inp in after + [X]:
            assert not np.shares_memory(out, inp)


def test_levels_zero_returns_copies():
    V, F = square()
    V2, F2 = hybridsub.subdivide(V, F, levels=0)
    assert np.array_equal(V2, V) and np.array_equal(F2, F)
    V2[:] = 7
    F2[:] = 0
    assert V[0, 0] == 0 and F[1, 2] == 3
    r = hybridsub.refine(F, levels=0)
    assert r.steps == [] and r.n_vertices == 4 and r.matrix.shape == (4, 4)
    X = np.ones((4, 2))
    assert r.apply(X) is not X and not np.shares_memory(r.apply(X), X)


def test_empty_mesh():
    for V, F in [(np.empty((0, 3)), np.empty((0, 3), int)), ([], [])]:
        for levels in (0, 1, 3):
            V2, F2, S = hybridsub.subdivide(V, F, levels=levels, return_matrix=True)
            assert V2.shape == (0, 3) and F2.shape == (0, 3) and S.shape == (0, 0)
    # vertices without faces are kept and do not move
    V = np.array([[1.0, 2, 3], [4, 5, 6]])
    V2, F2 = hybridsub.subdivide(V, np.empty((0, 3), int), levels=2)
    assert np.array_equal(V2, V) and F2.shape == (0, 3)
    r = hybridsub.refine([], levels=2)
    assert r.faces.shape == (0, 3) and r.n_vertices == 0


# ----------------------------------------------------------------- levels and options


@pytest.mark.parametrize("levels", [-1, -10])
def test_levels_negative(levels):
    with pytest.raises(ValueError, match=f"levels must be a non-negative integer, got {levels}"):
        hybridsub.subdivide(*square(), levels=levels)


@pytest.mark.parametrize("levels", [1.5, 2.0, "1", None, True, [1]])
def test_levels_not_an_integer(levels):
    with pytest.raises(TypeError, match="levels must be a non-negative integer"):
        hybridsub.subdivide(*square(), levels=levels)


def test_levels_numpy_integer_is_fine():
    a = hybridsub.subdivide(*square(), levels=np.int32(2))
    b = hybridsub.subdivide(*square(), levels=2)
    assert np.array_equal(a[0], b[0])


@pytest.mark.parametrize("kw, match", [
    (dict(scheme="catmull-clark"), "scheme must be one of"),
    (dict(scheme=None), "scheme must be one of"),
    (dict(loop_weights="stam"), "loop_weights must be one of"),
    (dict(non_manifold="ignore"), "non_manifold must be one of"),
    (dict(non_manifold=None), "non_manifold must be one of"),
    (dict(max_memory=-5), "max_memory must be a non-negative"),
    (dict(max_memory="lots"), "max_memory must be a number of bytes or a string"),
])
def test_bad_options(kw, match):
    with pytest.raises(ValueError, match=match) as ei:
        hybridsub.subdivide(*square(), **kw)
    assert not isinstance(ei.value, MeshError)


@pytest.mark.parametrize("n, err, match", [(2.0, TypeError, "n_vertices must be a non-negative integer"),
                                           (True, TypeError, "n_vertices"),
                                           (-1, ValueError, "n_vertices must be a non-negative integer"),
                                           (3, MeshError, "refers to vertex 3, but there are only 3")])
def test_refine_n_vertices(n, err, match):
    with pytest.raises(err, match=match):
        hybridsub.refine([[0, 1, 2], [0, 2, 3]], n_vertices=n)


# ----------------------------------------------------------------- tags


def test_sharp_edge_not_in_mesh():
    with pytest.raises(MeshError, match=r"sharp edge 1 = \[1, 3\] is not an edge of the mesh: no face has "
                                        r"both vertex 1 and vertex 3"):
        hybridsub.subdivide(*square(), [[0, 2], [1, 3]])


def test_sharp_edge_not_in_mesh_also_for_levels_zero():
    with pytest.raises(MeshError, match="not an edge of the mesh"):
        hybridsub.subdivide(*square(), [[1, 3]], levels=0)


def test_sharp_edge_self_loop():
    with pytest.raises(MeshError, match=r"sharp edge 0 = \[2, 2\] is not an edge.*joins vertex 2 to itself"):
        hybridsub.subdivide(*square(), [[2, 2]])


def test_sharp_edge_to_unused_vertex():
    with pytest.raises(MeshError, match=r"sharp edge 0 = \[0, 4\] is not an edge"):
        hybridsub.subdivide(*square(), [[0, 4]])


def test_sharp_edges_duplicates_and_both_orientations_are_fine():
    V, F = square()
    one = hybridsub.subdivide(V, F, [[0, 2]], 2, return_matrix=True)
    for E in ([[0, 2], [2, 0]], [[2, 0], [2, 0], [0, 2]]):
        got = hybridsub.subdivide(V, F, E, 2, return_matrix=True)
        assert np.array_equal(got[0], one[0]) and np.array_equal(got[1], one[1])
    # duplicates with different sharpness: the largest counts
    a = hybridsub.subdivide(V, F, [[0, 2], [2, 0]], 2, sharpness=[0.3, 1.5])[0]
    b = hybridsub.subdivide(V, F, [[0, 2]], 2, sharpness=[1.5])[0]
    assert np.array_equal(a, b)


@pytest.mark.parametrize("E, err, match", [
    ([[0, 7]], MeshError, r"sharp edge 0 = \[0, 7\] refers to a vertex outside 0..4"),
    ([[-1, 2]], MeshError, r"sharp edge 0 = \[-1, 2\] refers to a vertex outside"),
    ([0, 2], MeshError, r"sharp_edges must have shape \(k, 2\)"),
    ([[0, 1, 2]], MeshError, r"sharp_edges must have shape \(k, 2\)"),
    ([[0.5, 2]], MeshError, r"integer vertex indices; sharp edge 0 is \[0.5, 2.0\]"),
    ([["a", "b"]], TypeError, "sharp_edges must hold integer vertex indices"),
    ([[True, False]], TypeError, "sharp_edges must hold integer vertex indices"),
    ([[0, 2], [1]], MeshError, "sharp_edges must have shape .*row 1 has 1 entries"),
])
def test_sharp_edges_malformed(E, err, match):
    with pytest.raises(err, match=match):
        hybridsub.subdivide(*square(), E)


def test_sharp_edges_float_holding_integers_is_fine():
    V, F = square()
    a = hybridsub.subdivide(V, F, np.array([[0.0, 2.0]]))[0]
    assert np.array_equal(a, hybridsub.subdivide(V, F, [[0, 2]])[0])


@pytest.mark.parametrize("s, err, match", [
    ([1.0, 2.0], MeshError, r"sharpness must have one value per sharp edge \(1\), got 2"),
    ([np.nan], MeshError, r"sharpness 0 \(of sharp edge \[0, 2\]\) is NaN; give a number"),
    ([-3.0], MeshError, r"sharpness 0 \(of sharp edge \[0, 2\]\) is negative \(-3\); give 0 for no crease"),
    ([-np.inf], MeshError, r"sharpness 0 \(of sharp edge \[0, 2\]\) is negative \(-inf\)"),
    (["x"], TypeError, "sharpness must be real numbers"),
    ([1j], TypeError, "sharpness must be real numbers"),
])
def test_sharpness_malformed(s, err, match):
    with pytest.raises(err, match=match):
        hybridsub.subdivide(*square(), [[0, 2]], sharpness=s)


def test_sharpness_without_sharp_edges():
    with pytest.raises(ValueError, match="sharpness was given without sharp_edges"):
        hybridsub.subdivide(*square(), sharpness=[1.0])


def test_sharpness_zero_and_inf():
    V, F = square()
    plain = hybridsub.subdivide(V, F, levels=2)[0]
    for s in (0.0, -0.0):
        assert np.array_equal(hybridsub.subdivide(V, F, [[0, 2]], 2, sharpness=[s])[0], plain)
    sharp = hybridsub.subdivide(V, F, [[0, 2]], 2)[0]
    for s in (np.inf, 10.0, 1e300):
        assert np.array_equal(hybridsub.subdivide(V, F, [[0, 2]], 2, sharpness=[s])[0], sharp)


@pytest.mark.parametrize("sf, err, match", [
    ([0, 2], MeshError, r"sharp_faces\[1\] = 2 is not a face index \(valid 0..1\)"),
    ([-1], MeshError, r"sharp_faces\[0\] = -1 is not a face index"),
    ([True], MeshError, r"sharp_faces as a boolean mask must have one entry per face, shape \(2,\), got \(1,\)"),
    ([True, False, True], MeshError, "one entry per face"),
    ([[0, 1]], MeshError, "sharp_faces must be a 1-D array"),
    ([0.5], MeshError, r"integer face indices; sharp_faces\[0\] is 0.5"),
    (["0"], TypeError, "sharp_faces must hold integer face indices"),
])
def test_sharp_faces_malformed(sf, err, match):
    with pytest.raises(err, match=match):
        hybridsub.subdivide(*square(), sharp_faces=sf)


def test_sharp_faces_mask_or_indices_give_the_same():
    V, F = square()
    a = hybridsub.refine(F, levels=2, sharp_faces=[True, False])
    b = hybridsub.refine(F, levels=2, sharp_faces=[0, 0])  # duplicates are fine
    assert np.array_equal(a.faces, b.faces) and np.array_equal(a.apply(V[:4]), b.apply(V[:4]))
    assert a.sharp_faces.dtype == bool and b.sharp_faces.dtype == np.int64


@pytest.mark.parametrize("c, err, match", [
    ([5], MeshError, r"corners\[0\] = 5 is not a vertex index \(valid 0..4\)"),
    ([-1], MeshError, r"corners\[0\] = -1 is not a vertex index"),
    ([True, False], MeshError, r"corners as a boolean mask must have one entry per vertex, shape \(5,\)"),
    ([1.5], MeshError, r"corners\[0\] is 1.5"),
    ([1j], TypeError, "corners must hold integer vertex indices"),
])
def test_corners_malformed(c, err, match):
    with pytest.raises(err, match=match):
        hybridsub.subdivide(*square(), corners=c)


@pytest.mark.parametrize("tag", [dict(sharp_edges=[[0, 2]]), dict(sharp_faces=[0]), dict(corners=[1]),
                                 dict(sharp_faces=[True, False])])
def test_feature_tags_with_sqrt3(tag):
    with pytest.raises(ValueError, match='scheme="sqrt3" is Kobbelt.*use scheme="hybrid"'):
        hybridsub.subdivide(*square(), scheme="sqrt3", **tag)


def test_empty_tags_with_sqrt3_are_fine():
    V, F = square()
    a = hybridsub.subdivide(V, F, [], scheme="sqrt3", sharp_faces=[], corners=np.zeros(5, bool))[0]
    assert np.array_equal(a, hybridsub.subdivide(V, F, scheme="sqrt3")[0])


# ----------------------------------------------------------------- Refinement.apply


def test_apply_wrong_rows():
    r = hybridsub.refine(square()[1])
    with pytest.raises(MeshError, match=r"one row per coarse vertex \(4\), got shape \(3,\)"):
        r.apply(np.zeros(3))
    with pytest.raises(MeshError, match=r"got shape \(\)"):
        r.apply(1.0)


def test_apply_dtypes():
    V, F = square()
    r = hybridsub.refine(F, levels=2)
    X = V[:4, :2]
    assert r.apply(X.astype(np.float32)).dtype == np.float32
    assert r.apply(X.astype(int)).dtype == np.float64
    assert r.apply(X > 0.5).dtype == np.float64
    Z = X[:, 0] + 1j * X[:, 1]
    got = r.apply(Z)
    assert got.dtype == np.complex128
    assert np.allclose(got, r.apply(X[:, 0]) + 1j * r.apply(X[:, 1]), rtol=0, atol=1e-15)
    assert r.apply(np.zeros((4, 2, 2))).shape == (r.n_vertices, 2, 2)
    assert r.apply(np.zeros((4, 0))).shape == (r.n_vertices, 0)
    with pytest.raises(TypeError, match="data must be numeric"):
        r.apply(np.array(["a"] * 4))
