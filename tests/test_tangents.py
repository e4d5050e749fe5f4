"""limit_tangents and limit_normals(crease_normals=...) against OpenSubdiv 3.5 (tests/data/tangents/,
written by benchmarks/peers/osd_tangents_references.py with benchmarks/peers/osd_tangents.cpp).

OpenSubdiv's tangents are not normalised and turn with a smooth vertex's ring start, so at
smooth vertices the rotation-invariant T1 × T2 and |T1|² + |T2|² are compared; at crease
vertices (two sectors) the side and the vectors, up to Sdc's fixed scale factors (1.5 along,
3 or 2 across for sectors of 1–3 faces). Sdc's across mask for sectors of 4 or more faces is
not in the limit's tangent plane (up to 0.7° off on fandisk; docs/limit.md): there the
normals are checked against a deep refinement instead.
"""

import glob
import os

import numpy as np
import pytest

import hybridsub
from hybridsub._surface.normals import unit

DATA = os.path.join(os.path.dirname(__file__), "data", "tangents")
CASES = sorted(os.path.basename(p)[:-4] for p in glob.glob(os.path.join(DATA, "*.npz")))


def _dot(a, b):
    return np.einsum("ij,ij->i", a, b)


@pytest.mark.parametrize("case", CASES)
def test_loop_tangents_match_opensubdiv(case):
    d = np.load(os.path.join(DATA, case + ".npz"))
    levels = int(case.split(".")[-1][1:])
    V, F, C = d["V_in"], d["F_in"], d["creases"]
    T1, T2 = hybridsub.limit_tangents(V, F, C, levels=levels, scheme="loop")
    r = hybridsub.refine(F, C, levels=levels, scheme="loop")
    ncrease = np.bincount(np.asarray(r.sharp_edges).ravel(), minlength=len(T1))
    A, B = d["T1"], d["T2"]
    smooth = ncrease == 0
    cr, cr_ref = np.cross(T1, T2), np.cross(A, B)
    scale = np.linalg.norm(cr_ref, axis=1)
    assert np.all(np.linalg.norm(cr - cr_ref, axis=1)[smooth] <= 1e-12 * scale[smooth])
    # another ring start turns the pair: T1 × T2 and |T1|² + |T2|² stay
    np.testing.assert_allclose((_dot(T1, T1) + _dot(T2, T2))[smooth], (_dot(A, A) + _dot(B, B))[smooth],
                               rtol=1e-12)
    crease = ncrease == 2
    if not crease.any():
        return
    N = hybridsub.limit_normals(V, F, C, levels=levels, scheme="loop", crease_normals="one_side")
    Nc = hybridsub.limit_normals(V, F, C, levels=levels, scheme="loop", per_face_corner=True)
    Nref = unit(cr_ref)
    # the along tangent: OpenSubdiv's is ±1.5 × ours at every crease vertex
    T1c, Ac = T1[crease], A[crease]
    sign = np.sign(_dot(Ac, T1c))[:, None]
    np.testing.assert_allclose(Ac, 1.5 * sign * T1c, atol=1e-12 * np.abs(A).max())
    # OpenSubdiv's plane is one of the two sides (but where Sdc's across mask of 4+ faces is off)
    best = np.full(len(T1), -2.0)
    np.maximum.at(best, r.faces.ravel(), _dot(Nc.reshape(-1, 3), Nref[r.faces.ravel()]))
    assert (best[crease] > 1 - 1e-9).mean() > 0.97
    if levels == 0:  # the input's vertices: OpenSubdiv's side and orientation, vector for vector
        assert np.all(sign > 0)
        same = _dot(N, Nref) > 1 - 1e-9
        assert np.array_equal(same[crease], (best > 1 - 1e-9)[crease])


@pytest.mark.slow
def test_tangents_and_normals_agree_and_one_side_is_a_sector():
    V, F = hybridsub.load_example()
    from hybridsub._input import detect_features
    feat = detect_features(V, F, 30)
    for scheme, kw in (("loop", {}), ("hybrid", dict(sharp_faces=np.arange(0, len(F), 2))), ("sqrt3", None)):
        tags = dict(sharp_edges=feat.sharp_edges, **kw) if kw is not None else {}
        T1, T2 = hybridsub.limit_tangents(V, F, scheme=scheme, **tags)
        Na = hybridsub.limit_normals(V, F, scheme=scheme, **tags)
        No = hybridsub.limit_normals(V, F, scheme=scheme, crease_normals="one_side", **tags)
        Nc = hybridsub.limit_normals(V, F, scheme=scheme, per_face_corner=True, **tags)
        np.testing.assert_allclose(unit(np.cross(T1, T2)), No, atol=1e-9)
        # each one-side normal is the normal of one of the vertex's face corners
        best = np.full(len(V), -2.0)
        np.maximum.at(best, F.ravel(), _dot(Nc.reshape(-1, 3), No[F.ravel()]))
        assert np.all(best > 1 - 1e-9)
        smooth = np.isclose(_dot(Na, No), 1.0)
        assert smooth.mean() > 0.8 and (scheme == "sqrt3" or not smooth.all())
        c1, c2 = hybridsub.limit_tangents(V, F, scheme=scheme, per_face_corner=True, **tags)
        assert c1.shape == (len(F), 3, 3)
        np.testing.assert_allclose(unit(np.cross(c1, c2)), Nc, atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("scheme", ["sqrt3", "hybrid"])
def test_tangents_span_the_evaluator_derivatives(scheme):
    """√3 and hybrid: T1, T2 span the plane of LimitSurface.evaluate's derivatives at the vertices."""
    V, F = hybridsub.load_example()
    kw = {} if scheme == "sqrt3" else dict(sharp_faces=np.arange(0, len(F), 2))
    T1, T2 = hybridsub.limit_tangents(V, F, scheme=scheme, **kw)
    N = unit(np.cross(T1, T2))
    S = hybridsub.LimitSurface(V, F, scheme=scheme, **kw)
    rng = np.random.default_rng(0)
    faces = rng.choice(len(F), 40, replace=False)
    bary = np.tile([[0.98, 0.01, 0.01]], (len(faces), 1))
    out = S.evaluate(faces, bary, derivatives=True)
    P, du, dv = out if isinstance(out, tuple) else (out.positions, out.du, out.dv)
    n_fd = unit(np.cross(du, dv))
    v = F[faces, 0]
    assert np.median(np.abs(_dot(n_fd, N[v]))) > 0.99


def test_crease_normals_is_checked():
    V, F = hybridsub.load_example()
    with pytest.raises(ValueError, match="crease_normals must be one of"):
        hybridsub.limit_normals(V, F, crease_normals="left")
