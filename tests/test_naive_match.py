"""The Numba path equals the slow, obvious reference (tests/naive.py) step by step.

Faces, tags and face parents must be identical (the index layout is part of the contract);
matrices equal to 1e-14.
"""

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import hybridsub
from naive import naive_refine
from strategies import sharp_mask, tagged_meshes

SETTINGS = settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def _assert_same(r, ref, n_faces_in):
    assert np.array_equal(r.faces, ref["faces"])
    assert np.array_equal(r.face_parent, ref["face_parent"])
    assert r.matrix.shape == ref["S"].shape
    assert abs(r.matrix - ref["S"]).max() < 1e-14 if ref["S"].nnz else r.matrix.nnz == 0
    assert np.array_equal(r.sharp_edges, ref["sharp_edges"])
    assert np.array_equal(r.sharpness, ref["sharpness"])
    assert np.array_equal(sharp_mask(r.sharp_faces, len(r.faces)), ref["sharp_faces"])
    assert np.array_equal(np.sort(r.corners), ref["corners"])


@SETTINGS
@given(tagged_meshes("any"), st.sampled_from(["hybrid", "loop"]), st.integers(1, 2),
       st.sampled_from(["loop", "warren"]))
def test_tagged_schemes_match_naive(data, scheme, levels, loop_weights):
    V, F, tags = data
    r = hybridsub.refine(F, levels=levels, n_vertices=len(V), scheme=scheme, loop_weights=loop_weights, **tags)
    mask = sharp_mask(tags.get("sharp_faces"), len(F))
    ref = naive_refine(F, len(V), levels, scheme=scheme, loop_weights=loop_weights,
                       sharp_edges=tags.get("sharp_edges"), sharpness=tags.get("sharpness"),
                       sharp_faces=mask, corners=tags.get("corners"))
    _assert_same(r, ref, len(F))


@SETTINGS
@given(tagged_meshes("any", sharp_faces=False, corners=False), st.integers(1, 3))
def test_sqrt3_matches_naive(data, levels):
    V, F, _ = data
    r = hybridsub.refine(F, levels=levels, n_vertices=len(V), scheme="sqrt3")
    ref = naive_refine(F, len(V), levels, scheme="sqrt3")
    _assert_same(r, ref, len(F))
