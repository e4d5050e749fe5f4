"""Weights applied: one step's refinement matrix S as CSR, or S applied to data directly.

Rows of S are stencils (OpenSubdiv's Far calls them so): row r holds the weights of the
coarse vertices that make fine vertex r, so that ``V_fine = S @ V_coarse``. Each row lists
its entries in the order the kernel sums them (a vertex itself, then its neighbours in edge
order), so ``apply_step(level, plan, X)`` and ``step_matrix(level, plan) @ X`` agree bit for
bit.
"""

from __future__ import annotations

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
        K.apply_step(X, *step_arguments(level, plan), out, numba.get_num_threads())
    else:
        K.apply_step_serial(X, *step_arguments(level, plan), out, 1)
    return out


def apply_matrix(S: sp.csr_matrix, X: np.ndarray) -> np.ndarray:
    """``S @ X`` for (n, k) float64 data, rows in parallel; the same bits as SciPy's product."""
    X = np.ascontiguousarray(X, dtype=np.float64)
    out = np.empty((S.shape[0], X.shape[1]), np.float64)
    kernel = K.csr_apply if use_threads(S.shape[0]) else K.csr_apply_serial
    kernel(S.indptr, S.indices, S.data, X, out)
    return out
