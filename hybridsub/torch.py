"""Subdivision inside a PyTorch autograd graph (``pip install "hybridsub[torch]"``).

Every subdivision step is a sparse matrix, so a refined mesh is ``S @ X`` and the gradient
of anything computed from it is ``Sᵀ @ G``. :class:`Subdivide` holds the matrices of a
:class:`hybridsub.Refinement` (or any SciPy sparse matrix: a limit surface's
``evaluation_matrix``, ``limit_matrix``) as module buffers, so that the topology is refined
once and every forward pass, on the CPU or on a GPU, is a sparse product.
:func:`subdivide` also differentiates in each crease's sharpness. See
``docs/differentiable.md``.

>>> import torch, hybridsub, hybridsub.torch as ht
>>> V, F = hybridsub.load_example()
>>> sub = ht.Subdivide(hybridsub.refine(F, levels=2))
>>> X = torch.tensor(V, requires_grad=True)
>>> sub(X).square().sum().backward()
>>> X.grad.shape
torch.Size([6475, 3])

Importing this module imports PyTorch; ``import hybridsub`` does not.
"""

from __future__ import annotations

import warnings

try:
    import torch
except ImportError as e:  # pragma: no cover - the adapters' CI installs torch
    raise ImportError('hybridsub.torch needs PyTorch: pip install "hybridsub[torch]" '
                      "(or a build for your GPU from pytorch.org)") from e

import numpy as np
import scipy.sparse as sp

from ._input import as_sharp_edges, open_gate
from ._refiner import (CodedStencils, Refinement, apply_coded, apply_matrix, coded_stencils, in_read_order,
                       sharpness_steps)

__all__ = ["Subdivide", "sparse", "subdivide"]

#: The dtypes data may have (the matrices are cast to it).
FLOATS = (torch.float32, torch.float64)
_INT32_MAX = np.iinfo(np.int32).max


def sparse(M, *, dtype: torch.dtype = torch.float64, device=None) -> torch.Tensor:
    """A SciPy sparse matrix as a torch sparse CSR tensor.

    ``sparse(M) @ X`` is differentiable in ``X`` (PyTorch's own sparse product and its
    backward pass). Indices are int32 where they fit (PyTorch's CPU product is faster so).

    Parameters
    ----------
    M : scipy.sparse matrix or array, (m, n)
        ``r.matrix``, ``r.uv_matrix``, ``r.steps[i].matrix``,
        ``LimitSurface(...).evaluation_matrix(face, bary)``, ``limit_matrix(...)``, or any other.
    dtype : torch.float32 or torch.float64
    device : torch.device or str, optional

    Returns
    -------
    torch.Tensor
        Layout ``torch.sparse_csr``, shape (m, n).

    Examples
    --------
    >>> import numpy as np, torch, hybridsub, hybridsub.torch as ht
    >>> r = hybridsub.refine(np.array([[0, 1, 2]]), levels=1, scheme="loop")
    >>> S = ht.sparse(r.matrix)
    >>> S.layout, tuple(S.shape)
    (torch.sparse_csr, (6, 3))
    >>> X = torch.eye(3, dtype=torch.float64, requires_grad=True)
    >>> (S @ X).sum().backward()
    >>> X.grad[:, 0].tolist()          # column sums of S
    [2.0, 2.0, 2.0]
    """
    if not sp.issparse(M) or M.ndim != 2:
        raise TypeError(f"sparse takes a 2-D SciPy sparse matrix, got {type(M).__name__}")
    if dtype not in FLOATS:
        raise TypeError(f"dtype must be torch.float32 or torch.float64, got {dtype}")
    if not (np.issubdtype(M.dtype, np.floating) or np.issubdtype(M.dtype, np.integer)):
        raise TypeError(f"sparse takes a real matrix, got dtype {M.dtype}")
    C = sp.csr_matrix(M, copy=True)  # never the caller's arrays: sorting them would change its sums
    C.sum_duplicates()  # columns sorted in each row, as PyTorch's CSR expects
    index = np.int32 if max(C.shape[0], C.shape[1], C.nnz) < _INT32_MAX else np.int64
    with warnings.catch_warnings():  # "Sparse CSR tensor support is in beta state": known, and used as documented
        warnings.filterwarnings("ignore", message="Sparse CSR tensor support is in beta", category=UserWarning)
        return torch.sparse_csr_tensor(torch.from_numpy(C.indptr.astype(index)),
                                       torch.from_numpy(C.indices.astype(index)),
                                       torch.from_numpy(np.asarray(C.data, np.float64)).to(dtype), size=C.shape,
                                       device=device, check_invariants=False)


