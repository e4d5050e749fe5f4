"""subdivide_mesh: trimesh in, trimesh out, with attributes and features carried along."""

import os

import numpy as np
import pytest

import hybridsub
from conftest import DATA, load_mesh

trimesh = pytest.importorskip("trimesh")


@pytest.fixture(scope="module")
def cube():
    V, F = load_mesh("cube-meshed")
    return V, F, hybridsub.detect_features(V, F, 30)


def test_geometry_is_subdivide(cube):
    V, F, feat = cube
    mesh = trimesh.Trimesh(V, F, process=False)
    for scheme in ("hybrid", "loop"):
        out = hybridsub.subdivide_mesh(mesh, 2, scheme=scheme, sharp_edges=feat.sharp_edges, corners=feat.corners)
        V2, F2 = hybridsub.subdivide(V, F, feat.sharp_edges, 2, scheme=scheme, corners=feat.corners)
        assert np.array_equal(out.vertices, V2) and np.array_equal(out.faces, F2)
    out = hybridsub.subdivide_mesh(mesh, 1, scheme="sqrt3")
    assert np.array_equal(out.faces, hybridsub.subdivide(V, F, levels=1, scheme="sqrt3")[1])


def test_feature_angle_is_detect_features(cube):
    V, F, feat = cube
    mesh = trimesh.Trimesh(V, F, process=False)
    out = hybridsub.subdivide_mesh(mesh, 1, feature_angle=30)
    V2, _ = hybridsub.subdivide(V, F, feat.sharp_edges, 1, corners=feat.corners)
    assert np.array_equal(out.vertices, V2)
    # explicit tags and detected ones are merged
    out2 = hybridsub.subdivide_mesh(mesh, 1, feature_angle=30, sharp_edges=feat.sharp_edges[:3],
                                    corners=feat.corners[:2])
    assert np.array_equal(out2.vertices, V2)
    out3 = hybridsub.subdivide_mesh(mesh, 1, feature_angle=30, corners=[0])  # vertex 0 is no corner by angle
    assert not np.array_equal(out3.vertices, V2) and np.array_equal(out3.vertices[0], V[0])


def test_vertex_colors_follow_the_matrix(cube):
    V, F, feat = cube
    mesh = trimesh.Trimesh(V, F, process=False)
    rgb = np.clip((V - V.min(0)) / np.ptp(V, 0) * 255, 0, 255)
    colors = np.c_[rgb, np.full(len(V), 255)].astype(np.uint8)
    mesh.visual.vertex_colors = colors
    out = hybridsub.subdivide_mesh(mesh, 2, sharp_edges=feat.sharp_edges)
    r = hybridsub.refine(F, feat.sharp_edges, 2, n_vertices=len(V))
    want = np.clip(np.round(r.apply(colors.astype(float))), 0, 255).astype(np.uint8)
    assert out.visual.kind == "vertex"
    assert np.array_equal(out.visual.vertex_colors, want)
    assert np.array_equal(out.visual.vertex_colors[:len(V)][feat.corners], colors[feat.corners])  # corners stay


def test_face_colors_and_attributes_follow_the_parents(cube):
    V, F, feat = cube
    mesh = trimesh.Trimesh(V, F, process=False)
    fc = np.random.default_rng(0).integers(0, 255, (len(F), 4)).astype(np.uint8)
    mesh.visual.face_colors = fc
    mesh.face_attributes["label"] = np.arange(len(F)) % 7
    mesh.vertex_attributes["temperature"] = V[:, 0].copy()
    out = hybridsub.subdivide_mesh(mesh, 2, sharp_edges=feat.sharp_edges)
    parent = out.metadata["hybridsub"]["face_parent"]
    assert len(parent) == len(out.faces) and parent.max() < len(F)
    assert np.array_equal(out.visual.face_colors, fc[parent])
    assert np.array_equal(out.face_attributes["label"], (np.arange(len(F)) % 7)[parent])
    # a linear function of position stays that function of the refined positions (affine invariance)
    assert np.allclose(out.vertex_attributes["temperature"], out.vertices[:, 0])
    # every face lies over its parent (a √3 flip triangle straddles one of its edges): the centroid
    # of a child is within one parent edge length of the parent's centroid
    c_child = out.vertices[out.faces].mean(axis=1)
    T = V[F[parent]]
    longest = np.linalg.norm(T - np.roll(T, 1, axis=1), axis=2).max(axis=1)
    assert (np.linalg.norm(c_child - T.mean(axis=1), axis=1) < longest).all()
    shuffled = np.roll(parent, 1)
    T = V[F[shuffled]]
    assert not (np.linalg.norm(c_child - T.mean(axis=1), axis=1) < longest).all()


