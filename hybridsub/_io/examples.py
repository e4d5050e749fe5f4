"""The example meshes shipped with the package."""

from __future__ import annotations

from importlib import resources

import numpy as np

from .off import read_off


def example_names() -> list[str]:
    """The names of the shipped example meshes.

    >>> example_names()
    ['cube', 'fandisk', 'icosahedron']
    """
    data = resources.files("hybridsub").joinpath("data")
    return sorted(p.name[:-4] for p in data.iterdir() if p.name.endswith(".off"))


def example_path(name: str = "fandisk") -> str:
    """Path of a shipped example mesh (``"fandisk"``: 6475 vertices, 12946 faces; ``"cube"``:
    866 vertices, 1728 faces; ``"icosahedron"``: 12 vertices, 20 faces).

    >>> example_path("bunny")
    Traceback (most recent call last):
    ...
    ValueError: no example mesh named 'bunny'; the examples are: 'cube', 'fandisk', 'icosahedron'
    """
    names = example_names()
    if name not in names:
        raise ValueError(f"no example mesh named {name!r}; the examples are: " + ", ".join(map(repr, names)))
    return str(resources.files("hybridsub").joinpath("data", f"{name}.off"))


def load_example(name: str = "fandisk") -> tuple[np.ndarray, np.ndarray]:
    """Load a shipped example mesh as ``(V, F)``.

    Parameters
    ----------
    name : str
        The example's name: ``"fandisk"`` (the default, 6475 vertices, 12946 faces, the CAD
        part of Hoppe et al. with 722 creases at 30°) or ``"cube"`` (866 vertices, 1728 faces:
        a meshed CAD cube, its edges creases at 30°, small enough for quick examples) or
        ``"icosahedron"`` (12 vertices, 20 faces, on the unit sphere).

    Raises
    ------
    ValueError
        No example of that name; the message lists the examples.

    Examples
    --------
    >>> V, F = load_example()
    >>> V.shape, F.shape
    ((6475, 3), (12946, 3))
    """
    return read_off(example_path(name))
