"""hybridsub.torch against the NumPy library: forward equals r.apply / subdivide, backward
equals Sᵀ G, gradients against finite differences (torch's gradcheck and central
differences of hybridsub.subdivide), batched equals looped, bad input named."""

import numpy as np
import pytest
import scipy.sparse as sp
from adapters import adapter
from conftest import load_mesh

import hybridsub

torch = adapter("torch")
ht = adapter("hybridsub.torch")


def creased(name, k, seed):
    """A mesh of tests/data with k random interior edges as creases."""
    V, F = load_mesh(name)
    from hybridsub._topology import build_level
    level = build_level(F, len(V))
    inner = np.flatnonzero(~level.boundary_edge)
    pick = np.random.default_rng(seed).choice(inner, k, replace=False)
    return V, F, level.edge_vertices[pick]


@pytest.fixture(params=["kernels", "torch"])
def path(request, monkeypatch):
    """Both ways of multiplying: the library's kernels (the CPU's) and PyTorch's sparse
    products (a GPU's), the latter here on the CPU."""
    if request.param == "torch":
        monkeypatch.setattr(ht, "_use_kernels", lambda device: False)
    return request.param


@pytest.fixture(scope="module")
def fandisk():
    V, F = hybridsub.load_example()
    feat = hybridsub.detect_features(V, F, angle=30)
    return V, F, feat


@pytest.mark.parametrize("scheme", ["hybrid", "loop", "sqrt3"])
def test_forward_equals_apply(fandisk, scheme, path):
    V, F, feat = fandisk
    tags = {} if scheme == "sqrt3" else dict(sharp_edges=feat.sharp_edges, corners=feat.corners)
    r = hybridsub.refine(F, levels=2, scheme=scheme, **tags)
    want = r.apply(V)
    sub = ht.Subdivide(r)
    got = sub(torch.tensor(V))
    assert got.dtype == torch.float64 and got.shape == want.shape
    if path == "kernels":  # r.apply's own sums
        assert np.array_equal(got.numpy(), want)
    assert np.abs(got.numpy() - want).max() <= 1e-12 * np.abs(want).max()
    got32 = sub(torch.tensor(V, dtype=torch.float32))
    assert got32.dtype == torch.float32
    np.testing.assert_allclose(got32.numpy(), want, rtol=0, atol=4 * np.finfo(np.float32).eps * np.abs(V).max())


def test_input_matrices_untouched(fandisk):
    V, F, feat = fandisk
    r = hybridsub.refine(F, feat.sharp_edges, levels=2)
    before = [(S.matrix.indices.copy(), S.matrix.data.copy()) for S in r.steps]
    want = r.apply(V)
    ht.Subdivide(r)(torch.tensor(V))
    ht.sparse(r.steps[0].matrix)
    for S, (indices, data) in zip(r.steps, before):
        assert np.array_equal(S.matrix.indices, indices) and np.array_equal(S.matrix.data, data)
    assert np.array_equal(r.apply(V), want)


def test_batched_equals_looped(fandisk, path):
    V, F, feat = fandisk
    sub = ht.Subdivide(hybridsub.refine(F, feat.sharp_edges, levels=1))
    X = torch.tensor(np.stack([V, 2 * V + 1, V[::-1].copy()]), requires_grad=True)
    Y = sub(X)
    assert Y.shape == (3, sub.n_out, 3)
    for b in range(3):
        assert torch.equal(Y[b], sub(X[b]))
    G = torch.randn(Y.shape, dtype=torch.float64, generator=torch.Generator().manual_seed(0))
    (Y * G).sum().backward()
    X1 = torch.tensor(V, requires_grad=True)
    (sub(X1) * G[1]).sum().backward()
    torch.testing.assert_close(X.grad[1], X1.grad, rtol=0, atol=1e-13)


def test_backward_is_transpose_product(fandisk, path):
    V, F, feat = fandisk
    r = hybridsub.refine(F, feat.sharp_edges, levels=2, corners=feat.corners)
    G = np.random.default_rng(2).standard_normal((r.n_vertices, 3))
    X = torch.tensor(V, requires_grad=True)
    (ht.Subdivide(r)(X) * torch.tensor(G)).sum().backward()
    want = r.matrix.T @ G
    assert np.abs(X.grad.numpy() - want).max() <= 1e-12 * np.abs(want).max()


