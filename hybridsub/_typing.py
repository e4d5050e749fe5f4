"""Type aliases of the public API, and the names of the schemes.

NumPy's typing names (``ArrayLike``, ``NDArray``, ``np``) are imported on first use, so that
the command line can read :data:`SCHEMES` without loading NumPy (``hybridsub --help``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal, Union, get_args

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import ArrayLike, NDArray

Scheme = Literal["hybrid", "sqrt3", "loop"]
LoopWeights = Literal["loop", "warren"]
NonManifold = Literal["raise", "cut"]
UVMode = Literal["linear", "smooth"]
Boundary = Literal["edge_only", "edge_and_corner", "none"]
#: Bytes, or a string such as ``"16G"`` or ``"none"`` (see ``set_memory_limit``).
MemoryLimit = Union[int, float, str, None]

#: The schemes, in the order the command line lists them.
SCHEMES: tuple[str, ...] = get_args(Scheme)

__all__ = ["ArrayLike", "NDArray", "np", "Scheme", "LoopWeights", "NonManifold", "UVMode", "Boundary", "MemoryLimit", "SCHEMES"]


def __getattr__(name: str) -> Any:
    if name == "np":
        import numpy

        return numpy
    if name in ("ArrayLike", "NDArray"):
        import numpy.typing

        return getattr(numpy.typing, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
