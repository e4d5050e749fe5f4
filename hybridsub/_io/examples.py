"""The example mesh shipped with the package."""

from __future__ import annotations

from importlib import resources

import numpy as np

from .off import read_off


def example_path(name: str = "fandisk") -> str:
    """Path of a shipped example mesh (``"fandisk"``: 6475 vertices, 12946 faces)."""
    return str(resources.files("hybridsub").joinpath("data", f"{name}.off"))


def load_example(name: str = "fandisk") -> tuple[np.ndarray, np.ndarray]:
    """Load a shipped example mesh as ``(V, F)``.

    Examples
    --------
    >>> V, F = load_example()
    >>> V.shape, F.shape
    ((6475, 3), (12946, 3))
    """
    return read_off(example_path(name))
