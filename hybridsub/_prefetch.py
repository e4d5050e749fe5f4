"""A software prefetch for kernels whose reads hop through an index array.

Private. ``prefetch(x, at)`` asks the processor to bring the cache line holding ``x.flat[at]``
closer (LLVM's ``llvm.prefetch``: a read, into every cache level). It reads and writes
nothing, cannot fault (an address past the array is a hint the processor drops), and changes
no result; it only pays where a loop's next addresses are known some iterations ahead but
each depends on a load that misses the caches: a twin halfedge's face, then that face's
vertex. Without ``prefetch`` such a chain waits on memory once per link, as the hardware
prefetchers do not follow indices.

Examples
--------
>>> import numpy as np
>>> from numba import njit
>>> @njit
... def gather(x, idx, ahead):
...     total = 0.0
...     for i in range(idx.shape[0]):
...         if i + ahead < idx.shape[0]:
...             prefetch(x, idx[i + ahead])
...         total += x[idx[i]]
...     return total
>>> gather(np.arange(10.0), np.array([9, 2, 5]), 2)
16.0
"""

from __future__ import annotations

import functools

from llvmlite import binding, ir
from numba.core import config, types
from numba.extending import intrinsic

_I32 = ir.IntType(32)
_BYTE_POINTER = ir.IntType(8).as_pointer()
_SIGNATURE = ir.FunctionType(ir.VoidType(), [_BYTE_POINTER, _I32, _I32, _I32])


def _declare(module: ir.Module) -> ir.Function:
    # llvmlite names the intrinsic for its own pointer mode (``llvm.prefetch.p0i8`` with typed
    # pointers, ``llvm.prefetch.p0`` with opaque ones)
    return module.declare_intrinsic("llvm.prefetch", [_BYTE_POINTER], _SIGNATURE)


@functools.lru_cache(maxsize=None)
def lowers() -> bool:
    """Whether this LLVM accepts the prefetch as :func:`prefetch` writes it: checked once, on
    a one-function module parsed and verified by llvmlite. Where not, :func:`prefetch`
    compiles to nothing (a hint dropped), never a failed kernel.

    Examples
    --------
    >>> lowers() in (True, False)
    True
    """
    try:
        module = ir.Module(name="prefetch_probe")
        fn = ir.Function(module, ir.FunctionType(ir.VoidType(), [_BYTE_POINTER]), name="probe")
        builder = ir.IRBuilder(fn.append_basic_block())
        builder.call(_declare(module), [fn.args[0], ir.Constant(_I32, 0), ir.Constant(_I32, 3), ir.Constant(_I32, 1)])
        builder.ret_void()
        binding.parse_assembly(str(module)).verify()
    except Exception:  # noqa: BLE001 - any refusal by this llvmlite/LLVM
        return False
    return True


@intrinsic
def prefetch(typingctx, x, at):
    """Prefetch the element ``at`` of C-contiguous array ``x`` (a flat index, not checked)."""
    if not (isinstance(x, types.Array) and isinstance(at, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        if lowers():
            data = context.make_array(signature.args[0])(context, builder, args[0]).data
            address = builder.bitcast(builder.gep(data, [args[1]]), _BYTE_POINTER)
            # a read (0), kept in every cache level (locality 3), of data (1)
            builder.call(_declare(builder.module),
                         [address, ir.Constant(_I32, 0), ir.Constant(_I32, 3), ir.Constant(_I32, 1)])
        return context.get_dummy_value()
    return types.void(x, at), codegen


if config.DISABLE_JIT:  # the kernels run as Python: a hint with nothing to do
    def prefetch(x, at):  # noqa: F811
        return None
