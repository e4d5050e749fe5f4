"""Hypothesis strategies for valid triangle meshes and feature tags, plus mesh checks.

A *valid* mesh here is ``(V, F)`` with ``V`` float64 ``(n, 3)`` and ``F`` int64 ``(m, 3)``:
every edge in one or two faces (edge-manifold), consistently oriented (each directed
halfedge used once), no face with a repeated vertex, no two faces on the same vertex set.
Vertices where several fans meet (bow-ties) are valid; strategies that can make them take
``bowties=False`` to avoid them.

Meshes are small (at most about 300 faces) so that property tests stay fast. Bulk
randomness comes from a NumPy generator seeded by Hypothesis; sizes and choices are drawn
by Hypothesis itself, so they shrink.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

MAX_FACES = 300

# --------------------------------------------------------------------------------------
# Mesh checks (plain NumPy, no hybridsub)
# --------------------------------------------------------------------------------------


def halfedges_of(F):
    """Directed halfedges ``(3m, 2)``: face f gives rows 3f, 3f+1, 3f+2 = a→b, b→c, c→a."""
    F = np.asarray(F, dtype=np.int64).reshape(-1, 3)
    return np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2)


def _edge_counts(F):
    H = np.sort(halfedges_of(F), axis=1)
    if len(H) == 0:
        return np.empty((0, 2), np.int64), np.empty(0, np.int64)
    E, counts = np.unique(H, axis=0, return_counts=True)
    return E.astype(np.int64), counts


def edges_of(F):
    """Unique undirected edges as sorted pairs ``(k, 2)``, lexicographically sorted."""
    return _edge_counts(F)[0]


def boundary_edges(F):
    """Edges used by exactly one face, as sorted pairs ``(k, 2)``."""
    E, c = _edge_counts(F)
    return E[c == 1]


def interior_edges(F):
    """Edges used by exactly two faces, as sorted pairs."""
    E, c = _edge_counts(F)
    return E[c == 2]


def euler(nV, F):
    """Euler characteristic V - E + F, counting all ``nV`` vertices (unused ones too)."""
    F = np.asarray(F).reshape(-1, 3)
    return int(nV) - len(edges_of(F)) + len(F)


def is_edge_manifold(F):
    """Every edge is used by one or two faces."""
    _, c = _edge_counts(F)
    return bool(np.all(c <= 2))


def is_consistently_oriented(F):
    """Every directed halfedge occurs once (so the two faces of an edge traverse it oppositely)."""
    H = halfedges_of(F)
    if len(H) == 0:
        return True
    return len(np.unique(H, axis=0)) == len(H)


def has_degenerate_faces(F):
    F = np.asarray(F).reshape(-1, 3)
    return bool(np.any((F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])))


def has_duplicate_faces(F):
    F = np.sort(np.asarray(F).reshape(-1, 3), axis=1)
    return len(F) > 0 and len(np.unique(F, axis=0)) != len(F)


def vertex_fans(F, v):
    """Number of fans (face components connected through edges at v) around vertex v."""
    F = np.asarray(F).reshape(-1, 3)
    faces = np.flatnonzero(np.any(F == v, axis=1))
    if len(faces) == 0:
        return 0
    parent = {int(f): int(f) for f in faces}

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    by_spoke = {}
    for f in faces:
        for u in F[f]:
            if u != v:
                by_spoke.setdefault(int(u), []).append(int(f))
    for fs in by_spoke.values():
        for g in fs[1:]:
            parent[find(g)] = find(fs[0])
    return len({find(int(f)) for f in faces})


def bowtie_vertices(F):
    """Vertices whose faces form more than one fan."""
    F = np.asarray(F).reshape(-1, 3)
    return [int(v) for v in np.unique(F) if vertex_fans(F, v) > 1]


def check_mesh(V, F, *, nV=None):
    """Raise AssertionError saying what is wrong with (V, F), if anything."""
    F = np.asarray(F)
    assert F.ndim == 2 and F.shape[1] == 3, f"F shape {F.shape}"
    assert np.issubdtype(F.dtype, np.integer), f"F dtype {F.dtype}"
    n = len(V) if nV is None else nV
    if V is not None:
        V = np.asarray(V)
        assert V.ndim == 2 and V.shape[1] == 3, f"V shape {V.shape}"
        assert V.dtype == np.float64, f"V dtype {V.dtype}"
        assert np.all(np.isfinite(V))
    if len(F):
        assert F.min() >= 0 and F.max() < n, "face index out of range"
    assert not has_degenerate_faces(F), "degenerate face"
    assert not has_duplicate_faces(F), "duplicate face"
    assert is_edge_manifold(F), "edge in more than two faces"
    assert is_consistently_oriented(F), "inconsistent orientation"


def is_valid_mesh(V, F):
    try:
        check_mesh(V, F)
    except AssertionError:
        return False
    return True


def compact(V, F):
    """Drop vertices no face uses; keep their order."""
    used = np.unique(F)
    remap = np.full(len(V), -1, np.int64)
    remap[used] = np.arange(len(used))
    return np.ascontiguousarray(V[used], dtype=np.float64), remap[F].astype(np.int64)


def _mesh(V, F):
    return (np.ascontiguousarray(V, dtype=np.float64),
            np.ascontiguousarray(F, dtype=np.int64).reshape(-1, 3))


# --------------------------------------------------------------------------------------
# Deterministic constructors (usable without Hypothesis)
# --------------------------------------------------------------------------------------


def tetrahedron():
    V = np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    return _mesh(V, F)


def octahedron():
    V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4],
                  [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    return _mesh(V, F)


def icosahedron():
    t = (1 + 5 ** 0.5) / 2
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0],
                  [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
                  [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
                  [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
                  [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    return _mesh(V, F)


def single_triangle():
    return _mesh(np.array([[0, 0, 0], [1, 0, 0], [0.3, 0.8, 0.1]], float), np.array([[0, 1, 2]]))


def hull_mesh(points):
    """Convex hull of points in general position, faces oriented outward, unused dropped."""
    P = np.asarray(points, dtype=np.float64)
    hull = ConvexHull(P)
    F = hull.simplices.astype(np.int64).copy()
    n = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    flip = np.einsum("ij,ij->i", n, hull.equations[:, :3]) < 0
    F[flip] = F[flip][:, [0, 2, 1]]
    return compact(P, F)


def sphere_hull(n_points, rng):
    """Convex hull of ``n_points`` random points on the unit sphere (2n - 4 faces)."""
    for _ in range(10):
        P = rng.normal(size=(n_points, 3))
        P /= np.linalg.norm(P, axis=1, keepdims=True)
        V, F = hull_mesh(P)
        if len(V) == n_points and euler(len(V), F) == 2 and is_valid_mesh(V, F):
            return V, F
    raise RuntimeError("could not build a sphere hull")  # pragma: no cover


def grid(nx, ny, diagonals, *, z=None):
    """Grid patch of ``nx * ny`` quads, each split along a diagonal chosen by ``diagonals``.

    ``diagonals``: bool array ``(nx, ny)``; False splits quad (i, j) along v00-v11, True
    along v10-v01. Vertex (i, j) (i in 0..nx, j in 0..ny) has index ``i * (ny + 1) + j`` and
    position ``(i, j, z[i, j])``.
    """
    I, J = np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), indexing="ij")
    Z = np.zeros_like(I, dtype=float) if z is None else np.asarray(z, float)
    V = np.stack([I.ravel(), J.ravel(), Z.ravel()], axis=1).astype(float)
    F = _split_quads(nx, ny, lambda i, j: i * (ny + 1) + j, diagonals)
    return _mesh(V, F)


def _split_quads(nx, ny, idx, diagonals):
    """Two triangles per grid quad (i, j), split along the diagonal ``diagonals[i, j]`` picks."""
    F = []
    diagonals = np.asarray(diagonals, bool).reshape(nx, ny)
    for i in range(nx):
        for j in range(ny):
            a, b, c, d = idx(i, j), idx(i + 1, j), idx(i + 1, j + 1), idx(i, j + 1)
            if diagonals[i, j]:
                F += [[a, b, d], [b, c, d]]
            else:
                F += [[a, b, c], [a, c, d]]
    return np.array(F)


def torus(nu, nv, diagonals=None, R=2.0, r=0.7):
    """Torus (genus 1, closed) from an ``nu * nv`` periodic grid, ``nu, nv >= 3``."""
    if diagonals is None:
        diagonals = np.zeros((nu, nv), bool)
    u = 2 * np.pi * np.arange(nu) / nu
    v = 2 * np.pi * np.arange(nv) / nv
    U, W = np.meshgrid(u, v, indexing="ij")
    V = np.stack([(R + r * np.cos(W)) * np.cos(U), (R + r * np.cos(W)) * np.sin(U),
                  r * np.sin(W)], axis=2).reshape(-1, 3)
    return _mesh(V, _split_quads(nu, nv, lambda i, j: (i % nu) * nv + (j % nv), diagonals))


def fan(valence, *, closed, height=0.0):
    """Fan around vertex 0.

    ``closed=False``: open fan, vertex 0 joined to ``valence`` ring vertices by
    ``valence - 1`` faces (vertex 0 is on the boundary). ``closed=True``: a disk, vertex 0
    interior with ``valence`` faces. ``height`` lifts vertex 0 (a cone).
    """
    k = int(valence)
    span = 2 * np.pi if closed else 1.5 * np.pi
    ang = span * np.arange(k) / (k if closed else k - 1)
    ring = np.stack([np.cos(ang), np.sin(ang), np.zeros(k)], axis=1)
    V = np.vstack([[0.0, 0.0, height], ring])
    nfaces = k if closed else k - 1
    F = [[0, 1 + i, 1 + (i + 1) % k] for i in range(nfaces)]
    return _mesh(V, np.array(F))


def bipyramid(valence, *, flat_base=False, height=1.0):
    """Closed cone on a ring of ``valence`` vertices: apex 0 and base centre 1 both have
    valence ``valence``. ``flat_base=True`` puts the base centre in the ring's plane."""
    k = int(valence)
    ang = 2 * np.pi * np.arange(k) / k
    ring = np.stack([np.cos(ang), np.sin(ang), np.zeros(k)], axis=1)
    V = np.vstack([[0.0, 0.0, height], [0.0, 0.0, 0.0 if flat_base else -height], ring])
    F = []
    for i in range(k):
        a, b = 2 + i, 2 + (i + 1) % k
        F += [[0, a, b], [1, b, a]]
    return _mesh(V, np.array(F))


