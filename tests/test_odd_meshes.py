"""Odd geometry and topology: each gets a correct result or a MeshError that names it.

Catalog entries (issue 6): non-finite coordinates, degenerate faces, duplicate faces,
unreferenced vertices, non-manifold edges (error, and non_manifold="cut"), bow-tie vertices,
inconsistent orientation (error, Möbius strip cut), several components, isolated triangles.
The handling of each is documented in docs/errors.md.
"""

import numpy as np
import pytest
import scipy.sparse as sp

import hybridsub
from hybridsub import MeshError

import strategies as ms

SCHEMES = ["hybrid", "loop", "sqrt3"]


def check_result(V, F, V2, F2, S, n_out=None):
    """The output is a valid mesh, S has one column per input vertex and reproduces V2."""
    ms.check_mesh(V2.astype(np.float64), F2)
    assert S.shape == (len(V2), len(V) if n_out is None else n_out)
    assert np.allclose(S @ V, V2, rtol=0, atol=1e-12)
    assert np.allclose(np.asarray(S.sum(axis=1)).ravel(), 1.0, rtol=0, atol=1e-12)
    assert S.data.min() >= 0


# ----------------------------------------------------------------- geometry


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_coordinate_names_the_vertex(bad):
    V, F = ms.octahedron()
    V[3, 1] = bad
    V[5, 0] = bad
    with pytest.raises(MeshError, match=r"vertex 3 has a non-finite coordinate \[0.0, .*\] \(2 such vertices\)"):
        hybridsub.subdivide(V, F)


def test_non_finite_unused_vertex_is_still_refused():
    V, F = ms.octahedron()
    V = np.vstack([V, [np.nan, 0, 0]])
    with pytest.raises(MeshError, match="vertex 6 has a non-finite"):
        hybridsub.subdivide(V, F)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_zero_area_faces_are_subdivided(scheme):
    # Decision: a face with three distinct but collinear (or coincident) vertices has zero area
    # and is subdivided like any other: the rules are affine, so it is well defined.
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 1, 0], [1, 1, 0]])
    F = np.array([[0, 1, 3], [1, 2, 3], [0, 2, 1], [2, 4, 3]])  # (0, 2, 1) collinear, 3 == 4 coincide
    V2, F2, S = hybridsub.subdivide(V, F, levels=2, scheme=scheme, return_matrix=True)
    check_result(V, F, V2, F2, S)
    assert np.isfinite(V2).all()


def test_repeated_vertex_face_is_refused():
    # Decision: a face (a, a, b) has no area and makes an edge from a vertex to itself, which
    # no rule defines; it adds nothing to the surface, so it is refused with the fix.
    V, F = ms.octahedron()
    F = np.vstack([F, [[4, 4, 2]], [[1, 0, 1]]])
    with pytest.raises(MeshError, match=r"face 8 = \[4, 4, 2\] repeats a vertex \(a degenerate face with 2 "
                                        r"like it\).*nondegenerate_faces"):
        hybridsub.subdivide(V, F)


@pytest.mark.parametrize("rotate", [0, 1, 2])
@pytest.mark.parametrize("flip, how", [(False, "the same"), (True, "opposite")])
def test_duplicate_face_in_a_mesh(rotate, flip, how):
    V, F = ms.icosahedron()
    dup = np.roll(F[7], rotate)
    if flip:
        dup = dup[::-1]
    G = np.insert(F, 11, dup, axis=0)  # face 7 is repeated as face 11
    with pytest.raises(MeshError, match=rf"faces 7 and 11 are duplicate faces: both are the triangle on "
                                        rf"vertices \[{', '.join(map(str, sorted(F[7])))}\], with {how} "
                                        r"orientation \(1 duplicate face in all\).*unique_faces"):
        hybridsub.subdivide(V, G)


