"""Numbers for messages: bytes, rates and counts with decimal (SI) prefixes.

Every message of the package that prints a size or a speed formats it here, so the same
quantity reads the same in an error of the refiner and in a line of the command line.

>>> fmt_bytes(8e9), bytes_and_count(8e9), short_bytes(512), si(1.25e6), rate(1.25e6)
('8.0 GB', '8.0 GB (8,000,000,000 bytes)', '512 B', '1.2 M', '1.25 M')
"""

from __future__ import annotations

import math

_PREFIXES = (("T", 1e12), ("G", 1e9), ("M", 1e6), ("k", 1e3))


def _prefixed(x: float, largest: str) -> tuple[float, str] | None:
    """``x`` in the largest decimal prefix from ``largest`` down to k that it reaches, or None."""
    start = next(i for i, (p, _) in enumerate(_PREFIXES) if p == largest)
    for prefix, size in _PREFIXES[start:]:
        if x >= size:
            return x / size, prefix
    return None


def fmt_bytes(x: float) -> str:
    """``'8.0 GB'``, ``'512 bytes'``; ``'unlimited'`` for inf (a memory limit that is off).

    >>> fmt_bytes(1.5e12), fmt_bytes(999), fmt_bytes(math.inf)
    ('1.5 TB', '999 bytes', 'unlimited')
    """
    if not math.isfinite(x):
        return "unlimited"
    p = _prefixed(x, "T")
    return f"{int(x)} bytes" if p is None else f"{p[0]:.1f} {p[1]}B"


def bytes_and_count(x: float) -> str:
    """``'8.0 GB (8,000,000,000 bytes)'``, or just ``'512 bytes'``: a size in an error message.

    >>> bytes_and_count(2048), bytes_and_count(100)
    ('2.0 kB (2,048 bytes)', '100 bytes')
    """
    short = fmt_bytes(x)
    return short if short.endswith("bytes") or not math.isfinite(x) else f"{short} ({x:,.0f} bytes)"


def short_bytes(x: float) -> str:
    """``'8.0 GB'``, ``'512 B'``: a size in a table or a one-line message (GB at most).

    >>> short_bytes(2.5e12), short_bytes(3e6)
    ('2500.0 GB', '3.0 MB')
    """
    p = _prefixed(x, "G")
    return f"{int(x)} B" if p is None else f"{p[0]:.1f} {p[1]}B"


def si(x: float) -> str:
    """``'1.2 M'``, ``'950'``: a count or a rate, one decimal (G at most).

    >>> si(3.4e9), si(12_345), si(7.6)
    ('3.4 G', '12.3 k', '8')
    """
    p = _prefixed(x, "G")
    return f"{x:.0f}" if p is None else f"{p[0]:.1f} {p[1]}"


def rate(x: float) -> str:
    """``'1.25 M'``, ``'12 k'``, ``'950'``: faces per second after a run (M at most).

    >>> rate(2.5e9), rate(12_345), rate(950)
    ('2500.00 M', '12 k', '950')
    """
    p = _prefixed(x, "M")
    if p is None:
        return f"{x:.0f}"
    return f"{p[0]:.2f} M" if p[1] == "M" else f"{p[0]:.0f} k"