def remove_faces(V, F, order, n_remove, *, bowties=True, keep_unused=False):
    """Remove up to ``n_remove`` faces, tried in ``order`` (a permutation of face indices).

    The result stays edge-manifold and oriented (a subset of such a mesh always is). With
    ``bowties=False`` a removal that would leave a vertex with two fans is skipped.
    At least one face is kept. Unused vertices are dropped unless ``keep_unused``.
    """
    F = np.asarray(F)
    keep = np.ones(len(F), bool)
    removed = 0
    for f in order:
        if removed >= n_remove or keep.sum() <= 1:
            break
        keep[f] = False
        if not bowties:
            Fk = F[keep]
            if any(vertex_fans(Fk, v) > 1 for v in F[f]):
                keep[f] = True
                continue
        removed += 1
    Fk = F[keep]
    if keep_unused:
        return _mesh(V, Fk)
    return compact(V, Fk)


def combine(meshes, *, spacing=4.0):
    """Disjoint union of meshes, each translated along x so that they do not overlap."""
    Vs, Fs, off = [], [], 0
    for i, (V, F) in enumerate(meshes):
        V = np.asarray(V, float)
        Vs.append(V - V.mean(axis=0) + [spacing * i, 0.0, 0.0] if len(V) else V)
        Fs.append(np.asarray(F) + off)
        off += len(V)
    return _mesh(np.vstack(Vs), np.vstack(Fs))