def _use_kernels(device: torch.device) -> bool:
    """Whether data on ``device`` is multiplied by the library's kernels (the CPU) rather than
    by PyTorch's sparse products (the tests run both on the CPU)."""
    return device.type == "cpu"


class _Kernels:
    """Matrices applied one after the other on the CPU by the library's own kernels (those of
    ``Refinement.apply``: coded stencils where the weights allow, else the threaded CSR
    product), in float64 as ``apply`` computes, the result in the data's dtype."""

    def __init__(self, mats: list):
        self.mats = mats

    def __call__(self, X: torch.Tensor) -> torch.Tensor:
        A = X.detach().to(torch.float64).contiguous().numpy()  # a view where X is float64 already
        for S in self.mats:
            A = apply_coded(S, A) if isinstance(S, CodedStencils) else apply_matrix(S, A)
        return torch.from_numpy(A).to(X.dtype)


class _Products:
    """Torch sparse CSR matrices applied one after the other (any device)."""

    def __init__(self, mats: list):
        self.mats = mats

    def __call__(self, X: torch.Tensor) -> torch.Tensor:
        for S in self.mats:
            X = S @ X
        return X


def _kernel_chains(mats: list[sp.csr_matrix]) -> tuple[_Kernels, _Kernels]:
    """The CPU forward (``S_L ⋯ S_1``) and backward (``S_1ᵀ ⋯ S_Lᵀ``) of a chain, as
    ``r.apply`` holds its steps from the second call on: the weights coded, each level
    between two numbered in the order the next product reads it."""
    forward = in_read_order(mats)
    backward = in_read_order([sp.csr_matrix(S.T) for S in reversed(mats)])
    return (_Kernels([coded_stencils(S) or S for S in forward]),
            _Kernels([coded_stencils(S) or S for S in backward]))


class _Chain(torch.autograd.Function):
    """``X ↦ forward(X)``, backward ``G ↦ backward(G)`` (itself a ``_Chain``, so twice
    differentiable); ``forward`` and ``backward`` apply a chain of matrices and its transpose."""

    @staticmethod
    def forward(ctx, X, forward, backward):
        ctx.chain = (forward, backward)
        return forward(X)

    @staticmethod
    def backward(ctx, G):
        forward, backward = ctx.chain
        return _Chain.apply(G, backward, forward), None, None


