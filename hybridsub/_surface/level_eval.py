"""The general evaluation of one level: the plan of its vertices (``mask_plan``), their
stationary masks, and local refinement (``local``) where a vertex has none."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .limit_setup import LimitSetup
from .local import plan_vertices, refine_locally
from .mask_plan import SEC_TRANSIENT, LimitPlan
from .normals import sector_normals


def evaluate_level(s: LimitSetup, scheme: str, loop_weights: str, X: np.ndarray | None, want_rows: bool, tol: float,
                   max_levels: int, only: np.ndarray | None = None, plan: LimitPlan | None = None):
    """Limit matrix (n × n CSR, or None), plan and sector normals (or None) of the level evaluated.

    With ``only`` (a vertex mask), just those vertices are refined locally where they need it:
    the rows and normals of the others are not theirs (``s`` may hold only the faces around
    ``only``). ``plan``: the level's plan, if made already.

    Examples
    --------
    >>> import numpy as np
    >>> from hybridsub._surface.limit_setup import setup_limit
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])
    >>> s = setup_limit(F, None, 0, 4, "loop", None, None, None, "loop")
    >>> L, plan, nrm = evaluate_level(s, "loop", "loop", None, True, 1e-12, 60)
    >>> L.toarray()[0].round(4).tolist(), nrm is None
    ([0.4, 0.2, 0.2, 0.2], True)
    """
    level = s.level
    n = level.n_vertices
    if plan is None:
        plan = plan_vertices(level, s.esharp, s.face_sharp, s.corner, scheme, loop_weights)
    nrm = sector_normals(level, plan, X) if X is not None else None
    need = np.zeros(n, dtype=bool)
    if want_rows:
        need |= ~plan.pos_ok
    if X is not None:
        need[plan.sectors.vertex[plan.sec_kind == SEC_TRANSIENT]] = True
    if only is not None:
        need &= only
    centers = np.flatnonzero(need)
    rows = None
    if len(centers):
        rows, est = refine_locally(level, s.tagged, s.face_sharp, s.corner, scheme, loop_weights, centers, plan, X,
                                   want_rows, tol, max_levels)
        if X is not None:
            t = plan.sec_kind == SEC_TRANSIENT
            nrm[t] = est[t]
    if not want_rows:
        return None, plan, nrm
    L = plan.limit_csr(n)
    if rows is not None:
        moved = sp.csr_matrix((np.ones(len(centers)), (centers, np.arange(len(centers)))), shape=(n, len(centers)))
        L = L + moved @ rows
    L = sp.csr_matrix(L)
    L.sum_duplicates()
    L.sort_indices()
    return L, plan, nrm