def relabel(V, F, rng):
    """Random vertex permutation, face permutation and cyclic rotation of each face."""
    n, m = len(V), len(F)
    perm = rng.permutation(n)            # old index -> new index
    V2 = np.empty_like(V)
    V2[perm] = V
    F2 = perm[F][rng.permutation(m)]
    shift = rng.integers(0, 3, size=m)
    cols = (np.arange(3)[None, :] + shift[:, None]) % 3
    F2 = np.take_along_axis(F2, cols, axis=1)
    return _mesh(V2, F2)


# --------------------------------------------------------------------------------------
# Hypothesis strategies
# --------------------------------------------------------------------------------------

seeds = st.integers(0, 2**32 - 1)


def rngs():
    return seeds.map(np.random.default_rng)


def _jitter(V, rng, amount):
    return V + amount * rng.uniform(-1, 1, size=V.shape) if amount else V


@st.composite
def sphere_meshes(draw, min_points=4, max_points=100):
    """Closed convex meshes: hull of random points on a sphere (genus 0)."""
    n = draw(st.integers(min_points, max_points))
    return sphere_hull(n, draw(rngs()))


@st.composite
def platonic_meshes(draw):
    """Tetrahedron, octahedron or icosahedron, optionally jittered."""
    V, F = draw(st.sampled_from([tetrahedron, octahedron, icosahedron]))()
    amount = draw(st.sampled_from([0.0, 0.1]))
    return _jitter(V, draw(rngs()), amount), F


@st.composite
def torus_meshes(draw, max_n=9):
    nu, nv = draw(st.integers(3, max_n)), draw(st.integers(3, max_n))
    rng = draw(rngs())
    return torus(nu, nv, rng.random((nu, nv)) < 0.5)


@st.composite
def cone_meshes(draw, min_valence=3, max_valence=64):
    """Closed cones / bipyramids with two vertices of valence in [min_valence, max_valence]."""
    k = draw(st.integers(min_valence, max_valence))
    V, F = bipyramid(k, flat_base=draw(st.booleans()), height=draw(st.sampled_from([0.3, 1.0, 2.0])))
    return V, F


def closed_meshes(max_points=100):
    """Closed (boundary-free) meshes of genus 0 and 1."""
    return st.one_of(platonic_meshes(), sphere_meshes(max_points=max_points),
                     torus_meshes(), cone_meshes())