class Subdivide(torch.nn.Module):
    """A refinement as a differentiable layer: ``forward(X)`` is ``r.apply(X)``.

    The step matrices (or the given matrix) and their transposes are the module's buffers
    (torch sparse CSR, not saved in its ``state_dict``): ``.to(device)`` moves them,
    ``.float()`` casts them, and on a GPU the products are PyTorch's; data of the other float
    dtype is multiplied by a cast copy, made once per dtype and device. On the CPU the module
    multiplies with the library's own kernels instead, those of ``r.apply`` (in float64, the
    result in the data's dtype): the same sums and speed, forward and backward. The backward
    pass multiplies by the transposes (a custom autograd function), so
    ``torch.autograd.gradcheck`` and second derivatives pass.

    Parameters
    ----------
    source : hybridsub.Refinement or scipy.sparse matrix
        A refinement (its steps are applied one after the other, as ``r.apply`` does before
        ``r.matrix`` is formed), or one matrix of shape (m, n): ``r.matrix``, ``r.uv_matrix``,
        ``LimitSurface(...).evaluation_matrix(face, bary)``, ``limit_matrix(...)``.
    dtype : torch.float32 or torch.float64
        The buffers' dtype (default float64, the matrices' own).

    Attributes
    ----------
    n_in, n_out : int
        Rows of the data taken and given back.

    Examples
    --------
    >>> import numpy as np, torch, hybridsub, hybridsub.torch as ht
    >>> V, F = hybridsub.load_example()
    >>> r = hybridsub.refine(F, levels=1, scheme="loop")
    >>> sub = ht.Subdivide(r)
    >>> X = torch.tensor(V)
    >>> bool(torch.allclose(sub(X), torch.tensor(r.apply(V)), rtol=0, atol=1e-12))
    True
    >>> sub(torch.stack([X, 2 * X])).shape        # a batch of frames: (B, n, c)
    torch.Size([2, 25894, 3])
    >>> sub(X.float()).dtype
    torch.float32
    """

    def __init__(self, source, *, dtype: torch.dtype = torch.float64):
        super().__init__()
        if isinstance(source, Refinement):
            mats = [st.matrix for st in source.steps] or [sp.identity(source.n_coarse, format="csr")]
        elif sp.issparse(source) and source.ndim == 2:
            mats = [sp.csr_matrix(source)]
        else:
            raise TypeError("Subdivide takes a hybridsub.Refinement or a 2-D SciPy sparse matrix, "
                            f"got {type(source).__name__}")
        if dtype not in FLOATS:
            raise TypeError(f"dtype must be torch.float32 or torch.float64, got {dtype}")
        self.n_in, self.n_out = int(mats[0].shape[1]), int(mats[-1].shape[0])
        self.n_steps = len(mats)
        for i, S in enumerate(mats):
            self.register_buffer(f"S{i}", sparse(S, dtype=dtype), persistent=False)
            self.register_buffer(f"ST{i}", sparse(S.T, dtype=dtype), persistent=False)
        self._mats = mats
        self._casts: dict = {}
        self._kernels: tuple | None = None

    def _apply(self, fn, *args, **kwargs):  # .to(), .cuda(), .float(), ...: the casts are stale
        self._casts = {}
        return super()._apply(fn, *args, **kwargs)

    def _chain(self, dtype: torch.dtype, device: torch.device) -> tuple:
        forward = [getattr(self, f"S{i}") for i in range(self.n_steps)]
        if forward[0].device != device:
            raise ValueError(f"the data is on {device} and this Subdivide on {forward[0].device}: "
                             f"move one, e.g. sub.to({str(device)!r})")
        if _use_kernels(device):  # the library's kernels: r.apply's speed and sums
            if self._kernels is None:
                self._kernels = _kernel_chains(self._mats)
            return self._kernels
        backward = [getattr(self, f"ST{i}") for i in reversed(range(self.n_steps))]
        if forward[0].dtype != dtype:
            if dtype not in self._casts:
                self._casts[dtype] = ([S.to(dtype) for S in forward], [S.to(dtype) for S in backward])
            forward, backward = self._casts[dtype]
        return _Products(forward), _Products(backward)

    def forward(self, X: torch.Tensor) -> torch.Tensor:
        """``S @ X`` for (n_in, c) data, or each frame of (B, n_in, c) data: (n_out, c) or
        (B, n_out, c), X's dtype and device."""
        X = _data(X, self.n_in, "X")
        forward, backward = self._chain(X.dtype, X.device)
        return _batched(X, lambda Y: _Chain.apply(Y, forward, backward))

    def extra_repr(self) -> str:
        return f"n_in={self.n_in}, n_out={self.n_out}, steps={self.n_steps}"


def _data(X, n: int | None, name: str) -> torch.Tensor:
    """``X`` checked: a float32 or float64 tensor of shape (n, c) or (B, n, c)."""
    if not isinstance(X, torch.Tensor):
        hint = f" (torch.from_numpy({name}) makes one)" if isinstance(X, np.ndarray) else ""
        raise TypeError(f"{name} must be a torch.Tensor, got {type(X).__module__}.{type(X).__name__}{hint}")
    if X.dtype not in FLOATS:
        raise TypeError(f"{name} must be float32 or float64, got {X.dtype} ({name}.double() converts)")
    if X.layout != torch.strided:
        raise TypeError(f"{name} must be a dense tensor, got layout {X.layout}")
    if X.dim() not in (2, 3) or (n is not None and X.shape[-2] != n):
        k = "n" if n is None else n
        raise ValueError(f"{name} must have shape ({k}, c) or (B, {k}, c), got {tuple(X.shape)}")
    return X