def test_gradcheck_and_second_derivatives(path):
    V, F, E = creased("octahedron", 3, 0)
    sub = ht.Subdivide(hybridsub.refine(F, E, levels=2, sharpness=[0.5, 2, np.inf]))
    X = torch.tensor(V, requires_grad=True)
    fast = path == "torch"  # PyTorch's sparse products cost milliseconds each on the CPU, even tiny ones
    assert torch.autograd.gradcheck(sub, (X,), fast_mode=fast)
    assert torch.autograd.gradgradcheck(sub, (X,), fast_mode=fast)
    Xb = torch.tensor(np.stack([V, -V]), requires_grad=True)
    assert torch.autograd.gradcheck(sub, (Xb,), fast_mode=fast)


def test_module_buffers_and_dtype(path):
    V, F = load_mesh("tetrahedron")
    r = hybridsub.refine(F, levels=1, scheme="loop")
    sub = ht.Subdivide(r)
    assert sub.state_dict() == {}  # the matrices come from the refinement, not from training
    half = sub.float()
    assert half.S0.dtype == torch.float32
    Y = half(torch.tensor(V, dtype=torch.float32))
    np.testing.assert_allclose(Y.numpy(), r.apply(V), rtol=1e-6, atol=1e-6)
    assert half(torch.tensor(V)).dtype == torch.float64  # a cast copy for the other dtype
    ident = ht.Subdivide(hybridsub.refine(F, levels=0))
    assert torch.equal(ident(torch.tensor(V)), torch.tensor(V))


def test_limit_rows(fandisk):
    V, F, feat = fandisk
    surface = hybridsub.LimitSurface(V, F, feat.sharp_edges, corners=feat.corners)
    face = np.arange(0, len(F), 97)
    bary = np.tile([0.2, 0.3, 0.5], (len(face), 1))
    M = surface.evaluation_matrix(face, bary)
    X = torch.tensor(V, requires_grad=True)
    P = ht.Subdivide(M)(X)
    np.testing.assert_allclose(P.detach().numpy(), surface.evaluate(face, bary), rtol=0, atol=1e-12)
    L = hybridsub.limit_matrix(F, feat.sharp_edges, levels=1, corners=feat.corners)
    S = ht.sparse(L)
    assert S.layout == torch.sparse_csr
    G = torch.randn(L.shape[0], 3, dtype=torch.float64, generator=torch.Generator().manual_seed(1))
    ((S @ X) * G).sum().backward()
    torch.testing.assert_close(X.grad, torch.tensor(L.T @ G.numpy()), rtol=0, atol=1e-12)


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_subdivide_equals_numpy(fandisk, scheme, path):
    V, F, feat = fandisk
    s = np.random.default_rng(3).uniform(0.2, 3, len(feat.sharp_edges))
    want, F2 = hybridsub.subdivide(V, F, feat.sharp_edges, levels=2, scheme=scheme, sharpness=s)
    for req in (False, True):
        st = torch.tensor(s, requires_grad=req)
        got, F2t = ht.subdivide(torch.tensor(V), torch.tensor(F), torch.tensor(feat.sharp_edges), sharpness=st,
                                levels=2, scheme=scheme)
        assert np.abs(got.detach().numpy() - want).max() <= 1e-12 * np.abs(want).max()
        assert F2t.dtype == torch.int64 and np.array_equal(F2t.numpy(), F2)


@pytest.mark.parametrize("scheme", ["hybrid", "loop"])
def test_subdivide_takes_opensubdivs_options(fandisk, scheme, path):
    # corner_sharpness, boundary and holes as hybridsub.subdivide takes them; with a sharpness
    # gradient wanted, a semi-sharp corner is refused by name.
    V, F, feat = fandisk
    s = np.random.default_rng(4).uniform(0.2, 3, len(feat.sharp_edges))
    holes = np.zeros(len(F), bool)
    holes[::50] = True
    kw = dict(corners=feat.corners, corner_sharpness=np.linspace(0.5, 3.5, len(feat.corners)),
              boundary="edge_and_corner", levels=2, scheme=scheme)
    want, F2 = hybridsub.subdivide(V, F, feat.sharp_edges, sharpness=s, holes=holes, **kw)
    got, F2t = ht.subdivide(torch.tensor(V), F, feat.sharp_edges, sharpness=torch.tensor(s), holes=torch.tensor(holes),
                            **kw)
    assert np.abs(got.numpy() - want).max() <= 1e-12 * np.abs(want).max()
    assert np.array_equal(F2t.numpy(), F2) and len(F2) < 16 * len(F)
    with pytest.raises(ValueError, match="semi-sharp corners"):
        ht.subdivide(torch.tensor(V), F, feat.sharp_edges, sharpness=torch.tensor(s, requires_grad=True), **kw)
    st = torch.tensor(s, requires_grad=True)  # infinitely sharp corners: the gradient as before
    V2, _ = ht.subdivide(torch.tensor(V), F, feat.sharp_edges, sharpness=st, levels=2, scheme=scheme,
                         corners=feat.corners, holes=np.flatnonzero(holes))
    V2.sum().backward()
    assert st.grad.shape == (len(s),)