@st.composite
def grid_meshes(draw, max_n=10, bumpy=None):
    """Grid patches with random diagonal directions, flat or with random heights."""
    nx, ny = draw(st.integers(1, max_n)), draw(st.integers(1, max_n))
    rng = draw(rngs())
    diag = rng.random((nx, ny)) < 0.5
    bumpy = draw(st.booleans()) if bumpy is None else bumpy
    z = rng.uniform(-0.5, 0.5, size=(nx + 1, ny + 1)) if bumpy else None
    return grid(nx, ny, diag, z=z)


@st.composite
def fan_meshes(draw, min_valence=3, max_valence=64, closed=None):
    """A vertex (index 0) of valence in [min_valence, max_valence]: open fan or closed disk."""
    k = draw(st.integers(min_valence, max_valence))
    closed = draw(st.booleans()) if closed is None else closed
    return fan(k, closed=closed, height=draw(st.sampled_from([0.0, 0.5])))


def high_valence_meshes(min_valence=3, max_valence=64):
    return st.one_of(fan_meshes(min_valence, max_valence),
                     cone_meshes(min_valence, max_valence))


@st.composite
def open_meshes(draw, bowties=True, max_points=80, keep_unused=False):
    """A closed mesh with a random subset of its faces removed (holes, maybe several pieces)."""
    V, F = draw(st.one_of(platonic_meshes(), sphere_meshes(max_points=max_points),
                          torus_meshes(max_n=7), cone_meshes(max_valence=16)))
    rng = draw(rngs())
    n_remove = draw(st.integers(1, max(1, len(F) - 1)))
    return remove_faces(V, F, rng.permutation(len(F)), n_remove,
                        bowties=bowties, keep_unused=keep_unused)


def triangle_meshes():
    return st.just(single_triangle()).map(lambda m: (m[0].copy(), m[1].copy()))


def _single_meshes(bowties, max_points):
    return st.one_of(
        closed_meshes(max_points=max_points),
        open_meshes(bowties=bowties, max_points=max_points),
        grid_meshes(),
        high_valence_meshes(),
        triangle_meshes(),
    )


@st.composite
def multi_component_meshes(draw, bowties=True, max_components=3):
    k = draw(st.integers(2, max_components))
    parts = [draw(_single_meshes(bowties, 30)) for _ in range(k)]
    V, F = combine(parts)
    if len(F) > MAX_FACES:
        F = F[:MAX_FACES]
        V, F = compact(V, F)
    return V, F


@st.composite
def shuffled(draw, mesh_strategy):
    """Apply a random relabelling (vertices, faces, face rotation) half of the time."""
    V, F = draw(mesh_strategy)
    if draw(st.booleans()):
        V, F = relabel(V, F, draw(rngs()))
    return V, F


@st.composite
def with_unused_vertices(draw, mesh_strategy, max_extra=3):
    """Append a few vertices no face uses (they must be kept and must not move)."""
    V, F = draw(mesh_strategy)
    k = draw(st.integers(0, max_extra))
    rng = draw(rngs())
    return _mesh(np.vstack([V, rng.normal(size=(k, 3))]), F)


def meshes(kind="any", *, bowties=True, shuffle=True, max_points=100):
    """Valid triangle meshes. ``kind``: "any", "closed", "open" (has a boundary), "grid",
    "fan", "multi", "triangle"."""
    base = {
        "any": st.one_of(_single_meshes(bowties, max_points),
                         multi_component_meshes(bowties=bowties)),
        "closed": closed_meshes(max_points=max_points),
        "open": st.one_of(open_meshes(bowties=bowties, max_points=max_points), grid_meshes(),
                          fan_meshes(closed=False), fan_meshes(closed=True), triangle_meshes()),
        "grid": grid_meshes(),
        "fan": high_valence_meshes(),
        "multi": multi_component_meshes(bowties=bowties),
        "triangle": triangle_meshes(),
    }[kind]
    return shuffled(base) if shuffle else base


# ------------------------------- tags ---------------------------------------------------


def random_sharpness(rng, k, kind="mixed"):
    """``kind``: "inf" (all inf), "mixed" (inf, (0,1), (1,3), >= 10, and exact 1 and 2),
    "finite" (no inf, no >= 10), "semisharp" ((0, 1) and (1, 3) only), "mixed0" (as
    "mixed", plus 0 and -0.0, which mean "no crease"; negative values are an error)."""
    if kind == "inf":
        return np.full(k, np.inf)
    if kind == "mixed":
        cat = rng.integers(0, 6, size=k)
    elif kind == "mixed0":
        cat = rng.integers(0, 8, size=k)
    elif kind == "finite":
        cat = rng.choice([1, 2, 4, 5], size=k)
    elif kind == "semisharp":
        cat = rng.choice([1, 2], size=k)
    else:
        raise ValueError(kind)
    s = np.empty(k)
    s[cat == 0] = np.inf
    s[cat == 1] = rng.uniform(0.05, 0.95, size=(cat == 1).sum())
    s[cat == 2] = rng.uniform(1.05, 2.95, size=(cat == 2).sum())
    s[cat == 3] = rng.uniform(10.0, 50.0, size=(cat == 3).sum())
    s[cat == 4] = 1.0
    s[cat == 5] = 2.0
    s[cat == 6] = 0.0
    s[cat == 7] = -0.0
    return s