def _batched(X: torch.Tensor, f) -> torch.Tensor:
    """``f`` (on (n, k) data) applied to (n, c) data, or to every frame of (B, n, c) data."""
    if X.dim() == 2:
        return f(X)
    B, n, c = X.shape
    Y = f(X.transpose(0, 1).reshape(n, B * c))
    return Y.reshape(Y.shape[0], B, c).transpose(0, 1)


class _Sequence:
    """Operators applied one after the other."""

    def __init__(self, ops: list):
        self.ops = ops

    def __call__(self, X: torch.Tensor) -> torch.Tensor:
        for op in self.ops:
            X = op(X)
        return X


#: Face arguments that may be a boolean mask instead of indices.
_MASKS = ("sharp_faces", "holes")


def _indices(x, name: str):
    """An integer tensor as NumPy (the rest as it is: the gate checks it)."""
    if isinstance(x, torch.Tensor):
        if x.dtype.is_floating_point or x.dtype.is_complex or (x.dtype == torch.bool and name not in _MASKS):
            raise TypeError(f"{name} must hold integer indices, got a tensor of {x.dtype}")
        return x.detach().cpu().numpy()
    return x


class _SharpChain(torch.autograd.Function):
    """``(X, s) ↦ S_L(s) ⋯ S_1(s) X`` (``forward``, ``backward``: each step's product and its
    transpose's): backward in ``X`` by the transposes, in ``s`` by each step's slopes
    (:func:`hybridsub._refiner.sharpness_steps`) between the level before and the gradient
    after it."""

    @staticmethod
    def forward(ctx, X, s, forward, backward, slopes):
        levels = [X]
        for S in forward:
            levels.append(S(levels[-1]))
        ctx.state = (levels[:-1], backward, slopes)
        ctx.sharp = (s.shape[0], s.dtype, s.device)
        return levels[-1]

    @staticmethod
    @torch.autograd.function.once_differentiable
    def backward(ctx, G):
        levels, backward, slopes = ctx.state
        ds = None
        if ctx.needs_input_grad[1]:
            ds = torch.zeros(ctx.sharp[0], dtype=G.dtype, device=G.device)
        for k in range(len(levels) - 1, -1, -1):
            if ds is not None:
                row, col, value, edge = slopes[k]
                ds.index_add_(0, edge, value * (G[row] * levels[k][col]).sum(1))
            G = backward[len(levels) - 1 - k](G)
        return G, None if ds is None else ds.to(dtype=ctx.sharp[1], device=ctx.sharp[2]), None, None, None