def numeric_gradient(V, F, E, s, G, scheme, levels, h=1e-3):
    """d <G, subdivide(V, F, E, sharpness=s)> / d s by central differences, from below at
    integers (the documented one-sided derivative). The result is affine in each sharpness
    between integers, so a wide step only spares rounding."""
    def f(t):
        return hybridsub.subdivide(V, F, E, sharpness=t, levels=levels, scheme=scheme)[0]
    out = np.empty(len(s))
    for j in range(len(s)):
        lo, hi = s.copy(), s.copy()
        lo[j] -= h
        hi[j] += h
        integer = s[j] == np.round(s[j])
        assert integer or abs(s[j] - np.round(s[j])) > 2 * h
        out[j] = np.sum(G * (f(s) - f(lo))) / h if integer else np.sum(G * (f(hi) - f(lo))) / (2 * h)
    return out


@pytest.mark.parametrize("scheme,mesh", [("loop", "icosahedron"), ("hybrid", "icosahedron"),
                                         ("hybrid", "mesh_with_border")])
def test_sharpness_gradient_against_finite_differences(scheme, mesh):
    V, F, E = creased(mesh, 12, 4)
    V = V / np.abs(V).max()  # unit size: the differences' rounding relative to the gradient
    rng = np.random.default_rng(5)
    s = rng.uniform(0.05, 2.95, len(E))
    s[:4] = [1.0, 2.0, 3.0, 3.5]  # integers (from below), and one past the last level (derivative 0)
    levels = 3
    G = rng.standard_normal((hybridsub.refine(F, E, levels=levels, scheme=scheme, sharpness=s).n_vertices, 3))
    st = torch.tensor(s, requires_grad=True)
    V2, _ = ht.subdivide(torch.tensor(V), F, E, sharpness=st, levels=levels, scheme=scheme)
    (V2 * torch.tensor(G)).sum().backward()
    want = numeric_gradient(V, F, E, s, G, scheme, levels)
    scale = np.abs(want).max()
    assert scale > 1e-4  # the sharpness matters here
    np.testing.assert_allclose(st.grad.numpy(), want, rtol=0, atol=1e-7 * scale)
    assert st.grad[3] == 0


def test_sharpness_gradcheck_and_zero_cases(path):
    V, F, E = creased("icosahedron", 6, 6)
    for scheme in ("loop", "hybrid"):
        def f(X, s):
            return ht.subdivide(X, F, E, sharpness=s, levels=2, scheme=scheme)[0]
        X = torch.tensor(V, requires_grad=True)
        s = torch.tensor([0.3, 0.7, 1.4, 1.8, 0.55, 1.25], requires_grad=True)
        assert torch.autograd.gradcheck(f, (X, s.double().detach().requires_grad_()), fast_mode=path == "torch")
    s = torch.tensor([0.0, np.inf, 10.0, 12.0, 0.5, 1.5], dtype=torch.float32, requires_grad=True)
    V2, _ = ht.subdivide(torch.tensor(V), F, E, sharpness=s, levels=2, scheme="loop")
    V2.square().sum().backward()
    assert s.grad.dtype == torch.float32
    assert s.grad[:4].tolist() == [0, 0, 0, 0] and (s.grad[4:] != 0).all()


def test_sharpness_batched_and_duplicates(path):
    V, F, E = creased("icosahedron", 4, 7)
    s = torch.tensor([0.5, 1.5, 0.25, 2.5], dtype=torch.float64, requires_grad=True)
    X = torch.tensor(np.stack([V, 3 * V]))
    (ht.subdivide(X, F, E, sharpness=s, levels=3, scheme="loop")[0] ** 2).sum().backward()
    g_batch = s.grad.clone()
    s.grad = None
    total = sum((ht.subdivide(X[b], F, E, sharpness=s, levels=3, scheme="loop")[0] ** 2).sum() for b in range(2))
    total.backward()
    torch.testing.assert_close(g_batch, s.grad, rtol=1e-12, atol=1e-12)
    # an edge listed twice: the larger sharpness is used, and its derivative goes to it
    E2 = np.concatenate([E, E[[0]]])
    s2 = torch.tensor([0.5, 1.5, 0.25, 2.5, 0.2], dtype=torch.float64, requires_grad=True)
    (ht.subdivide(X[0], F, E2, sharpness=s2, levels=3, scheme="loop")[0] ** 2).sum().backward()
    s.grad = None
    (ht.subdivide(X[0], F, E, sharpness=s, levels=3, scheme="loop")[0] ** 2).sum().backward()
    torch.testing.assert_close(s2.grad[:4], s.grad, rtol=1e-12, atol=1e-12)
    assert s2.grad[4] == 0


