"""hybridsub.jax against the NumPy library: r.apply under jit, gradients equal to Sᵀ G and
to finite differences (jax's check_grads), vmap equal to a loop, float32, bad input."""

import numpy as np
import pytest
from adapters import adapter
from conftest import load_mesh

import hybridsub

jax = adapter("jax")
jax.config.update("jax_enable_x64", True)
jnp = jax.numpy
hj = adapter("hybridsub.jax")
from jax.test_util import check_grads  # noqa: E402


@pytest.fixture(scope="module")
def fandisk():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    r = hybridsub.refine(F, feat.sharp_edges, levels=2, corners=feat.corners,
                         sharpness=np.linspace(0.5, 3, len(feat.sharp_edges)))
    return V, r


def test_jit_equals_apply(fandisk):
    V, r = fandisk
    f = jax.jit(hj.subdivide_fn(r))
    want = r.apply(V)
    got = f(jnp.asarray(V))
    assert got.dtype == jnp.float64
    assert np.abs(np.asarray(got) - want).max() <= 1e-12 * np.abs(want).max()
    got32 = f(jnp.asarray(V, jnp.float32))
    assert got32.dtype == jnp.float32
    np.testing.assert_allclose(np.asarray(got32), want, rtol=0, atol=4 * np.finfo(np.float32).eps * np.abs(V).max())
    assert np.array_equal(np.asarray(hj.subdivide_fn(r)(V)), np.asarray(got))  # NumPy data too, same sums


def test_grad_is_transpose_product(fandisk):
    V, r = fandisk
    f = hj.subdivide_fn(r)
    G = np.random.default_rng(0).standard_normal((r.n_vertices, 3))
    g = jax.jit(jax.grad(lambda X: jnp.sum(f(X) * G)))(jnp.asarray(V))
    want = r.matrix.T @ G
    assert np.abs(np.asarray(g) - want).max() <= 1e-12 * np.abs(want).max()


def test_vmap_equals_loop_and_finite_differences():
    V, F = load_mesh("octahedron")
    r = hybridsub.refine(F, [[0, 1], [1, 2]], levels=2, sharpness=[0.5, 2.0])
    f = hj.subdivide_fn(r)
    X = jnp.asarray(np.stack([V, 2 * V, -V]))
    Y = jax.jit(jax.vmap(f))(X)
    for b in range(3):
        np.testing.assert_array_equal(np.asarray(Y[b]), np.asarray(f(X[b])))
    check_grads(f, (jnp.asarray(V),), order=2, modes=("fwd", "rev"))
    M = hybridsub.limit_matrix(F, levels=1)
    np.testing.assert_allclose(np.asarray(hj.subdivide_fn(M)(V)), M @ V, rtol=0, atol=1e-14)
    assert hj.subdivide_fn(r)(np.zeros((6, 2, 5))).shape == (r.n_vertices, 2, 5)  # any trailing shape


def test_bad_input():
    V, F = load_mesh("tetrahedron")
    f = hj.subdivide_fn(hybridsub.refine(F, levels=1))
    with pytest.raises(TypeError, match="float32 or float64 data, got int"):
        f(jnp.asarray(F))
    with pytest.raises(ValueError, match=r"shape \(4, \.\.\.\).*got \(3, 3\)"):
        f(jnp.zeros((3, 3)))
    with pytest.raises(ValueError, match="shape"):
        jax.jit(f)(jnp.zeros((5, 3)))
    with pytest.raises(TypeError, match="Refinement or a 2-D SciPy sparse matrix, got list"):
        hj.subdivide_fn([[1.0]])
