"""Weights applied: one step's refinement matrix S as CSR, or S applied to data directly.

Rows of S are stencils (OpenSubdiv's Far calls them so): row r holds the weights of the
coarse vertices that make fine vertex r, so that ``V_fine = S @ V_coarse``. Each row lists
its entries in the order the kernel sums them (a vertex itself, then its neighbours in edge
order), so ``apply_step(level, plan, X)`` and ``step_matrix(level, plan) @ X`` agree bit for
bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
import scipy.sparse as sp

from .._topology import Level, StepPlan, step_arguments, use_threads
from . import _stencil_kernels as K

#: Largest index a CSR matrix stores as int32 (above it, int64 indices).
INT32_LIMIT = np.iinfo(np.int32).max


def step_matrix(level: Level, plan: StepPlan) -> sp.csr_matrix:
    """The (n_new, n) refinement matrix of one step."""
    args = step_arguments(level, plan)
    shape = (plan.n_new, level.n_vertices)
    indptr = np.zeros(plan.n_new + 1, np.int64)
    K.matrix_row_sizes(*args, indptr)
    nnz = int(indptr[-1])
    index = np.int32 if max(shape[0], shape[1], nnz) < INT32_LIMIT else np.int64
    indices = np.empty(nnz, index)
    data = np.empty(nnz, np.float64)
    K.fill_matrix(*args, indptr, indices, data)
    S = sp.csr_matrix((data, indices, indptr.astype(index, copy=False)), shape=shape, copy=False)
    if S.indices.dtype != index:  # scipy narrows int64 indices whose values fit; keep the choice above
        S.indices, S.indptr = indices, indptr.astype(index, copy=False)
    return S


def apply_step(level: Level, plan: StepPlan, X: np.ndarray) -> np.ndarray:
    """``S @ X`` for (n, k) float64 data, without forming S."""
    X = np.ascontiguousarray(X, dtype=np.float64)
    out = np.empty((plan.n_new, X.shape[1]), np.float64)
    if use_threads(level.n_faces):
        K.apply_step(X, *step_arguments(level, plan), out, numba.get_num_threads(), level.far_apart)
    else:
        K.apply_step_serial(X, *step_arguments(level, plan), out, 1, level.far_apart)
    return out


def apply_matrix(S: sp.csr_matrix, X: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``S @ X`` for (n, k) float64 data, rows in parallel; the same bits as SciPy's product.
    ``out``: a C-contiguous (S.shape[0], k) float64 array to write it into."""
    X = np.ascontiguousarray(X, dtype=np.float64)
    out = np.empty((S.shape[0], X.shape[1]), np.float64) if out is None else out
    kernel = K.csr_apply if use_threads(S.shape[0]) else K.csr_apply_serial
    kernel(S.indptr, S.indices, S.data, X, out)
    return out


def product(A: sp.csr_matrix, B: sp.csr_matrix, fetch: bool = False) -> sp.csr_matrix:
    """``A @ B`` for CSR matrices, its columns sorted: SciPy's ``(A @ B)`` after
    ``sort_indices()`` to the bit (the same sums in the same order, exact zeros dropped),
    its rows computed on threads. ``fetch``: prefetch the rows of B that A's columns pick
    (the step's level's :attr:`~hybridsub._topology.Level.far_apart`, for a step matrix A).

    Examples
    --------
    >>> import numpy as np, scipy.sparse as sp
    >>> A = sp.random(40, 30, density=0.2, format="csr", random_state=1)
    >>> B = sp.random(30, 20, density=0.2, format="csr", random_state=2)
    >>> C, D = product(A, B), A @ B
    >>> D.sort_indices()
    >>> all(np.array_equal(x, y) for x, y in ((C.indptr, D.indptr), (C.indices, D.indices), (C.data, D.data)))
    True
    """
    m, n_cols = A.shape[0], B.shape[1]
    chunks = 4 * numba.get_num_threads() if use_threads(m) else 1
    # the inputs' indices all int32, or all int64 if one is (the kernels compile for two
    # signatures, not one per mix); the product's int64 if an input's are, as SciPy chooses
    wide = any(a.dtype != np.int32 for a in (A.indptr, A.indices, B.indptr, B.indices))
    a_ptr, a_idx, b_ptr, b_idx = (a.astype(np.int64 if wide else np.int32, copy=False)
                                  for a in (A.indptr, A.indices, B.indptr, B.indices))
    counts = np.empty(m, np.int64)
    K.product_pattern(a_ptr, a_idx, b_ptr, b_idx, n_cols, chunks, counts, fetch)
    indptr = np.zeros(m + 1, np.int64)
    np.cumsum(counts, out=indptr[1:])
    nnz = int(indptr[-1])
    index = np.int64 if wide or max(m, n_cols, nnz) >= INT32_LIMIT else np.int32
    indices = np.empty(nnz, index)
    data = np.empty(nnz, np.float64)
    kept = np.empty(m, np.int64)
    K.product_fill(a_ptr, a_idx, np.asarray(A.data, np.float64), b_ptr, b_idx, np.asarray(B.data, np.float64), n_cols,
                   chunks, indptr, indices, data, kept, fetch)
    if int(kept.sum()) < nnz:  # exact zero sums were dropped: close the gaps
        keep = np.arange(nnz) - np.repeat(indptr[:-1], counts) < np.repeat(kept, counts)
        indices, data = indices[keep], data[keep]
        np.cumsum(kept, out=indptr[1:])
    C = _as_is((m, n_cols), data, indices, indptr.astype(index, copy=False))
    C.has_sorted_indices = True
    return C