def test_uvs_without_seams(cube):
    """No duplicated vertices: nothing to weld, the UV index mesh is the mesh. Linear UVs are
    midpoints and centroids; smooth UVs are refined by the positions' matrix."""
    V, F, _ = cube
    uv = V[:, :2] * 0.5 + 0.25
    mesh = trimesh.Trimesh(V, F, visual=trimesh.visual.TextureVisuals(uv=uv), process=False)
    r = hybridsub.refine(F, levels=1, n_vertices=len(V), scheme="loop")
    smooth = hybridsub.subdivide_mesh(mesh, 1, scheme="loop", uv_mode="smooth")
    assert smooth.visual.kind == "texture"
    assert np.array_equal(smooth.faces, r.faces) and np.array_equal(smooth.visual.uv, r.apply(uv))
    linear = hybridsub.subdivide_mesh(mesh, 1, scheme="loop")
    assert np.array_equal(linear.faces, r.faces) and np.array_equal(linear.vertices, r.apply(V))
    E = np.sort(F[:, [0, 1]], axis=1)[:5]
    mid = linear.visual.uv[len(V):]
    for a, b in E:
        assert np.abs(mid - (uv[a] + uv[b]) / 2).max(axis=1).min() < 1e-15
    assert not np.allclose(linear.visual.uv, smooth.visual.uv)


def test_tags_travel_in_metadata(cube):
    """Subdividing the result again uses the propagated tags: 1 + 1 levels = 2 levels."""
    V, F, feat = cube
    mesh = trimesh.Trimesh(V, F, process=False)
    s = np.where(np.arange(len(feat.sharp_edges)) % 2 == 0, 1.5, np.inf)
    one = hybridsub.subdivide_mesh(mesh, 1, scheme="loop", sharp_edges=feat.sharp_edges, sharpness=s,
                                   corners=feat.corners)
    two = hybridsub.subdivide_mesh(one, 1, scheme="loop")
    V2, F2 = hybridsub.subdivide(V, F, feat.sharp_edges, 2, scheme="loop", sharpness=s, corners=feat.corners)
    assert np.array_equal(two.faces, F2) and np.allclose(two.vertices, V2, atol=1e-14)
    md = two.metadata["hybridsub"]
    assert md["levels"] == 1 and md["scheme"] == "loop"
    assert set(md) >= {"sharp_edges", "sharpness", "corners", "sharp_faces", "face_parent"}


def test_callers_mesh_is_not_modified(cube):
    V, F, feat = cube
    mesh = trimesh.Trimesh(V, F, process=False, metadata={"name": "cube"})
    mesh.visual.vertex_colors = np.tile([10, 20, 30, 255], (len(V), 1)).astype(np.uint8)
    before = (mesh.vertices.copy(), mesh.faces.copy(), mesh.visual.vertex_colors.copy(), dict(mesh.metadata))
    out = hybridsub.subdivide_mesh(mesh, 1, feature_angle=30)
    assert np.array_equal(mesh.vertices, before[0]) and np.array_equal(mesh.faces, before[1])
    assert np.array_equal(mesh.visual.vertex_colors, before[2])
    assert mesh.metadata == before[3] and "hybridsub" not in mesh.metadata
    assert out.metadata["name"] == "cube"


def test_errors(cube):
    V, F, _ = cube
    with pytest.raises(TypeError, match="trimesh.Trimesh"):
        hybridsub.subdivide_mesh(trimesh.Scene(), 1)
    bad = trimesh.Trimesh(np.r_[V, [[9, 9, 9]]], np.r_[F, [[0, 1, len(V)]]], process=False)
    with pytest.raises(hybridsub.MeshError, match="shared by 3 faces.*non_manifold=\"cut\""):
        hybridsub.subdivide_mesh(bad, 1)