@pytest.mark.parametrize("non_manifold", ["raise", "cut"])
def test_duplicate_faces_alone_pillow(non_manifold):
    # A triangle and its reverse make a closed two-face "pillow" that is topologically valid;
    # it is still a duplicate face and refused, with either non_manifold setting.
    V, F = ms.single_triangle()
    G = np.vstack([F, F[:, ::-1], F + 3, (F + 3)[:, ::-1]])
    with pytest.raises(MeshError, match=r"faces 0 and 1 are duplicate faces.*opposite orientation "
                                        r"\(2 duplicate faces in all\)"):
        hybridsub.subdivide(np.vstack([V, V]), G, non_manifold=non_manifold)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_unreferenced_vertices_are_kept_and_do_not_move(scheme):
    V, F = ms.octahedron()
    # unused vertices at the start, in the middle and at the end of the index range
    extra = np.array([[9.0, 9, 9], [-7, 3, 1], [0.5, 0.25, 2]])
    W = np.vstack([extra[:1], V[:3], extra[1:2], V[3:], extra[2:]])
    remap = np.array([1, 2, 3, 5, 6, 7])
    G = remap[F]
    V2, F2, S = hybridsub.subdivide(W, G, levels=3, scheme=scheme, return_matrix=True)
    for i in (0, 4, 8):
        assert np.array_equal(V2[i], W[i])
        assert S[i].nnz == 1 and S[i, i] == 1.0
        assert not np.isin(i, F2)
    # the rest is exactly the subdivision without them
    V3, F3 = hybridsub.subdivide(V, F, levels=3, scheme=scheme)
    used = np.unique(F2)
    assert len(used) == len(V3)
    assert np.allclose(np.sort(V2[used], axis=0), np.sort(V3, axis=0), rtol=0, atol=1e-14)


# ----------------------------------------------------------------- non-manifold edges


def book(pages=3):
    """``pages`` triangles on the edge (0, 1), alternately oriented: a non-manifold edge."""
    V = [[0.0, 0, 0], [1, 0, 0]]
    F = []
    for k in range(pages):
        a = 2 * np.pi * k / pages
        V.append([0.5, np.cos(a), np.sin(a)])
        F.append([0, 1, 2 + k] if k % 2 == 0 else [1, 0, 2 + k])
    return np.array(V), np.array(F)


def fin_on_plane():
    """A 2×2 grid in z = 0 and a fin standing on its middle line x ∈ [0, 2], y = 1."""
    V, F = ms.grid(2, 2, np.zeros((2, 2), bool))
    mid = [1, 4, 7]  # (0, 1), (1, 1), (2, 1)
    top = len(V) + np.arange(3)
    V = np.vstack([V, V[mid] + [0, 0, 1]])
    fin = [[mid[0], mid[1], top[1]], [mid[0], top[1], top[0]], [mid[1], mid[2], top[2]],
           [mid[1], top[2], top[1]]]
    return V, np.vstack([F, fin])


def test_non_manifold_edge_names_edge_and_faces():
    V, F = book(4)
    with pytest.raises(MeshError, match=r"edge \(0, 1\) is shared by 4 faces \[0, 1, 2, 3\]: the mesh is not "
                                        r"edge-manifold.*non_manifold=\"cut\""):
        hybridsub.subdivide(V, F)
    V, F = fin_on_plane()
    with pytest.raises(MeshError, match=r"edge \(1, 4\) is shared by 3 faces \[1, 2, 8\].*2 such edges in all"):
        hybridsub.refine(F)
    # also with levels=0: the same input gets the same answer
    with pytest.raises(MeshError, match="shared by 3 faces"):
        hybridsub.subdivide(V, F, levels=0)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("levels", [1, 2, 3])
def test_cut_gives_a_valid_result_on_the_callers_vertices(scheme, levels):
    for V, F in (book(3), book(5), fin_on_plane()):
        r = hybridsub.refine(F, levels=levels, scheme=scheme, non_manifold="cut")
        V2, F2, S = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, non_manifold="cut",
                                        return_matrix=True)
        check_result(V, F, V2, F2, S)
        assert r.n_coarse == len(V) and r.steps[0].matrix.shape[1] == len(V)
        assert np.array_equal(r.apply(V), V2) and np.array_equal(r.faces, F2)
        assert np.array_equal(np.unique(r.face_parent), np.arange(len(F)))
        # every input vertex keeps its index; copies come after them
        assert np.isin(np.arange(len(V)), F2).all()


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_cut_copies_stay_together(scheme):
    # In hybrid and loop the cut edges are creases and the copies move alike: the sheets stay
    # joined along the former non-manifold curve at every level.
    V, F = fin_on_plane()
    for levels in (1, 2, 3):
        V2, F2 = hybridsub.subdivide(V, F, levels=levels, scheme=scheme, non_manifold="cut")
        # points on the line y = 1, z = 0 (the cut): each is there three times (two plane halves, fin)
        on_cut = np.flatnonzero((np.abs(V2[:, 1] - 1) < 1e-12) & (np.abs(V2[:, 2]) < 1e-12))
        pts, counts = np.unique(V2[on_cut].round(12), axis=0, return_counts=True)
        assert len(pts) == 2 ** (levels + 1) + 1 and (counts == 3).all()
        # the cut curve is the crease curve: ends fixed (corners), middle a cubic B-spline
        assert np.array_equal(pts[[0, -1], 0], [0.0, 2.0])
    # endpoints of the non-manifold curve are corners; its inner vertex (4) is a crease vertex
    r = hybridsub.refine(F, levels=1, scheme=scheme, non_manifold="cut")
    assert {1, 7} <= set(r.corners.tolist()) and 4 not in r.corners


