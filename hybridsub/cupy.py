"""Refinement on a GPU with CuPy: ``hybridsub.cupy.apply(r, X)``.

The step matrices of a :class:`hybridsub.Refinement` (or a given SciPy sparse matrix) are
copied to the GPU on the first call, as ``cupyx.scipy.sparse`` CSR matrices, and kept there
for every later frame (one copy per device and dtype, dropped with the refinement), so a
frame costs its own transfer, if it is not on the GPU already, and the sparse products.
CuPy is imported on the first call, not with this module. Not yet run on a GPU by the
project's tests (they run it against a stand-in for CuPy): see ``docs/differentiable.md``.
"""

from __future__ import annotations

import weakref

import numpy as np
import scipy.sparse as sp

from ._refiner import Refinement

__all__ = ["apply"]

_INSTALL = ("hybridsub.cupy needs CuPy and a GPU: pip install cupy-cuda12x (or the package for your CUDA or "
            "ROCm version, see https://docs.cupy.dev/en/stable/install.html)")

#: The matrices on the GPU of the given SciPy matrices: id → {(device id, dtype): [cupyx CSR]}
#: (SciPy's matrices cannot be dictionary keys; an entry goes with its matrix). A refinement
#: keeps its own in its cache.
_HELD: dict = {}


def _cupy():
    try:
        import cupy
        import cupyx.scipy.sparse
    except ImportError as e:
        raise ImportError(_INSTALL) from e
    return cupy, cupyx.scipy.sparse


def _chain(source) -> list[sp.csr_matrix]:
    if isinstance(source, Refinement):
        return [st.matrix for st in source.steps] or [sp.identity(source.n_coarse, format="csr")]
    if sp.issparse(source) and source.ndim == 2:
        return [sp.csr_matrix(source)]
    raise TypeError(f"apply takes a hybridsub.Refinement or a 2-D SciPy sparse matrix, got {type(source).__name__}")


def _held(source) -> dict:
    """Where the GPU copies of ``source``'s matrices are kept."""
    if isinstance(source, Refinement):
        return source._cache.setdefault("cupy", {})
    key = id(source)
    if key not in _HELD:
        _HELD[key] = {}
        weakref.finalize(source, _HELD.pop, key, None)
    return _HELD[key]


def apply(source, X):
    """``S @ X`` on the GPU, the matrices kept there between calls.

    Parameters
    ----------
    source : hybridsub.Refinement or scipy.sparse matrix
        A refinement (its steps applied one after the other, as ``r.apply`` does before
        ``r.matrix`` is formed), or one (m, n) matrix (``r.matrix``, ``r.uv_matrix``, rows of
        a limit surface).
    X : cupy.ndarray or array_like, (n, ...)
        Per-vertex data; NumPy data is copied to the current device. float32 and float64 keep
        their dtype, other real data is computed in float64.

    Returns
    -------
    cupy.ndarray, (m, ...)
        On the current device.

    Examples
    --------
    >>> import hybridsub, hybridsub.cupy as hc       # doctest: +SKIP
    >>> V, F = hybridsub.load_example()               # doctest: +SKIP
    >>> r = hybridsub.refine(F, levels=2)             # doctest: +SKIP
    >>> V2 = hc.apply(r, V)                           # doctest: +SKIP
    >>> bool(abs(V2.get() - r.apply(V)).max() < 1e-12)   # doctest: +SKIP
    True
    """
    cp, csp = _cupy()
    chain = _chain(source)
    n = chain[0].shape[1]
    A = X if isinstance(X, cp.ndarray) else cp.asarray(np.asarray(X))
    if A.dtype.kind == "c" or A.dtype.kind not in "fiub":
        raise TypeError(f"X must hold real numbers, got dtype {A.dtype}")
    if A.dtype not in (np.float32, np.float64):
        A = A.astype(np.float64)
    if A.ndim < 1 or A.shape[0] != n:
        raise ValueError(f"X must have shape ({n}, ...) (one row per vertex), got {tuple(A.shape)}")
    key = (cp.cuda.Device().id, np.dtype(A.dtype).str)
    held = _held(source)
    if key not in held:
        if max(S.nnz for S in chain) > np.iinfo(np.int32).max:
            raise ValueError("a matrix of more than 2³¹ entries: CuPy's CSR indices are int32; apply the steps "
                             "(pass the Refinement, not r.matrix)")
        held[key] = [csp.csr_matrix((cp.asarray(S.data.astype(A.dtype)), cp.asarray(S.indices.astype(np.int32)),
                                     cp.asarray(S.indptr.astype(np.int32))), shape=S.shape) for S in chain]
    Y = A.reshape(n, -1)
    for S in held[key]:
        Y = S @ Y
    return Y.reshape((Y.shape[0],) + tuple(A.shape[1:]))