def test_non_manifold_cut_is_refine_with_cut(cube):
    """The hint of the error above works here too: non_manifold="cut" refines the cut mesh,
    with the caller's vertices and their colours."""
    V, F, _ = cube
    V3, F3 = np.r_[V, [[9, 9, 9]]], np.r_[F, [[0, 1, len(V)]]]
    bad = trimesh.Trimesh(V3, F3, process=False)
    bad.visual.vertex_colors = np.tile([10, 200, 30, 255], (len(V3), 1))
    fine = hybridsub.subdivide_mesh(bad, 2, non_manifold="cut")
    r = hybridsub.refine(F3, None, 2, n_vertices=len(V3), non_manifold="cut")
    np.testing.assert_array_equal(fine.faces, r.faces)
    assert np.array_equal(fine.vertices, r.apply(V3))
    assert (fine.visual.vertex_colors == [10, 200, 30, 255]).all()


# ----------------------------------------------------------------------------------------------
# textured meshes: vertices duplicated along UV seams, welded for the geometry

def charted(V, F, chart):
    """The textured trimesh of (V, F) with faces in UV charts ``chart`` (m,): one vertex copy
    per (vertex, chart), as trimesh stores a textured mesh; UVs are a projection of the
    positions shifted per chart (so every seam has different UVs on its two sides)."""
    pairs, inv = np.unique(np.stack([F.ravel(), np.repeat(chart, 3)], 1), axis=0, return_inverse=True)
    Vd = V[pairs[:, 0]]
    uv = Vd[:, :2] * 0.3 + np.c_[pairs[:, 1] * 0.5, pairs[:, 1] % 2]
    image = __import__("PIL.Image").Image.new("RGB", (4, 4), (200, 10, 10))
    visual = trimesh.visual.TextureVisuals(uv=uv, material=trimesh.visual.material.SimpleMaterial(image=image))
    return trimesh.Trimesh(Vd, inv.reshape(-1, 3), visual=visual, process=False), pairs[:, 0]


def cube_charts(V, F):
    """A chart per side of the cube: faces grouped by their normal's dominant axis and sign."""
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    axis = np.abs(N).argmax(axis=1)
    return 2 * axis + (N[np.arange(len(F)), axis] > 0)


def boundary_edge_count(F):
    he = np.sort(np.stack([F.ravel(), np.roll(F, -1, axis=1).ravel()], 1), axis=1)
    _, c = np.unique(he, axis=0, return_counts=True)
    return int((c == 1).sum())


@pytest.fixture(scope="module")
def textured_cube(cube):
    V, F, feat = cube
    mesh, origin = charted(V, F, cube_charts(V, F))
    assert len(mesh.vertices) > len(V) and len(np.unique(mesh.vertices, axis=0)) == len(V)
    return mesh, origin


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
@pytest.mark.parametrize("uv_mode", ["linear", "smooth"])
def test_textured_mesh_is_welded_and_refined_face_varying(textured_cube, scheme, uv_mode):
    """The result is subdivide_face_varying of the welded mesh, corner by corner: closed across
    the seams (no creases there), UV seams kept; same material, caller's mesh untouched."""
    mesh, origin = textured_cube
    before = (mesh.vertices.copy(), mesh.faces.copy(), mesh.visual.uv.copy(), dict(mesh.metadata))
    out = hybridsub.subdivide_mesh(mesh, 2, scheme=scheme, uv_mode=uv_mode)
    assert np.array_equal(mesh.vertices, before[0]) and np.array_equal(mesh.faces, before[1])
    assert np.array_equal(mesh.visual.uv, before[2]) and mesh.metadata == before[3]
    # the same mesh welded independently: vertex copies -> the original vertex, corners -> copies
    V, F, UV, FUV = np.asarray(load_mesh("cube-meshed")[0]), origin[mesh.faces], mesh.visual.uv, mesh.faces
    V2, F2, UV2, FUV2 = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2, scheme=scheme, uv_mode=uv_mode)
    assert np.array_equal(out.vertices[out.faces], V2[F2])  # bit for bit, corner by corner
    assert np.array_equal(out.visual.uv[out.faces], UV2[FUV2])
    assert len(out.vertices) == len(UV2) and len(np.unique(out.vertices, axis=0)) == len(V2)
    assert out.visual.material is mesh.visual.material
    # closed: welding the output by position leaves no boundary; stored as is, seams gape
    _, inv = np.unique(out.vertices, axis=0, return_inverse=True)
    assert boundary_edge_count(inv.ravel()[out.faces]) == 0
    assert boundary_edge_count(out.faces) == 2 * 2**2 * len(hybridsub.seam_edges(F, FUV))
    # weld=False refines the mesh as stored: six separate sides, each with its own boundary
    apart = hybridsub.subdivide_mesh(mesh, 2, scheme=scheme, uv_mode=uv_mode, weld=False)
    _, inv = np.unique(apart.vertices, axis=0, return_inverse=True)
    assert boundary_edge_count(inv.ravel()[apart.faces]) > 0
    assert len(np.unique(apart.vertices, axis=0)) > len(V2)


