"""Weights: one step's refinement matrix S, built directly as CSR from a StepPlan.

Rows of S are stencils (OpenSubdiv's Far calls them so): row r holds the weights of the
coarse vertices that make fine vertex r, so that ``V_fine = S @ V_coarse``.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from . import _kernels as K
from ._topology import Level, StepPlan


def step_matrix(level: Level, plan: StepPlan) -> sp.csr_matrix:
    """The (n_new, n) refinement matrix of one step, columns sorted within each row."""
    cs, cn = plan.crease_mask
    indptr, indices, data = K.build_matrix(
        level.n_vertices, plan.n_new, level.faces, level.twin, level.edge_owner, level.ve_start,
        level.ve_edges, plan.esharp, plan.kind, plan.edge_point, plan.face_point, plan.bnext, plan.bprev,
        plan.rule_parent, plan.rule_child, plan.blend, plan.smooth_weight, float(cs), float(cn),
    )
    return _csr(data, indices, indptr, (plan.n_new, level.n_vertices))


def _csr(data, indices, indptr, shape) -> sp.csr_matrix:
    """Wrap CSR arrays without scipy re-checking them; int32 indices where they fit."""
    if max(shape[1], len(data)) < np.iinfo(np.int32).max:
        indices = indices.astype(np.int32)
        indptr = indptr.astype(np.int32)
    S = sp.csr_matrix((data, indices, indptr), shape=shape, copy=False)
    S.has_sorted_indices = True
    S.has_canonical_format = True
    return S
