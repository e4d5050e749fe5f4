"""The progress bar of a refinement: tqdm (a line on a terminal, a widget in a notebook), one
tick per level. tqdm is imported only when a bar is shown."""

from __future__ import annotations

import sys
from contextlib import nullcontext
from typing import Any


def level_bar(levels: int, progress: bool | None, desc: str) -> Any:
    """A tqdm bar over ``levels`` levels (``update(1)`` per level, faces shown), or a do-nothing
    context where ``progress`` is false. ``progress=None``: a bar only where stderr is a terminal.

    >>> with level_bar(2, False, "hybrid") as bar:
    ...     bar is None
    True
    """
    if progress is None:
        progress = sys.stderr.isatty()
    if not progress or levels <= 0:
        return nullcontext()
    from tqdm.auto import tqdm

    return tqdm(total=levels, desc=desc, unit="level", leave=False, mininterval=0)


def tick(bar: Any, n_faces: int) -> None:
    """Advance ``bar`` by one level, showing the faces made (nothing for a do-nothing bar)."""
    if bar is not None:
        bar.set_postfix_str(f"{n_faces:,} faces", refresh=False)
        bar.update(1)
