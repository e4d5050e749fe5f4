"""Subdivision as a JAX function (``pip install "hybridsub[jax]"``).

:func:`subdivide_fn` turns a :class:`hybridsub.Refinement` (or any SciPy sparse matrix)
into a function ``X ↦ S X`` built from ``jax.ops.segment_sum``, so that ``jax.jit``,
``jax.grad`` (and every other transformation: ``vmap``, ``jvp``, ``jacfwd``) work on it:
JAX differentiates the gather and the segment sum itself. See ``docs/differentiable.md``.

>>> import jax, jax.numpy as jnp, hybridsub, hybridsub.jax as hj
>>> V, F = hybridsub.load_example()
>>> f = hj.subdivide_fn(hybridsub.refine(F, levels=1))
>>> X = jnp.asarray(V, jnp.float32)
>>> jax.jit(f)(X).shape
(19421, 3)
>>> jax.grad(lambda X: jnp.sum(f(X) ** 2))(X).shape
(6475, 3)

Importing this module imports JAX; ``import hybridsub`` does not. float64 data needs
``jax.config.update("jax_enable_x64", True)`` (JAX's default is float32).
"""

from __future__ import annotations

try:
    import jax
    import jax.numpy as jnp
except ImportError as e:  # pragma: no cover - the adapters' CI installs jax
    raise ImportError('hybridsub.jax needs JAX: pip install "hybridsub[jax]"') from e

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ._refiner import Refinement

__all__ = ["subdivide_fn"]


def _chain(source) -> list[sp.csr_matrix]:
    """The matrices ``source`` applies, first one first."""
    if isinstance(source, Refinement):
        return [st.matrix for st in source.steps] or [sp.identity(source.n_coarse, format="csr")]
    if sp.issparse(source) and source.ndim == 2:
        return [sp.csr_matrix(source)]
    raise TypeError("subdivide_fn takes a hybridsub.Refinement or a 2-D SciPy sparse matrix, "
                    f"got {type(source).__name__}")


def subdivide_fn(source) -> Callable:
    """``X ↦ S X`` as a JAX function: the refinement's steps (or the given matrix).

    Parameters
    ----------
    source : hybridsub.Refinement or scipy.sparse matrix
        A refinement (its step matrices applied one after the other), or one (m, n) matrix:
        ``r.matrix``, ``r.uv_matrix``, ``LimitSurface(...).evaluation_matrix(face, bary)``,
        ``limit_matrix(...)``.

    Returns
    -------
    callable
        ``f(X)`` for (n, ...) float32 or float64 data (a JAX or NumPy array): (m, ...) in
        X's dtype, ``r.apply(X)`` to rounding. Works under ``jax.jit``, ``jax.grad``,
        ``jax.vmap`` (a batch of frames: ``jax.vmap(f)(X)`` for (B, n, c)) and forward mode.
        The matrices are held as device arrays, one copy per dtype used; under ``jit`` they
        are constants of the compiled function.

    Examples
    --------
    >>> import numpy as np, jax, jax.numpy as jnp, hybridsub, hybridsub.jax as hj
    >>> r = hybridsub.refine(np.array([[0, 1, 2]]), levels=1, scheme="loop")
    >>> f = hj.subdivide_fn(r)
    >>> X = jnp.eye(3, dtype=jnp.float32)
    >>> bool(jnp.allclose(f(X), r.apply(np.eye(3))))
    True
    >>> jax.vmap(f)(jnp.stack([X, 2 * X])).shape
    (2, 6, 3)
    """
    mats = _chain(source)
    n = int(mats[0].shape[1])
    parts = [(np.repeat(np.arange(S.shape[0], dtype=np.int32), np.diff(S.indptr)), S.indices.astype(np.int32),
              np.asarray(S.data, np.float64), int(S.shape[0])) for S in mats]
    held: dict = {}

    def arrays(dtype):
        if dtype not in held:
            with jax.ensure_compile_time_eval():
                held[dtype] = [(jnp.asarray(row), jnp.asarray(col), jnp.asarray(data.astype(dtype)), m)
                               for row, col, data, m in parts]
        return held[dtype]

    def f(X):
        X = jnp.asarray(X)
        if X.dtype not in (np.float32, np.float64):
            raise TypeError(f"X must be float32 or float64 data, got {X.dtype}")
        if X.ndim < 1 or X.shape[0] != n:
            raise ValueError(f"X must have shape ({n}, ...) (one row per vertex), got {tuple(X.shape)}")
        tail = X.shape[1:]
        Y = X.reshape(n, -1)
        for row, col, data, m in arrays(np.dtype(X.dtype)):
            Y = jax.ops.segment_sum(data[:, None] * Y[col], row, num_segments=m, indices_are_sorted=True)
        return Y.reshape((Y.shape[0],) + tail)

    return f
