"""Exceptions of the public API."""

from __future__ import annotations


class MeshError(ValueError):
    """The mesh or its tags cannot be subdivided as given.

    The message names the problem: which face, which edge (as a vertex pair), which index.
    It is a ``ValueError``, so ``except ValueError`` catches it too.
    """