def test_textured_bunny_through_trimesh():
    """The textured scan as trimesh loads it (one vertex per (v, vt) pair): welded back, it is
    subdivide_face_varying of the OBJ's own index mesh, corner by corner."""
    d = np.load(os.path.join(DATA, "bunny10k_textured.fvar_linear.L1.npz"))
    V, F, UV, FUV = d["V_in"], d["F_in"], d["UV_in"], d["FUV_in"]
    vertex_of_uv = np.empty(len(UV), np.int64)
    vertex_of_uv[FUV.ravel()] = F.ravel()
    mesh = trimesh.Trimesh(V[vertex_of_uv], FUV, visual=trimesh.visual.TextureVisuals(uv=UV), process=False)
    out = hybridsub.subdivide_mesh(mesh, 2)
    V2, F2, UV2, FUV2 = hybridsub.subdivide_face_varying(V, F, UV, FUV, levels=2)
    assert np.array_equal(out.vertices[out.faces], V2[F2]) and np.array_equal(out.visual.uv[out.faces], UV2[FUV2])
    _, inv = np.unique(out.vertices, axis=0, return_inverse=True)
    assert boundary_edge_count(inv.ravel()[out.faces]) == boundary_edge_count(F2)  # the scan's own holes only


def test_textured_tags_and_metadata_round_trip(textured_cube, cube):
    """Tags given on any copy of a vertex are the welded vertex's; the propagated tags in the
    result's metadata name its own vertices, so 1 + 1 levels = 2 levels."""
    mesh, origin = textured_cube
    V, F, feat = cube
    copy_of = {int(v): i for i, v in enumerate(origin)}  # the last copy of each vertex
    first_of = {int(v): i for i, v in reversed(list(enumerate(origin)))}
    s = np.where(np.arange(len(feat.sharp_edges)) % 2 == 0, 1.5, np.inf)
    E1 = np.vectorize(copy_of.get)(feat.sharp_edges)
    E2 = np.vectorize(first_of.get)(feat.sharp_edges)
    assert not np.array_equal(E1, E2)
    kw = dict(sharpness=s, scheme="loop")
    a = hybridsub.subdivide_mesh(mesh, 1, sharp_edges=E1, corners=[copy_of[int(c)] for c in feat.corners], **kw)
    b = hybridsub.subdivide_mesh(mesh, 1, sharp_edges=E2, corners=[first_of[int(c)] for c in feat.corners], **kw)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.visual.uv, b.visual.uv)
    two = hybridsub.subdivide_mesh(a, 1, scheme="loop")
    ref = hybridsub.subdivide_mesh(mesh, 2, sharp_edges=E1, corners=[copy_of[int(c)] for c in feat.corners], **kw)
    assert np.array_equal(two.faces, ref.faces)
    assert np.allclose(two.vertices, ref.vertices, atol=1e-14, rtol=0)
    assert np.allclose(two.visual.uv, ref.visual.uv, atol=1e-14, rtol=0)
    md = a.metadata["hybridsub"]
    edges = {frozenset(e) for e in np.sort(np.stack([a.faces.ravel(), np.roll(a.faces, -1, 1).ravel()], 1),
                                            axis=1).tolist()}
    assert all(frozenset(e) in edges for e in md["sharp_edges"].tolist())  # edges of the result itself
    # the creases are where hybridsub.subdivide puts them
    V1, F1 = hybridsub.subdivide(V, F, feat.sharp_edges, 1, corners=feat.corners, **kw)
    r = hybridsub.refine(F, feat.sharp_edges, 1, corners=feat.corners, **kw)
    want = {frozenset(map(tuple, V1[e].round(12).tolist())) for e in r.sharp_edges}
    got = {frozenset(map(tuple, a.vertices[e].round(12).tolist())) for e in md["sharp_edges"]}
    assert got == want and len(md["corners"]) >= len(feat.corners)