def test_cut_matches_the_mesh_cut_by_hand():
    # Cutting by hand (duplicate the vertices, make them corners as the docs say) and refining
    # gives the same positions as non_manifold="cut".
    V, F = book(3)
    Fc = np.array([[0, 1, 2], [6, 5, 3], [7, 8, 4]])  # 0,1 copied as 5,6 (page 1) and 7,8 (page 2)
    Vc = np.vstack([V, V[[0, 1, 0, 1]]])
    for scheme in ("hybrid", "loop"):
        want = hybridsub.subdivide(Vc, Fc, levels=2, scheme=scheme, corners=[0, 1, 5, 6, 7, 8])[0]
        got, F2 = hybridsub.subdivide(V, F, levels=2, scheme=scheme, non_manifold="cut")
        assert np.allclose(np.sort(got, axis=0), np.sort(want, axis=0), rtol=0, atol=1e-15)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_cut_on_a_manifold_mesh_changes_nothing(scheme):
    V, F = ms.torus(5, 4)
    tags = {} if scheme == "sqrt3" else dict(sharp_edges=F[:3, :2], sharp_faces=[2, 5], corners=[0])
    a = hybridsub.subdivide(V, F, levels=2, scheme=scheme, return_matrix=True, **tags)
    b = hybridsub.subdivide(V, F, levels=2, scheme=scheme, return_matrix=True, non_manifold="cut", **tags)
    for x, y in zip(a, b):
        assert (x != y).nnz == 0 if sp.issparse(x) else np.array_equal(x, y)


def test_cut_carries_tags_to_every_copy():
    V, F = fin_on_plane()
    # crease (3, 4) in the plane next to the cut, semi-sharp (4, 10) on the fin, a sharp fin face
    r = hybridsub.refine(F, [[3, 4], [10, 4]], levels=1, sharpness=[np.inf, 0.5], sharp_faces=[8],
                         corners=[6], non_manifold="cut")
    # input vertex 4 (on both cut edges, but also on a tagged crease) is a corner; 6 stays one
    assert {4, 6} <= set(r.corners.tolist())
    # (3, 4) lies in one sector of 4; its children are tagged
    assert len(r.sharp_edges) == 2 and np.isinf(r.sharpness).all()
    with pytest.raises(MeshError, match=r"sharp edge 0 = \[3, 10\] is not an edge"):
        hybridsub.refine(F, [[3, 10]], non_manifold="cut")


def test_cut_levels_zero_is_the_input():
    V, F = fin_on_plane()
    r = hybridsub.refine(F, [[3, 4]], levels=0, corners=[6], non_manifold="cut")
    assert np.array_equal(r.faces, F) and r.n_vertices == len(V) and r.steps == []
    assert r.sharp_edges.tolist() == [[3, 4]] and r.corners.tolist() == [6]
    V2, F2 = hybridsub.subdivide(V, F, levels=0, non_manifold="cut")
    assert np.array_equal(V2, V) and np.array_equal(F2, F)


# ----------------------------------------------------------------- orientation


def mobius(n=8):
    """A Möbius strip: n quads around a circle, the last one joined with a half twist."""
    t = 2 * np.pi * np.arange(n) / n
    c, s = np.cos(t), np.sin(t)
    w = 0.3 * np.cos(t / 2)
    h = 0.3 * np.sin(t / 2)
    inner = np.stack([c * (1 - w), s * (1 - w), -h], axis=1)
    outer = np.stack([c * (1 + w), s * (1 + w), h], axis=1)
    V = np.vstack([inner, outer])  # i: inner i, n + i: outer i
    F = []
    for i in range(n):
        a, b = i, n + i
        if i < n - 1:
            c_, d = i + 1, n + i + 1
        else:  # the twist: inner meets outer
            c_, d = n, 0
        F += [[a, b, d], [a, d, c_]]
    return V, np.array(F)


def test_inconsistent_orientation_names_edge_and_fix():
    V, F = ms.octahedron()
    F = F.copy()
    F[3] = F[3][::-1]
    with pytest.raises(MeshError, match=r"faces 0 and 3 both run along edge 4->0 in the same direction: the mesh "
                                        r"is not consistently oriented; 3 such edges in all.*fix_winding.*bfs_orient"):
        hybridsub.subdivide(V, F)


