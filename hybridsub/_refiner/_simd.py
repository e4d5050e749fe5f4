"""Four float64 lanes in one register, for kernels whose sums must keep their bits.

Private. ``Vec4`` is a Numba type whose value is LLVM's ``<4 x double>``, so a loop that
carries one keeps it in a vector register (a tuple of four floats is rebuilt from scalars on
every iteration). :func:`madd4` multiplies four consecutive values of an array by one weight
and adds them to the lanes: a multiply, then an add, each rounded as the scalar operations
are (no fused multiply-add: LLVM contracts only under fast-math flags, which these
operations do not carry), so each lane's sum has the bits of the scalar loop that adds the
same terms in the same order.

Examples
--------
>>> import numpy as np
>>> from numba import njit
>>> @njit
... def dot_rows(x4, w):
...     acc = vzero()
...     for i in range(w.shape[0]):
...         acc = madd4(acc, w[i], x4, np.uintp(4 * i))
...     return lane(acc, 0), lane(acc, 1), lane(acc, 2)
>>> dot_rows(np.arange(8.0), np.array([0.5, 2.0]))
(8.0, 10.5, 13.0)
"""

from __future__ import annotations

import numpy as np
from llvmlite import ir
from numba.core import config, types
from numba.extending import intrinsic, models, register_model

_V4 = ir.VectorType(ir.DoubleType(), 4)


class Vec4Type(types.Type):
    """Four float64 lanes (LLVM ``<4 x double>``)."""

    def __init__(self):
        super().__init__(name="Vec4")


vec4 = Vec4Type()


@register_model(Vec4Type)
class _Vec4Model(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _V4)


@intrinsic
def vzero(typingctx):
    """Four zero lanes."""
    def codegen(context, builder, signature, args):
        return ir.Constant(_V4, [0.0] * 4)
    return vec4(), codegen


@intrinsic
def madd4(typingctx, acc, w, x, at):
    """``acc + w * x[at:at + 4]`` lane by lane; ``x`` a 1-D float64 array, ``at`` an index
    (the caller keeps ``at + 4 <= len(x)``: no bounds check)."""
    if not (isinstance(acc, Vec4Type) and isinstance(x, types.Array) and x.dtype == types.float64
            and x.ndim == 1 and isinstance(at, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        accv, wv, xarr, atv = args
        data = context.make_array(signature.args[2])(context, builder, xarr).data
        xv = builder.load(builder.bitcast(builder.gep(data, [atv]), _V4.as_pointer()), align=8)
        splat = ir.Constant(_V4, ir.Undefined)
        for i in range(4):
            splat = builder.insert_element(splat, wv, ir.Constant(ir.IntType(32), i))
        return builder.fadd(accv, builder.fmul(splat, xv))
    return vec4(vec4, types.float64, x, at), codegen


@intrinsic
def lane(typingctx, acc, i):
    """Lane ``i`` of ``acc`` as a float64."""
    if not (isinstance(acc, Vec4Type) and isinstance(i, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        return builder.extract_element(args[0], args[1])
    return types.float64(vec4, i), codegen


if config.DISABLE_JIT:  # the kernels run as Python: the same operations on a NumPy array
    def vzero():  # noqa: F811
        return np.zeros(4)

    def madd4(acc, w, x, at):  # noqa: F811
        return acc + w * x[at:at + 4]

    def lane(acc, i):  # noqa: F811
        return float(acc[i])
