"""An atomic integer add for kernels whose threads count into shared arrays.

Private. ``atomic_add(x, i, value)`` adds ``value`` to ``x[i]`` of a one-dimensional integer
array as one indivisible read-modify-write (LLVM's ``atomicrmw add``, relaxed ordering: the
threads' totals are read after the parallel loop joins). Integer sums do not depend on the
order of their terms, so threads that each take a range of faces and count the vertices
those faces touch get the serial pass's counts exactly, without each walking every face.
The index is not checked: the kernels add at vertex indices the input gate has checked.

Examples
--------
>>> import numpy as np
>>> from numba import njit, prange
>>> @njit(parallel=True)
... def degrees(edges, n):
...     d = np.zeros(n, np.int64)
...     for e in prange(edges.shape[0]):
...         atomic_add(d, edges[e, 0], 1)
...         atomic_add(d, edges[e, 1], 1)
...     return d
>>> degrees(np.array([[0, 1], [1, 2], [2, 0], [0, 3]]), 4).tolist()
[3, 2, 2, 1]
"""

from __future__ import annotations

from numba.core import cgutils, config, types
from numba.extending import intrinsic


@intrinsic
def atomic_add(typingctx, x, at, value):
    """``x[at] += value`` for a 1-D integer array ``x``, atomically (``at`` not checked);
    returns what ``x[at]`` held before (so threads adding 1 each get a slot of their own)."""
    if not (isinstance(x, types.Array) and x.ndim == 1 and isinstance(x.dtype, types.Integer)
            and isinstance(at, types.Integer) and isinstance(value, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        array_type, at_type, value_type = signature.args
        array = context.make_array(array_type)(context, builder, args[0])
        index = context.cast(builder, args[1], at_type, types.intp)
        address = cgutils.get_item_pointer(context, builder, array_type, array, [index], wraparound=False,
                                           boundscheck=False)
        return builder.atomic_rmw("add", address, context.cast(builder, args[2], value_type, array_type.dtype),
                                  "monotonic")
    return x.dtype(x, at, value), codegen


if config.DISABLE_JIT:  # the kernels run as Python, on one thread
    def atomic_add(x, at, value):  # noqa: F811
        old = x[at]
        x[at] += value
        return old
