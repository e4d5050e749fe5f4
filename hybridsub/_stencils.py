"""Weights applied: one step's refinement matrix S as CSR, or S applied to data directly.

Rows of S are stencils (OpenSubdiv's Far calls them so): row r holds the weights of the
coarse vertices that make fine vertex r, so that ``V_fine = S @ V_coarse``. Each row lists
its entries in the order the kernel sums them (a vertex itself, then its neighbours in edge
order), so ``apply_step(level, plan, X)`` and ``step_matrix(level, plan) @ X`` agree bit for
bit.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from . import _kernels as K
from ._topology import Level, StepPlan, step_arguments

#: Largest index a CSR matrix stores as int32 (above it, int64 indices).
INT32_LIMIT = np.iinfo(np.int32).max


def step_matrix(level: Level, plan: StepPlan) -> sp.csr_matrix:
    """The (n_new, n) refinement matrix of one step."""
    indptr, indices, data = K.build_matrix(*step_arguments(level, plan))
    return _csr(data, indices, indptr, (plan.n_new, level.n_vertices))


def apply_step(level: Level, plan: StepPlan, X: np.ndarray) -> np.ndarray:
    """``S @ X`` for (n, k) float64 data, without forming S."""
    return K.apply_step(np.ascontiguousarray(X, dtype=np.float64), *step_arguments(level, plan))


def _csr(data, indices, indptr, shape) -> sp.csr_matrix:
    """Wrap CSR arrays without scipy re-checking them; int32 indices where they fit."""
    if max(shape[0], shape[1], len(data)) < INT32_LIMIT:
        indices = indices.astype(np.int32)
        indptr = indptr.astype(np.int32)
    return sp.csr_matrix((data, indices, indptr), shape=shape, copy=False)
