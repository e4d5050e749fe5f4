"""Feature detection: creases by dihedral angle, corners by count and by turning angle.

trimesh's face adjacency is the independent oracle for the dihedral angles and the boundary.
"""

import numpy as np
import pytest
import trimesh
from conftest import load_mesh

import hybridsub
from hybridsub import MeshError


def _edge_set(E):
    return set(map(tuple, np.sort(np.asarray(E), axis=1).tolist()))


def _lines(edges, corners):
    """Crease lines: connected pieces of the feature graph, cut at the corners."""
    adj = {}
    for a, b in edges:
        adj.setdefault(a, []).append(b)
        adj.setdefault(b, []).append(a)
    cs = set(corners.tolist())
    seen, lines = set(), []
    for a, b in edges:
        if (a, b) in seen:
            continue
        line, stack = set(), [(a, b)]
        while stack:
            u, w = stack.pop()
            if (u, w) in seen:
                continue
            seen.update({(u, w), (w, u)})
            line.update({u, w})
            for x in (u, w):
                if x not in cs:
                    stack.extend((x, y) for y in adj[x])
        lines.append(line)
    return lines


def test_cube_has_12_crease_lines_and_8_corners():
    V, F = load_mesh("cube-meshed")
    feat = hybridsub.detect_features(V, F, angle=30)
    assert len(feat.boundary_edges) == 0
    lo, hi = V.min(axis=0), V.max(axis=0)
    on_face = (np.isclose(V, lo) | np.isclose(V, hi)).sum(axis=1)
    # corners: exactly the 8 vertices at the box's corners
    assert np.array_equal(feat.corners, np.flatnonzero(on_face == 3))
    assert len(feat.corners) == 8
    # every sharp edge runs along a cube edge (both ends on two box faces), and all such edges are sharp
    e = feat.sharp_edges
    assert (on_face[e] >= 2).all()
    level_edges = _edge_set(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]))
    along = {(a, b) for a, b in level_edges if on_face[a] >= 2 and on_face[b] >= 2
             and ((np.isclose(V[a], lo) | np.isclose(V[a], hi)) & (np.isclose(V[b], lo) | np.isclose(V[b], hi))).sum() >= 2}
    assert _edge_set(e) == along
    lines = _lines(e.tolist(), feat.corners)
    assert len(lines) == 12
    for line in lines:
        pts = V[sorted(line)]
        # collinear: the points vary along one axis only
        assert (np.ptp(pts, axis=0) > 1e-9).sum() == 1
        assert len(line & set(feat.corners.tolist())) == 2


@pytest.mark.parametrize("name", ["cube-meshed", "fandisk", "mesh_with_border"])
@pytest.mark.parametrize("angle", [10.0, 30.0, 60.0])
def test_sharp_edges_match_trimesh_dihedral_angles(name, angle):
    V, F = hybridsub.load_example() if name == "fandisk" else load_mesh(name)
    feat = hybridsub.detect_features(V, F, angle=angle)
    tm = trimesh.Trimesh(V, F, process=False)
    sharp = tm.face_adjacency_edges[np.degrees(tm.face_adjacency_angles) > angle]
    assert _edge_set(feat.sharp_edges) == _edge_set(sharp)
    # boundary edges: the edges of one face only
    e = np.sort(tm.edges_sorted, axis=1)
    uniq, count = np.unique(e, axis=0, return_counts=True)
    assert _edge_set(feat.boundary_edges) == _edge_set(uniq[count == 1])
    assert not (_edge_set(feat.sharp_edges) & _edge_set(feat.boundary_edges))


def _naive_corners(V, E, corner_angle):
    adj = {}
    for a, b in E:
        adj.setdefault(a, []).append(b)
        adj.setdefault(b, []).append(a)
    out = []
    for v, nb in adj.items():
        if len(nb) >= 3:
            out.append(v)
        elif len(nb) == 2 and corner_angle is not None:
            d1, d2 = V[nb[0]] - V[v], V[nb[1]] - V[v]
            between = np.degrees(np.arccos(np.clip(d1 @ d2 / np.linalg.norm(d1) / np.linalg.norm(d2), -1, 1)))
            if 180.0 - between > corner_angle:
                out.append(v)
    return np.array(sorted(out), dtype=np.int64)