def test_mobius_strip_cannot_be_oriented_but_can_be_cut():
    V, F = mobius()
    assert not ms.is_consistently_oriented(F) and ms.is_edge_manifold(F)
    with pytest.raises(MeshError, match="same direction.*Möbius strip.*non_manifold=\"cut\""):
        hybridsub.subdivide(V, F)
    for scheme in SCHEMES:
        V2, F2, S = hybridsub.subdivide(V, F, levels=2, scheme=scheme, non_manifold="cut", return_matrix=True)
        check_result(V, F, V2, F2, S)


# ----------------------------------------------------------------- bow-ties, components, isolated faces


@pytest.mark.parametrize("scheme", SCHEMES)
def test_bowtie_of_two_open_fans(scheme):
    # Two triangles sharing only vertex 0: allowed. Vertex 0 has four boundary edges, hence is
    # a corner in hybrid and loop (it does not move); sqrt3 follows each fan's boundary.
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [-1, 0, 0], [-1, -1, 0.5]])
    F = np.array([[0, 1, 2], [0, 3, 4]])
    V2, F2, S = hybridsub.subdivide(V, F, levels=3, scheme=scheme, return_matrix=True)
    check_result(V, F, V2, F2, S)
    assert ms.bowtie_vertices(F2) == [0]
    if scheme != "sqrt3":
        assert np.array_equal(V2[0], V[0])


@pytest.mark.parametrize("scheme", SCHEMES)
def test_bowtie_of_two_closed_surfaces(scheme):
    # Two tetrahedra sharing one vertex: allowed; the shared vertex follows the smooth rule
    # over all its neighbours (both fans), and stays shared.
    V, F = ms.tetrahedron()
    V2_ = V + [2.0, 0, 0]
    G = np.vstack([F, np.where(F == 0, 0, F + 3)])
    W = np.vstack([V, V2_[1:]])
    out, F2, S = hybridsub.subdivide(W, G, levels=2, scheme=scheme, return_matrix=True)
    check_result(W, G, out, F2, S)
    assert ms.bowtie_vertices(F2) == [0]


@pytest.mark.parametrize("scheme", SCHEMES)
def test_components_are_subdivided_independently(scheme):
    parts = [ms.octahedron(), ms.single_triangle(), ms.grid(2, 3, np.eye(2, 3, dtype=bool)),
             ms.fan(64, closed=True)]
    V, F = ms.combine(parts)
    V2, F2, S = hybridsub.subdivide(V, F, levels=2, scheme=scheme, return_matrix=True)
    check_result(V, F, V2, F2, S)
    pieces = []
    off = 0
    for P, Q in parts:
        Vp = V[off:off + len(P)]
        pieces.append(hybridsub.subdivide(Vp, Q, levels=2, scheme=scheme)[0])
        off += len(P)
    assert np.allclose(np.sort(V2, axis=0), np.sort(np.vstack(pieces), axis=0), rtol=0, atol=1e-13)


def test_isolated_triangle_worked_example():
    # docs/scheme.md, "Worked example": a face with three boundary edges, valence-2 vertices
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    V2, F2 = hybridsub.subdivide(V, [[0, 1, 2]])
    assert F2.tolist() == [[6, 0, 3], [6, 3, 1], [6, 1, 4], [6, 4, 2], [6, 2, 5], [6, 5, 0]]
    want = [3 / 4 * V[0] + (V[1] + V[2]) / 8, 3 / 4 * V[1] + (V[0] + V[2]) / 8, 3 / 4 * V[2] + (V[0] + V[1]) / 8,
            (V[0] + V[1]) / 2, (V[1] + V[2]) / 2, (V[2] + V[0]) / 2, V.mean(axis=0)]
    assert np.allclose(V2, want, rtol=0, atol=1e-15)
    V2, F2 = hybridsub.subdivide(V, [[0, 1, 2]], scheme="sqrt3")
    assert F2.tolist() == [[3, 0, 1], [3, 1, 2], [3, 2, 0]]
    assert np.array_equal(V2[:3], V)
    for scheme in SCHEMES:
        V2, F2, S = hybridsub.subdivide(V, [[0, 1, 2]], levels=4, scheme=scheme, return_matrix=True)
        check_result(V, [[0, 1, 2]], V2, F2, S)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_many_isolated_triangles(scheme):
    V, F = ms.combine([ms.single_triangle()] * 5)
    V2, F2, S = hybridsub.subdivide(V, F, levels=2, scheme=scheme, return_matrix=True)
    check_result(V, F, V2, F2, S)


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("closed", [True, False])
def test_valence_64(scheme, closed):
    V, F = ms.fan(64, closed=closed, height=0.5)
    V2, F2, S = hybridsub.subdivide(V, F, levels=2, scheme=scheme, return_matrix=True)
    check_result(V, F, V2, F2, S)