def test_textured_vertex_attributes(textured_cube):
    """Per-vertex arrays equal on every copy follow the surface; arrays that differ between
    copies (per corner) follow the UVs."""
    mesh, origin = textured_cube
    m = mesh.copy()
    m.vertex_attributes["x"] = m.vertices[:, 0].copy()  # continuous: same on every copy
    chart = np.zeros(len(m.vertices))
    chart[m.faces.ravel()] = np.repeat(cube_charts(load_mesh("cube-meshed")[0], origin[m.faces]), 3)
    m.vertex_attributes["chart"] = chart  # differs between copies: per corner
    out = hybridsub.subdivide_mesh(m, 2)
    assert np.allclose(out.vertex_attributes["x"], out.vertices[:, 0], atol=1e-14, rtol=0)  # affine invariance
    want = chart[mesh.faces[:, 0]][out.metadata["hybridsub"]["face_parent"]]  # the chart of each face's parent
    assert np.array_equal(out.vertex_attributes["chart"][out.faces], np.repeat(want[:, None], 3, axis=1))


def test_weld_untextured_triangle_soup(cube):
    """weld=True on a mesh stored as separate triangles (as STL is): the surface of the welded
    mesh, vertex colours equal on every copy following it."""
    V, F, _ = cube
    rgb = np.c_[np.round((V - V.min(0)) / np.ptp(V, 0) * 255), np.full(len(V), 255)].astype(np.uint8)
    soup = trimesh.Trimesh(V[F].reshape(-1, 3), np.arange(3 * len(F)).reshape(-1, 3), process=False)
    soup.visual.vertex_colors = rgb[F.ravel()]
    out = hybridsub.subdivide_mesh(soup, 2, weld=True)
    V2, F2 = hybridsub.subdivide(V, F, levels=2)
    assert np.array_equal(out.vertices[out.faces], V2[F2]) and len(out.vertices) == len(V2)  # welded vertices
    r = hybridsub.refine(F, levels=2)
    want = np.clip(np.round(r.apply(rgb.astype(float))), 0, 255)
    assert np.array_equal(out.visual.vertex_colors[out.faces], want[F2])
    # welded by default too (a soup, as trimesh.load("part.stl", process=False) gives); weld=False: lone triangles
    assert np.array_equal(hybridsub.subdivide_mesh(soup, 2).vertices, out.vertices)
    assert len(hybridsub.subdivide_mesh(soup, 1, weld=False).faces) == 6 * len(F)


def test_textured_welding_limits(textured_cube):
    mesh, _ = textured_cube
    with pytest.raises(ValueError, match="weld=False"):
        hybridsub.subdivide_mesh(mesh, 1, scheme="sqrt3")
    apart = hybridsub.subdivide_mesh(mesh, 1, scheme="sqrt3", weld=False)  # the mesh as stored
    assert len(apart.faces) == 3 * len(mesh.faces)
    with pytest.raises(TypeError, match="weld must be"):
        hybridsub.subdivide_mesh(mesh, 1, weld="yes")
    # two boxes sharing one side: welded, that side's edges are in four faces
    box = trimesh.creation.box()
    other = box.copy()
    other.apply_translation([1.0, 0, 0])
    soup = trimesh.util.concatenate([box, other])
    both = trimesh.Trimesh(soup.vertices, soup.faces, process=False,
                           visual=trimesh.visual.TextureVisuals(uv=soup.vertices[:, :2]))
    with pytest.raises(hybridsub.MeshError, match="welded mesh.*weld=False"):
        hybridsub.subdivide_mesh(both, 1)
    assert len(hybridsub.subdivide_mesh(both, 1, weld=False).faces) == 2 * len(box.faces) * 3
    # a face whose corners weld together
    flat = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [1, 0, 0]], [[0, 1, 2], [1, 3, 4]],
                           process=False, visual=trimesh.visual.TextureVisuals(uv=np.eye(5)[:, :2]))
    with pytest.raises(hybridsub.MeshError, match=r"face 1 = \[1, 3, 4\] has two corners at the same position"):
        hybridsub.subdivide_mesh(flat, 1)
    # two pieces touching at one vertex: a bow-tie, which is valid (refined as a corner)
    tip = trimesh.Trimesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 0], [-1, 0, 0], [0, -1, 0]],
                          [[0, 1, 2], [3, 4, 5]], process=False,
                          visual=trimesh.visual.TextureVisuals(uv=np.arange(12.0).reshape(6, 2)))
    out = hybridsub.subdivide_mesh(tip, 2)
    assert np.array_equal(out.vertices[[0, 3]], np.zeros((2, 3)))
