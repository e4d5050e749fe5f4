"""Multiresolution: Refinement.decompose / reconstruct (reverse subdivision, details in local frames)."""

import numpy as np
import pytest

import hybridsub
from conftest import load_mesh
from hybridsub._fit.multires import local_frames


def _cases():
    V, F = load_mesh("cube-meshed")
    feat = hybridsub.detect_features(V, F, angle=30)
    Vb, Fb = load_mesh("mesh_with_border")
    return {
        "hybrid-creases": (V, F, dict(sharp_edges=feat.sharp_edges, corners=feat.corners, levels=2,
                                      sharp_faces=np.arange(0, len(F), 7))),
        "loop-semisharp": (V, F, dict(sharp_edges=feat.sharp_edges, sharpness=np.full(len(feat.sharp_edges), 1.5),
                                      scheme="loop", levels=2)),
        "sqrt3-border": (Vb, Fb, dict(scheme="sqrt3", levels=3)),     # Kobbelt's boundary, odd and even steps
        "hybrid-border": (Vb, Fb, dict(levels=2)),
    }


CASES = _cases()


@pytest.mark.parametrize("name", sorted(CASES))
def test_refined_data_gives_its_coarse_data_back(name):
    V, F, kw = CASES[name]
    r = hybridsub.refine(F, **kw)
    coarse, details = r.decompose(r.apply(V))
    scale = np.abs(V).max()
    assert np.abs(coarse - V).max() < 1e-12 * scale
    assert len(details) == kw["levels"] and details.local_frames
    assert details.norms().max() < 1e-12 * scale


@pytest.mark.parametrize("name", sorted(CASES))
def test_reconstruct_inverts_decompose_and_carries_details_through_a_rigid_motion(name):
    V, F, kw = CASES[name]
    r = hybridsub.refine(F, **kw)
    rng = np.random.default_rng(3)
    X = r.apply(V) + 0.02 * rng.normal(size=(r.n_vertices, 3))
    coarse, details = r.decompose(X)
    assert np.abs(r.reconstruct(coarse, details) - X).max() < 1e-12
    assert details.norms()[-1] > 1e-3                       # the noise is in the details
    Q = np.linalg.qr(rng.normal(size=(3, 3)))[0]            # the frames turn with the coarse mesh
    moved = r.reconstruct(coarse @ Q.T + [0.3, -1, 2], details)
    assert np.abs(moved - (X @ Q.T + [0.3, -1, 2])).max() < 1e-12


def test_details_follow_a_local_edit_and_stay_put_elsewhere():
    V, F, kw = CASES["hybrid-creases"]
    r = hybridsub.refine(F, **kw)
    X = r.apply(V) + 0.01 * np.random.default_rng(4).normal(size=(r.n_vertices, 3))
    coarse, details = r.decompose(X)
    edited = coarse.copy()
    edited[10] += [0, 0, 0.5]
    X2 = r.reconstruct(edited, details)
    moved = np.linalg.norm(X2 - X, axis=1) > 1e-12
    assert moved.any() and moved.mean() < 0.05              # local support: only near vertex 10
    Q = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])     # world details do not turn: frames are what carry
    cw, dw = r.decompose(X, frames=False)
    assert not dw.local_frames and np.abs(r.reconstruct(cw, dw) - X).max() < 1e-12
    assert np.abs(r.reconstruct(cw @ Q.T, dw) - X @ Q.T).max() > 1e-3


def test_other_data_has_world_details_and_keeps_its_shape():
    V, F, kw = CASES["hybrid-border"]
    r = hybridsub.refine(F, **kw)
    rgb = np.random.default_rng(5).random((r.n_vertices, 2, 2))
    coarse, details = r.decompose(rgb)
    assert coarse.shape == (len(V), 2, 2) and not details.local_frames
    assert np.abs(r.reconstruct(coarse, details) - rgb).max() < 1e-12
    c1, d1 = r.decompose(rgb[:, 0, 0])
    assert c1.shape == (len(V),) and np.abs(c1 - coarse[:, 0, 0]).max() < 1e-12
    c3, d3 = r.decompose(rgb[:, 0, :1].repeat(3, axis=1), frames=False)
    assert not d3.local_frames
    assert hybridsub.refine(F, levels=0).decompose(V)[1].levels == ()


def test_reverse_is_least_squares_and_the_factor_is_reused():
    Vi, Fi = load_mesh("icosahedron")
    r1 = hybridsub.refine(Fi, [[0, 1], [1, 9]], levels=1, sharp_faces=[0, 3])
    X = np.random.default_rng(6).normal(size=(r1.n_vertices, 2))
    coarse, _ = r1.decompose(X)
    lsq = np.linalg.lstsq(r1.matrix.toarray(), X, rcond=None)[0]
    assert np.abs(coarse - lsq).max() < 1e-10
    V, F, kw = CASES["hybrid-creases"]
    r = hybridsub.refine(F, **kw)
    r.decompose(r.apply(V))
    factors = {k: v for k, v in r._cache.items() if isinstance(k, tuple)}
    assert len(factors) == 2                                  # one per step, kept
    r.decompose(r.apply(2 * V))
    assert all(r._cache[k] is f for k, f in factors.items())


def test_bad_input_is_named():
    V, F, kw = CASES["hybrid-border"]
    r = hybridsub.refine(F, **kw)
    with pytest.raises(hybridsub.MeshError, match="one row per vertex"):
        r.decompose(V)
    X = r.apply(V)
    coarse, details = r.decompose(X)
    with pytest.raises(ValueError, match="three columns"):
        r.decompose(X[:, :2], frames=True)
    with pytest.raises(TypeError, match="MultiresDetails"):
        r.reconstruct(coarse, list(details))
    with pytest.raises(ValueError, match="levels"):
        hybridsub.refine(F, levels=1).reconstruct(coarse, details)
    with pytest.raises(ValueError, match="finite"):
        r.decompose(np.where(np.arange(len(X))[:, None] == 5, np.nan, X))
    with pytest.raises(ValueError, match="shape"):
        r.reconstruct(coarse[:, :2], details)
    X0 = X.copy()
    r.decompose(X)
    assert np.array_equal(X, X0)


def test_local_frames_are_orthonormal_and_follow_the_normal():
    V, F = load_mesh("icosahedron")
    R = local_frames(V, F)
    assert np.abs(np.einsum("vij,vkj->vik", R, R) - np.eye(3)).max() < 1e-14
    assert (np.einsum("vi,vi->v", R[:, 2], V) > 0.9).all()        # outward on the unit sphere
    R2 = local_frames(np.vstack([V, [[5, 5, 5]]]), F)            # an unused vertex: the identity
    assert np.array_equal(R2[-1], np.eye(3))