def subdivide(V: torch.Tensor, F, sharp_edges=None, *, sharpness: torch.Tensor | None = None, levels: int = 1,
              scheme: str = "hybrid", sharp_faces=None, corners=None, loop_weights: str = "loop",
              corner_sharpness=None, boundary: str = "edge_only", holes=None) -> tuple[torch.Tensor, torch.Tensor]:
    """:func:`hybridsub.subdivide`, differentiable in the positions and in the creases' sharpness.

    The topology and the tags are refined from ``F``, ``sharp_edges`` and the current
    sharpness values; the refined positions are the product of the step matrices with ``V``,
    differentiable in ``V`` (the transposes) and in ``sharpness``. Within a step a crease
    that decays (``0 < s ≤ 1`` left) enters its edge point and its two ends' vertex blends
    affinely, and a crease given with ``s`` has ``s − k`` at step ``k + 1``, so ``V2`` is
    affine in each crease's sharpness between integers: its derivative is exact, that of the
    piece ``(⌈s⌉ − 1, ⌈s⌉]`` holding ``s``, the derivative from below at an integer (where
    the decay moves to another level, and ``V2`` may jump). It is zero for ``s > levels``
    (``V2`` does not depend on it) and for infinite creases; an edge with ``s = 0`` is no
    crease and gets 0.

    Parameters
    ----------
    V : torch.Tensor, (n, c) or (B, n, c), float32 or float64
        Positions (or any per-vertex data), one frame or a batch; may require grad.
    F : (m, 3) array_like or integer tensor
        Triangles.
    sharp_edges : (k, 2) array_like or integer tensor, optional
        Creases as vertex pairs.
    sharpness : torch.Tensor, (k,), optional
        Their sharpness (default: infinite); may require grad.
    levels, scheme, sharp_faces, corners, loop_weights, corner_sharpness, boundary, holes
        As in :func:`hybridsub.subdivide` (the faces of holes are left out of ``F2``). With
        semi-sharp corners (finite ``corner_sharpness``) ``sharpness`` may not require grad.

    Returns
    -------
    V2 : torch.Tensor, (n', c) or (B, n', c)
        V's dtype and device.
    F2 : torch.Tensor, (m', 3) int64
        On V's device.

    Examples
    --------
    >>> import torch, hybridsub, hybridsub.torch as ht
    >>> V, F = hybridsub.load_example()
    >>> feat = hybridsub.detect_features(V, F, angle=30)
    >>> s = torch.full((len(feat.sharp_edges),), 1.5, dtype=torch.float64, requires_grad=True)
    >>> V2, F2 = ht.subdivide(torch.tensor(V), F, feat.sharp_edges, sharpness=s, levels=2, scheme="loop")
    >>> V2.sum().backward()
    >>> s.grad.shape, F2.shape
    (torch.Size([722]), torch.Size([207136, 3]))
    """
    V = _data(V, None, "V")
    n = V.shape[-2]
    if sharpness is not None:
        if not isinstance(sharpness, torch.Tensor):
            raise TypeError(f"sharpness must be a torch.Tensor (it may require grad), got {type(sharpness).__name__}"
                            " — torch.tensor(s, dtype=torch.float64) makes one")
        if not sharpness.dtype.is_floating_point:
            raise TypeError(f"sharpness must be a float tensor, got {sharpness.dtype}")
    F = _indices(F, "F")
    sharp_edges = _indices(sharp_edges, "sharp_edges")
    s_np = None if sharpness is None else sharpness.detach().cpu().double().numpy()
    cs = corner_sharpness.detach().cpu().numpy() if isinstance(corner_sharpness, torch.Tensor) else corner_sharpness
    inp = open_gate(F, sharp_edges, levels, n_vertices=n, scheme=scheme, sharpness=s_np,
                    sharp_faces=_indices(sharp_faces, "sharp_faces"), corners=_indices(corners, "corners"),
                    loop_weights=loop_weights, corner_sharpness=cs, boundary=boundary,
                    holes=_indices(holes, "holes"))
    want_s = sharpness is not None and sharpness.requires_grad and torch.is_grad_enabled()
    pairs, s_norm = as_sharp_edges(sharp_edges, s_np, n)
    steps = sharpness_steps(inp, pairs, s_norm, slopes=want_s)
    dtype, device = V.dtype, V.device
    kept = steps.faces if steps.hole is None else steps.faces[~steps.hole]
    F2 = torch.as_tensor(kept, dtype=torch.int64, device=device)
    if not steps.matrices:  # levels=0
        return V.clone(), F2
    if _use_kernels(device):
        forward = [_Kernels([S]) for S in steps.matrices]
        backward = [_Kernels([sp.csr_matrix(S.T)]) for S in reversed(steps.matrices)]
    else:
        forward = [_Products([sparse(S, dtype=dtype, device=device)]) for S in steps.matrices]
        backward = [_Products([sparse(S.T, dtype=dtype, device=device)]) for S in reversed(steps.matrices)]
    if not want_s:
        return _batched(V, lambda Y: _Chain.apply(Y, _Sequence(forward), _Sequence(backward))), F2
    slopes = [(torch.as_tensor(q.row, device=device), torch.as_tensor(q.col, device=device),
               torch.as_tensor(q.value, dtype=dtype, device=device), torch.as_tensor(q.edge, device=device))
              for q in steps.slopes]
    return _batched(V, lambda Y: _SharpChain.apply(Y, sharpness, forward, backward, slopes)), F2
