"""subdivide_mesh: trimesh in, trimesh out, with attributes and features carried along."""

import numpy as np
import pytest

import hybridsub
from conftest import load_mesh

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


def test_uvs_per_vertex_are_refined(cube):
    V, F, _ = cube
    uv = V[:, :2] * 0.5 + 0.25
    mesh = trimesh.Trimesh(V, F, visual=trimesh.visual.TextureVisuals(uv=uv), process=False)
    out = hybridsub.subdivide_mesh(mesh, 1, scheme="loop")
    r = hybridsub.refine(F, levels=1, n_vertices=len(V), scheme="loop")
    assert out.visual.kind == "texture"
    assert np.allclose(out.visual.uv, r.apply(uv))


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
    with pytest.raises(hybridsub.MeshError, match="shared by 3 faces"):
        hybridsub.subdivide_mesh(bad, 1)
