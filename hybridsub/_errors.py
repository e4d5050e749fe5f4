"""Exceptions of the public API (every one is listed in ``docs/errors.md``)."""

from __future__ import annotations


class MeshError(ValueError):
    """The mesh or its tags cannot be subdivided as given.

    The message names the problem: which face, which edge (as a vertex pair), which index.
    It is a ``ValueError``, so ``except ValueError`` catches it too.
    """


class OutputTooLargeError(MemoryError, ValueError):
    """The refined mesh would need more memory than the configured limit allows.

    Raised before anything large is allocated. The message gives the estimated and the
    allowed number of bytes and how to raise the limit (``max_memory=``,
    :func:`hybridsub.set_memory_limit` or the environment variable ``HYBRIDSUB_MAX_MEMORY``).
    It is both a ``MemoryError`` and a ``ValueError`` (the request, not the machine, is at
    fault), so either ``except`` clause catches it.
    """