@pytest.mark.parametrize("corner_angle", [None, 20.0, 45.0, 170.0])
def test_fandisk_corners(corner_angle):
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 30, corner_angle=corner_angle)
    E = np.concatenate([feat.sharp_edges, feat.boundary_edges])
    assert np.array_equal(feat.corners, _naive_corners(V, E.tolist(), corner_angle))
    base = hybridsub.detect_features(V, F, 30, corner_angle=None).corners
    assert len(base) == 22  # vertices where three or more creases meet
    if corner_angle == 45.0:
        # one crease vertex turns by ~160° (the tip of fandisk's notch): a corner, not a crease
        extra = np.setdiff1d(feat.corners, base)
        assert len(extra) == 1
    if corner_angle == 20.0:  # the coarse circular arcs turn by ~22.5° per vertex: all corners now
        assert len(feat.corners) > 30


def test_turning_corner_on_a_bent_crease_and_the_boundary():
    # A strip folded along a polyline that turns by 90° at vertex 2 (and is a boundary at the ends).
    V = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [2, 1, 0], [2, 2, 0],
                  [0, -1, 1], [1, -1, 1], [2, -1, 1], [3, -1, 1], [3, 0, 1], [3, 1, 1], [3, 2, 1]], float)
    F = np.array([[0, 5, 6], [0, 6, 1], [1, 6, 7], [1, 7, 2], [2, 7, 8], [2, 8, 9], [2, 9, 3], [3, 9, 10],
                  [3, 10, 4], [4, 10, 11]])
    feat = hybridsub.detect_features(V, F, angle=100.0, corner_angle=45.0)
    assert len(feat.sharp_edges) == 0
    # the boundary polyline 0-1-2-3-4 turns by 90° at 2; the far side turns at 7/8 and 8/9
    assert 2 in feat.corners
    assert 1 not in feat.corners and 3 not in feat.corners
    none = hybridsub.detect_features(V, F, angle=100.0, corner_angle=None)
    assert len(none.corners) == 0


def test_degenerate_faces_and_empty_mesh():
    V = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 1, 0], [1, -1, 1]], float)
    folded = np.array([[0, 1, 3], [1, 2, 3], [1, 0, 4], [2, 1, 4]])
    feat = hybridsub.detect_features(V, folded, angle=10)
    assert _edge_set(feat.sharp_edges) == {(0, 1), (1, 2)}
    # the same two edges with a zero-area face (0, 1, 2 are collinear) across: no normal, no crease
    flat = np.array([[0, 1, 3], [1, 2, 3], [2, 1, 0]])
    feat = hybridsub.detect_features(V, flat, angle=1)
    assert len(feat.sharp_edges) == 0
    assert _edge_set(feat.boundary_edges) == {(0, 3), (2, 3), (0, 2)}
    empty = hybridsub.detect_features(V, np.empty((0, 3), int))
    assert empty.sharp_edges.shape == (0, 2) and empty.corners.shape == (0,)


def test_bad_input_and_no_side_effects():
    V, F = load_mesh("cube-meshed")
    V.setflags(write=False)
    F.setflags(write=False)
    with pytest.raises(ValueError, match="angle must be in"):
        hybridsub.detect_features(V, F, angle=200)
    with pytest.raises(ValueError, match="corner_angle must be in"):
        hybridsub.detect_features(V, F, corner_angle=-1)
    with pytest.raises(TypeError, match="angle must be a number"):
        hybridsub.detect_features(V, F, angle="sharp")
    with pytest.raises(MeshError, match="F must have shape"):
        hybridsub.detect_features(V, F[:, :2])
    hybridsub.detect_features(V, F)  # read-only input is fine


def test_subdivide_with_feature_angle_equals_explicit_tags():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, 30)
    a = hybridsub.subdivide(V, F, levels=1, feature_angle=30)
    b = hybridsub.subdivide(V, F, feat.sharp_edges, levels=1, corners=feat.corners)
    assert np.array_equal(a[1], b[1]) and np.array_equal(a[0], b[0])
    # the caller's tags take precedence: a semi-sharp edge stays semi-sharp, sharpness 0 un-tags
    e = feat.sharp_edges[:2]
    r1 = hybridsub.subdivide(V, F, e, levels=1, sharpness=[0.5, 0.0], feature_angle=30, return_matrix=True)
    r2 = hybridsub.subdivide(V, F, np.concatenate([e, feat.sharp_edges[2:]]), levels=1,
                             sharpness=np.r_[0.5, 0.0, np.full(len(feat.sharp_edges) - 2, np.inf)],
                             corners=feat.corners, return_matrix=True)
    assert np.array_equal(r1[1], r2[1])
    assert abs(r1[2] - r2[2]).max() == 0