def in_read_order(steps: list[sp.csr_matrix]) -> list[sp.csr_matrix]:
    """The chain ``S_L ⋯ S_1`` with each level between two steps renumbered in the order the
    next step first reads its vertices: ``P_k S_k P_(k−1)ᵀ`` with ``P_0``, ``P_L`` the identity.

    Rows keep their entries in order, so multiplying the chain gives the same bits. A step
    numbers its new vertices edge by edge, so the next step's rows read a level of 10⁵–10⁶
    vertices all over; in read order they walk it almost in sequence.

    Examples
    --------
    >>> import numpy as np, hybridsub
    >>> V, F = hybridsub.load_example()
    >>> r = hybridsub.refine(F, levels=2)
    >>> S2, S1 = (s.matrix for s in reversed(r.steps))
    >>> T1, T2 = in_read_order([S1, S2])
    >>> np.array_equal(T2 @ (T1 @ V), S2 @ (S1 @ V))
    True
    """
    out = [sp.csr_matrix(S, copy=False) for S in steps]
    for k in range(len(out) - 1, 0, -1):
        nxt = out[k]
        first = np.full(nxt.shape[1], nxt.nnz, np.int64)
        np.minimum.at(first, nxt.indices, np.arange(nxt.nnz))
        order = np.argsort(first, kind="stable")  # new number → old
        renumber = np.empty_like(order)
        renumber[order] = np.arange(len(order))
        out[k] = _as_is(nxt.shape, nxt.data, renumber[nxt.indices].astype(nxt.indices.dtype), nxt.indptr)
        prev = out[k - 1]
        sizes = np.diff(prev.indptr)[order]
        indptr = np.zeros(len(order) + 1, prev.indptr.dtype)
        np.cumsum(sizes, out=indptr[1:])
        take = np.repeat(prev.indptr[:-1][order] - indptr[:-1], sizes) + np.arange(indptr[-1])
        out[k - 1] = _as_is(prev.shape, prev.data[take], prev.indices[take], indptr)
    return out


def _as_is(shape: tuple, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray) -> sp.csr_matrix:
    """A CSR matrix from these arrays as they are (SciPy's constructor may narrow them)."""
    M = sp.csr_matrix(shape, dtype=np.float64)
    M.data, M.indices, M.indptr = data, indices, indptr
    return M


#: Most distinct weights a coded matrix holds (its codes are uint16).
MAX_CODES = 1 << 16


@dataclass(frozen=True, eq=False)
class CodedStencils:
    """A CSR matrix whose distinct weights are stored once: entry ``q`` of row ``r`` is
    ``weights[codes[q]]`` at column ``indices[q]``. Refinement matrices hold few distinct
    weights (20 per Loop step, about 3,000 in three composed Loop steps on armadillo), so an
    entry costs 4 bytes (uint16 column and code) where CSR spends 12, and the product reads a
    third of the memory. Rows keep CSR's entry order: :func:`apply_coded` gives
    ``S @ X``'s bits."""

    indptr: np.ndarray  # (rows + 1,) int32 or int64, CSR's
    indices: np.ndarray  # (nnz,) uint16 where the columns allow, else CSR's
    codes: np.ndarray  # (nnz,) uint16
    weights: np.ndarray  # (distinct,) float64
    shape: tuple


def coded_stencils(S: sp.csr_matrix) -> CodedStencils | None:
    """``S`` with its weights coded, or None when it has more than ``MAX_CODES`` distinct ones.

    Weights are told apart by their bits (``-0.0`` is not ``0.0``), so decoding gives back
    exactly ``S.data``.
    """
    codes = np.empty(S.nnz, np.uint16)
    table = np.empty(min(MAX_CODES, max(S.nnz, 1)), np.int64)
    n = K.weight_codes(np.ascontiguousarray(S.data, np.float64).view(np.int64), codes, table)
    if n < 0:
        return None
    narrow = S.shape[1] <= MAX_CODES
    indices = S.indices.astype(np.uint16) if narrow else S.indices
    return CodedStencils(S.indptr, indices, codes, table[:n].view(np.float64).copy(), S.shape)


def apply_coded(C: CodedStencils, X: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``S @ X`` for (n, k) float64 data, bit for bit as :func:`apply_matrix` with S (``out``
    likewise)."""
    X = np.ascontiguousarray(X, dtype=np.float64)
    out = np.empty((C.shape[0], X.shape[1]), np.float64) if out is None else out
    threaded = use_threads(C.shape[0])
    if X.shape[1] == 3:  # a frame of positions: one row's three sums in one vector register
        x4 = np.zeros((X.shape[0], 4))
        x4[:, :3] = X
        kernel = K.coded_apply3 if threaded else K.coded_apply3_serial
        kernel(C.indptr, C.indices, C.codes, C.weights, x4.reshape(-1), out.reshape(-1))
    else:
        kernel = K.coded_apply if threaded else K.coded_apply_serial
        kernel(C.indptr, C.indices, C.codes, C.weights, X, out)
    return out