@st.composite
def sharp_edge_tags(draw, F, *, sharpness="maybe", duplicates=True, max_fraction=0.5,
                    edges=None):
    """``(sharp_edges (k, 2) int64, sharpness (k,) float64 or None)`` on edges of ``F``.

    Each tagged edge gets a random orientation; with ``duplicates`` some rows are repeated
    (same sharpness as the original). ``sharpness``: "none" (always None), "inf",
    "mixed", "finite", "semisharp", or "maybe" (None or "mixed"). ``edges`` restricts the
    candidates (sorted pairs).
    """
    E = edges_of(F) if edges is None else np.asarray(edges, np.int64).reshape(-1, 2)
    rng = draw(rngs())
    frac = draw(st.sampled_from([0.0, 0.1, 0.3, max_fraction]))
    pick = rng.random(len(E)) < frac
    S = E[pick].copy()
    flip = rng.random(len(S)) < 0.5
    S[flip] = S[flip][:, ::-1]
    if sharpness == "maybe":
        sharpness = draw(st.sampled_from(["none", "mixed"]))
    s = None if sharpness == "none" else random_sharpness(rng, len(S), sharpness)
    if duplicates and len(S) and draw(st.booleans()):
        dup = rng.integers(0, len(S), size=rng.integers(1, min(len(S), 5) + 1))
        D = S[dup].copy()
        rev = rng.random(len(D)) < 0.5
        D[rev] = D[rev][:, ::-1]
        order = rng.permutation(len(S) + len(D))
        S = np.vstack([S, D])[order]
        if s is not None:
            s = np.concatenate([s, s[dup]])[order]
    return np.ascontiguousarray(S, dtype=np.int64).reshape(-1, 2), s


@st.composite
def sharp_face_tags(draw, m, *, form=None, fraction=None):
    """Sharp faces of a mesh with ``m`` faces: a bool mask ``(m,)`` or unique indices
    (random order). ``form``: "mask", "indices" or None (either)."""
    rng = draw(rngs())
    frac = draw(st.sampled_from([0.0, 0.2, 0.5, 0.8, 1.0])) if fraction is None else fraction
    mask = rng.random(m) < frac
    form = draw(st.sampled_from(["mask", "indices"])) if form is None else form
    if form == "mask":
        return mask
    return rng.permutation(np.flatnonzero(mask)).astype(np.int64)


@st.composite
def corner_tags(draw, n, *, max_fraction=0.3):
    """Unique vertex indices (random order)."""
    rng = draw(rngs())
    frac = draw(st.sampled_from([0.0, 0.05, max_fraction]))
    return rng.permutation(np.flatnonzero(rng.random(n) < frac)).astype(np.int64)


def sharp_mask(sharp_faces, m):
    """Normalise a sharp-face tag (None, bool mask or indices) to a bool mask."""
    if sharp_faces is None:
        return np.zeros(m, bool)
    a = np.asarray(sharp_faces)
    if a.dtype == bool:
        assert a.shape == (m,)
        return a.copy()
    mask = np.zeros(m, bool)
    mask[a.astype(np.int64)] = True
    return mask


@st.composite
def tagged_meshes(draw, kind="any", *, sharpness="maybe", sharp_faces=True, corners=True,
                  bowties=True, duplicates=True):
    """``(V, F, tags)`` with ``tags`` a dict of keyword arguments for hybridsub
    (``sharp_edges``, ``sharpness``, ``sharp_faces``, ``corners``), each possibly absent."""
    V, F = draw(meshes(kind, bowties=bowties))
    tags = {}
    if draw(st.booleans()):
        se, s = draw(sharp_edge_tags(F, sharpness=sharpness, duplicates=duplicates))
        tags["sharp_edges"] = se
        if s is not None:
            tags["sharpness"] = s
    if sharp_faces and draw(st.booleans()):
        tags["sharp_faces"] = draw(sharp_face_tags(len(F)))
    if corners and draw(st.booleans()):
        tags["corners"] = draw(corner_tags(len(V)))
    return V, F, tags


# ------------------------------- UV charts ----------------------------------------------