def test_bad_input():
    V, F = load_mesh("tetrahedron")
    sub = ht.Subdivide(hybridsub.refine(F, levels=1))
    with pytest.raises(TypeError, match=r"torch.Tensor, got numpy.ndarray \(torch.from_numpy"):
        sub(V)
    with pytest.raises(TypeError, match="float32 or float64, got torch.int64"):
        sub(torch.tensor(F))
    with pytest.raises(ValueError, match=r"shape \(4, c\) or \(B, 4, c\), got \(3, 3\)"):
        sub(torch.zeros(3, 3))
    with pytest.raises(ValueError, match="shape"):
        sub(torch.zeros(4))
    with pytest.raises(ValueError, match="the data is on meta and this Subdivide on cpu"):
        sub(torch.zeros(4, 3, device="meta"))
    with pytest.raises(TypeError, match="Refinement or a 2-D SciPy sparse matrix, got ndarray"):
        ht.Subdivide(np.eye(3))
    with pytest.raises(TypeError, match="2-D SciPy sparse matrix"):
        ht.sparse(np.eye(3))
    with pytest.raises(TypeError, match="dtype must be"):
        ht.sparse(sp.identity(3), dtype=torch.int64)
    E = np.array([[0, 1]])
    with pytest.raises(TypeError, match="V must be a torch.Tensor, got numpy.ndarray"):
        ht.subdivide(V, F, E)
    with pytest.raises(TypeError, match="sharpness must be a torch.Tensor"):
        ht.subdivide(torch.tensor(V), F, E, sharpness=np.array([0.5]))
    with pytest.raises(TypeError, match="sharpness must be a float tensor"):
        ht.subdivide(torch.tensor(V), F, E, sharpness=torch.tensor([1]))
    with pytest.raises(TypeError, match="F must hold integer indices"):
        ht.subdivide(torch.tensor(V), torch.tensor(F, dtype=torch.float64))
    with pytest.raises(ValueError, match="sharpness must have one value per sharp edge"):
        ht.subdivide(torch.tensor(V), F, E, sharpness=torch.tensor([0.5, 1.0]))
    with pytest.raises(ValueError, match=r"V must have shape \(n, c\) or \(B, n, c\), got \(12,\)"):
        ht.subdivide(torch.zeros(12), F)
    with pytest.raises(hybridsub.MeshError, match="refers to a vertex outside"):
        ht.subdivide(torch.tensor(V), F, [[0, 9]])


@pytest.mark.skipif(not torch.cuda.is_available(), reason="no CUDA device")
def test_cuda_equals_cpu(fandisk):
    V, F, feat = fandisk
    r = hybridsub.refine(F, feat.sharp_edges, levels=2)
    sub = ht.Subdivide(r).to("cuda")
    X = torch.tensor(V, device="cuda", requires_grad=True)
    Y = sub(X)
    np.testing.assert_allclose(Y.detach().cpu().numpy(), r.apply(V), rtol=0, atol=1e-12)
    Y.sum().backward()
    np.testing.assert_allclose(X.grad.cpu().numpy(), r.matrix.T @ np.ones((r.n_vertices, 3)), rtol=1e-12)
    s = torch.full((len(feat.sharp_edges),), 1.5, dtype=torch.float64, device="cuda", requires_grad=True)
    V2, _ = ht.subdivide(X, F, feat.sharp_edges, sharpness=s, levels=2)
    V2.sum().backward()
    assert s.grad.device.type == "cuda"


@pytest.mark.slow  # the docs' figure script, quick mode: ~10 s
def test_figure_script(tmp_path):
    import importlib.util
    import os
    path = os.path.join(os.path.dirname(__file__), "..", "docs", "figures", "differentiable.py")
    spec = importlib.util.spec_from_file_location("differentiable_figure", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.main(["--out", str(tmp_path), "--quick"])
    assert (tmp_path / "differentiable.png").stat().st_size > 10_000
