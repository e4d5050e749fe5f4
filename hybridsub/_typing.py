"""Type aliases of the public API."""

from __future__ import annotations

from typing import Literal, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

Scheme = Literal["hybrid", "sqrt3", "loop"]
LoopWeights = Literal["loop", "warren"]
NonManifold = Literal["raise", "cut"]
UVMode = Literal["linear", "smooth"]
#: Bytes, or a string such as ``"16G"`` or ``"none"`` (see ``set_memory_limit``).
MemoryLimit = Union[int, float, str, None]

__all__ = ["ArrayLike", "NDArray", "np", "Scheme", "LoopWeights", "NonManifold", "UVMode", "MemoryLimit"]