def twins_of(F):
    """(3m,) twin halfedge of each halfedge (-1 on the boundary), by sorting (no hybridsub)."""
    H = halfedges_of(F)
    n = int(H.max()) + 1 if len(H) else 1
    key = H[:, 0] * n + H[:, 1]
    order = np.argsort(key)
    want = H[:, 1] * n + H[:, 0]
    pos = np.minimum(np.searchsorted(key[order], want), max(len(key) - 1, 0))
    found = key[order][pos] == want if len(key) else np.zeros(0, bool)
    return np.where(found, order[pos], -1)


def sectors(F, cut):
    """Label of each face corner ``3f + i``: corners of one vertex joined across the interior
    halfedges not in ``cut`` (a (3m,) mask, symmetric over twins)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = len(F)
    twin = twins_of(F)
    h = np.flatnonzero((twin >= 0) & ~cut)
    g = twin[h]
    nxt = lambda x: x - x % 3 + (x % 3 + 1) % 3  # noqa: E731
    # h = a->b in face f, g = b->a: a's corners are h and next(g), b's are next(h) and g
    a = np.concatenate([h, nxt(h)])
    b = np.concatenate([nxt(g), g])
    graph = coo_matrix((np.ones(len(a), np.int8), (a, b)), shape=(3 * m, 3 * m))
    return connected_components(graph, directed=False)[1]


@st.composite
def uv_charts(draw, F, *, max_fraction=0.6, unmapped=None):
    """Random UV charts on a mesh ``F``: ``(UV (t, 2), FUV (m, 3))``, one UV index per
    (vertex, face sector), sectors cut along a random subset of the interior edges (the
    seams), UV indices in random order, a few unused UV values, random UV values. With
    ``unmapped`` (drawn if None) a few faces have all three corners on one extra UV index, as
    files map untextured faces (degenerate UV faces, a UV index on several vertices)."""
    F = np.asarray(F, dtype=np.int64)
    rng = draw(rngs())
    twin = twins_of(F)
    frac = draw(st.sampled_from([0.0, 0.1, 0.3, max_fraction, 1.0]))
    h = np.flatnonzero((twin >= 0) & (np.arange(len(twin)) < twin))
    pick = h[rng.random(len(h)) < frac]
    cut = np.zeros(len(twin), bool)
    cut[pick] = True
    cut[twin[pick]] = True
    _, label = np.unique(sectors(F, cut), return_inverse=True)
    t = int(label.max()) + 1 if len(label) else 0
    extra = draw(st.integers(0, 2))
    perm = rng.permutation(t + extra)[:t]
    FUV = perm[label.ravel()].reshape(-1, 3).astype(np.int64)
    unmapped = draw(st.booleans()) if unmapped is None else unmapped
    if unmapped and len(F) >= 2:
        FUV[rng.choice(len(F), size=rng.integers(1, len(F) // 4 + 2), replace=False)] = t + extra
        extra += 1
    return rng.random((t + extra, 2)), FUV


# ------------------------------- broken meshes ------------------------------------------
#
# Each strategy below returns a ``Broken`` case: arguments for ``hybridsub.subdivide`` that
# must be refused, the exception type the docs (docs/errors.md) promise, and a fragment the
# message must contain.


@dataclass
class Broken:
    """A call ``hybridsub.subdivide(V, F, **kwargs)`` that must raise ``error`` (message
    containing ``match``)."""

    what: str
    V: object
    F: object
    kwargs: dict = field(default_factory=dict)
    error: type = ValueError
    match: str = ""


def _mesh_error():
    import hybridsub  # noqa: F401  (imported late: the valid-mesh strategies need no hybridsub)

    return hybridsub.MeshError


def add_fin(F, n, edge):
    """Faces plus one triangle on ``edge`` = (u, w) and a new vertex ``n``: a third face on an
    interior edge makes it non-manifold."""
    u, w = int(edge[0]), int(edge[1])
    return np.vstack([F, [[u, w, n]]]).astype(np.int64)


def flip_face(F, f):
    F = np.array(F, dtype=np.int64, copy=True)
    F[f] = F[f][::-1]
    return F


@st.composite
def broken_shapes(draw):
    """V or F of the wrong shape, dtype or content (no topology involved)."""
    V, F = draw(meshes("any", max_points=30))
    rng = draw(rngs())
    ME = _mesh_error()
    n, m = len(V), len(F)
    kind = draw(st.sampled_from([
        "V2", "V4", "V1d", "V3d", "Vstr", "Vcomplex", "Vbool", "Vnan", "Vinf", "Fquad", "F2", "F1d",
        "Fbool", "Fstr", "Ffrac", "Fnan", "Fneg", "Frange", "Fhuge", "Frepeat", "ragged",
    ]))
    v, f = int(rng.integers(n)), int(rng.integers(m))
    if kind == "V2":
        return Broken(kind, V[:, :2], F, error=ME, match="(n, 3)")
    if kind == "V4":
        return Broken(kind, np.c_[V, V[:, :1]], F, error=ME, match="(n, 3)")
    if kind == "V1d":
        return Broken(kind, V.ravel(), F, error=ME, match="(n, 3)")
    if kind == "V3d":
        return Broken(kind, V[:, :, None], F, error=ME, match="(n, 3)")
    if kind == "Vstr":
        return Broken(kind, V.astype(str), F, error=TypeError, match="V must be")
    if kind == "Vcomplex":
        return Broken(kind, V.astype(complex), F, error=TypeError, match="V must be")
    if kind == "Vbool":
        return Broken(kind, V > 0, F, error=TypeError, match="V must be")
    if kind in ("Vnan", "Vinf"):
        W = V.copy()
        W[v, int(rng.integers(3))] = np.nan if kind == "Vnan" else -np.inf
        return Broken(kind, W, F, error=ME, match=f"vertex {v} ")
    if kind == "Fquad":
        return Broken(kind, V, np.c_[F, F[:, :1]], error=ME, match="triangulate")
    if kind == "F2":
        return Broken(kind, V, F[:, :2], error=ME, match="(m, 3)")
    if kind == "F1d":
        return Broken(kind, V, F.ravel(), error=ME, match="(m, 3)")
    if kind == "Fbool":
        return Broken(kind, V, F > 0, error=TypeError, match="F must")
    if kind == "Fstr":
        return Broken(kind, V, F.astype(str), error=TypeError, match="F must")
    if kind == "Ffrac":
        G = F.astype(float)
        G[f, int(rng.integers(3))] += 0.5
        return Broken(kind, V, G, error=ME, match=f"face {f} ")
    if kind == "Fnan":
        G = F.astype(float)
        G[f, int(rng.integers(3))] = np.nan
        return Broken(kind, V, G, error=ME, match=f"face {f} ")
    if kind == "Fneg":
        G = F.copy()
        G[f, int(rng.integers(3))] = -int(rng.integers(1, 5))
        return Broken(kind, V, G, error=ME, match=f"face {f} ")
    if kind == "Frange":
        G = F.copy()
        G[f, int(rng.integers(3))] = n + int(rng.integers(0, 5))
        return Broken(kind, V, G, error=ME, match=f"face {f} ")
    if kind == "Fhuge":
        G = F.astype(np.uint64)
        G[f, 0] = np.uint64(2**64 - 1)
        return Broken(kind, V, G, error=ME, match=f"face {f} ")
    if kind == "Frepeat":
        G = F.copy()
        G[f, 1] = G[f, 0]
        return Broken(kind, V, G, error=ME, match=f"face {f} ")
    # ragged: one face with 4 vertices, as a list (all faces of a one-face mesh: a quad array)
    G = F.tolist()
    G[f] = G[f] + [G[f][0]]
    return Broken(kind, V, G, error=ME, match=f"face {f} has 4" if m > 1 else "triangulate")


def _interior_edge(F, rng):
    E = interior_edges(F)
    if len(E) == 0:
        return None
    return E[int(rng.integers(len(E)))]


@st.composite
def broken_topology(draw):
    """Duplicate faces, non-manifold edges and inconsistent orientation on valid meshes."""
    V, F = draw(meshes("any", max_points=30))
    rng = draw(rngs())
    ME = _mesh_error()
    n, m = len(V), len(F)
    kind = draw(st.sampled_from(["duplicate", "duplicate_flipped", "fin", "flip"]))
    f = int(rng.integers(m))
    if kind in ("duplicate", "duplicate_flipped"):
        face = np.roll(F[f], int(rng.integers(3)))
        if kind == "duplicate_flipped":
            face = face[::-1]
        G = np.insert(F, int(rng.integers(m + 1)), face, axis=0)
        return Broken(kind, V, G, error=ME, match="duplicate face")
    e = _interior_edge(F, rng)
    if kind == "fin" and e is not None:
        W = np.vstack([V, V[e].mean(axis=0) + [0.0, 0.0, 1.0]])
        return Broken(kind, W, add_fin(F, n, e[:: int(rng.choice([-1, 1]))]), error=ME, match="shared by 3 faces")
    # flip a face that has an interior edge (a face alone on all sides would stay valid)
    I = {tuple(x) for x in interior_edges(F).tolist()}
    cand = [g for g in range(m) if any(tuple(sorted((int(F[g, i]), int(F[g, (i + 1) % 3])))) in I
                                       for i in range(3))]
    if not cand:  # no interior edge at all: duplicate instead
        return Broken("duplicate", V, np.vstack([F, F[f]]), error=ME, match="duplicate face")
    g = cand[int(rng.integers(len(cand)))]
    return Broken("flip", V, flip_face(F, g), error=ME, match="same direction")


@st.composite
def broken_tags(draw):
    """Tags that do not fit the mesh, and bad options."""
    V, F = draw(meshes("any", max_points=30))
    rng = draw(rngs())
    ME = _mesh_error()
    n, m = len(V), len(F)
    kind = draw(st.sampled_from([
        "not_an_edge", "self_loop", "edge_range", "edge_shape", "edge_frac", "sharpness_len",
        "sharpness_nan", "sharpness_str", "face_range", "face_mask_len", "face_frac", "corner_range",
        "corner_mask_len", "sqrt3_tags", "levels_neg", "levels_float", "scheme", "loop_weights",
        "non_manifold", "max_memory",
    ]))
    E = edges_of(F)
    if kind == "not_an_edge":
        have = {tuple(x) for x in E.tolist()}
        pairs = [(a, b) for a in range(min(n, 12)) for b in range(a + 1, min(n, 12)) if (a, b) not in have]
        if pairs:
            a, b = pairs[int(rng.integers(len(pairs)))]
            tags = np.vstack([E[:1], [[b, a]]])
            return Broken(kind, V, F, {"sharp_edges": tags}, ME, "sharp edge 1 ")
        kind = "self_loop"
    if kind == "self_loop":
        return Broken(kind, V, F, {"sharp_edges": [[0, 0]]}, ME, "itself")
    if kind == "edge_range":
        return Broken(kind, V, F, {"sharp_edges": [[0, n + int(rng.integers(3))]]}, ME, "sharp edge 0 ")
    if kind == "edge_shape":
        return Broken(kind, V, F, {"sharp_edges": E[:1].ravel()[:1]}, ME, "(k, 2)")
    if kind == "edge_frac":
        return Broken(kind, V, F, {"sharp_edges": E[:1] + 0.5}, ME, "sharp edge 0 ")
    if kind == "sharpness_len":
        return Broken(kind, V, F, {"sharp_edges": E[:1], "sharpness": [1.0, 2.0]}, ME, "one value per")
    if kind == "sharpness_nan":
        return Broken(kind, V, F, {"sharp_edges": E[:1], "sharpness": [np.nan]}, ME, "NaN")
    if kind == "sharpness_str":
        return Broken(kind, V, F, {"sharp_edges": E[:1], "sharpness": ["x"]}, TypeError, "sharpness")
    if kind == "face_range":
        return Broken(kind, V, F, {"sharp_faces": [0, m + int(rng.integers(3))]}, ME, "sharp_faces[1]")
    if kind == "face_mask_len":
        return Broken(kind, V, F, {"sharp_faces": np.ones(m + 1, bool)}, ME, "one entry per face")
    if kind == "face_frac":
        return Broken(kind, V, F, {"sharp_faces": [0.5]}, ME, "sharp_faces[0]")
    if kind == "corner_range":
        return Broken(kind, V, F, {"corners": [-1 - int(rng.integers(3))]}, ME, "corners[0]")
    if kind == "corner_mask_len":
        return Broken(kind, V, F, {"corners": np.ones(n - 1, bool)}, ME, "one entry per vertex")
    if kind == "sqrt3_tags":
        tag = draw(st.sampled_from([{"sharp_edges": E[:1]}, {"sharp_faces": [0]}, {"corners": [0]}]))
        return Broken(kind, V, F, dict(tag, scheme="sqrt3"), ValueError, "sqrt3")
    if kind == "levels_neg":
        return Broken(kind, V, F, {"levels": -int(rng.integers(1, 4))}, ValueError, "levels")
    if kind == "levels_float":
        return Broken(kind, V, F, {"levels": 1.5}, TypeError, "levels")
    if kind == "scheme":
        return Broken(kind, V, F, {"scheme": "catmull-clark"}, ValueError, "scheme")
    if kind == "loop_weights":
        return Broken(kind, V, F, {"loop_weights": "stam"}, ValueError, "loop_weights")
    if kind == "non_manifold":
        return Broken(kind, V, F, {"non_manifold": "ignore"}, ValueError, "non_manifold")
    return Broken(kind, V, F, {"max_memory": -1}, ValueError, "max_memory")


def broken_inputs():
    return st.one_of(broken_shapes(), broken_topology(), broken_tags())


@st.composite
def non_manifold_meshes(draw, max_fins=3):
    """Valid meshes made non-manifold (fins on interior edges) or inconsistently oriented
    (flipped faces): inputs that ``non_manifold="cut"`` must handle."""
    V, F = draw(meshes("any", max_points=30))
    rng = draw(rngs())
    for _ in range(draw(st.integers(1, max_fins))):
        e = _interior_edge(F, rng)
        if e is not None and draw(st.booleans()):
            V = np.vstack([V, V[e].mean(axis=0) + rng.normal(size=3)])
            F = add_fin(F, len(V) - 1, e[:: int(rng.choice([-1, 1]))])
        else:
            F = flip_face(F, int(rng.integers(len(F))))
    return _mesh(V, F)
