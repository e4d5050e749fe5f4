"""Memory budget: estimate what a refinement will need before allocating it, refuse above a limit.

The limit, in bytes, is taken from (first found):

1. the ``max_memory=`` argument of ``refine`` / ``subdivide``;
2. :func:`set_memory_limit`;
3. the environment variable ``HYBRIDSUB_MAX_MEMORY`` (read at every call);
4. 80 % of the machine's physical memory (8 GiB where that cannot be read) — the threshold
   the command line's own check uses; the estimate errs high, so this is not a tight fit.

A limit is a number of bytes, or a string such as ``"16G"``, ``"16GB"`` (10⁹), ``"16GiB"``
(2³⁰), ``"1.5e10"``; ``inf`` or ``"none"`` turns the check off.

The estimate (:func:`estimate`) follows the counts of ``docs/scheme.md`` — a smooth face makes
``3 + s`` faces, a sharp face 4, ``|V'| = |V| + |split edges| + |face points|`` — exactly for the
next step and as an upper bound for the steps after it (every split edge still split, every
crease still a crease). It adds what the finished :class:`~hybridsub.Refinement` keeps (faces,
face parents, tags and the matrix of every step), the largest temporary tables of one step, and
two position arrays of the finest level. It errs on the high side; it is a guard against
asking for levels that cannot fit, not an exact account.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from dataclasses import dataclass

import numpy as np

from .._rules import refinement as R
from . import stencils as _stencils
from .._errors import OutputTooLargeError
from .._typing import MemoryLimit

ENV_VAR = "HYBRIDSUB_MAX_MEMORY"
DEFAULT_FRACTION = 0.8
FALLBACK_LIMIT = 8 * 2**30

_limit: float | None = None  # set by set_memory_limit; None: environment or default

_UNITS = {"": 1, "b": 1, "k": 10**3, "kb": 10**3, "m": 10**6, "mb": 10**6, "g": 10**9, "gb": 10**9,
          "t": 10**12, "tb": 10**12, "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}


def parse_limit(value, source: str = "max_memory") -> float:
    """A memory limit in bytes (``inf``: no limit) from a number or a string like ``"16G"``."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{source} must be a number of bytes or a string like '16G', got {value!r}")
    if isinstance(value, str):
        text = value.strip().lower()
        if text in ("none", "inf", "infinity", "off", "unlimited"):
            return math.inf
        match = re.fullmatch(r"([0-9]*\.?[0-9]+(?:e[+-]?[0-9]+)?)\s*([a-z]*)", text)
        if not match or match.group(2) not in _UNITS:
            raise ValueError(
                f"{source} must be a number of bytes or a string like '16G', '16GB', '16GiB' or 'none', "
                f"got {value!r}"
            )
        return float(match.group(1)) * _UNITS[match.group(2)]
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{source} must be a number of bytes or a string like '16G', got {value!r}") from None
    if math.isnan(x) or x < 0:
        raise ValueError(f"{source} must be a non-negative number of bytes (inf: no limit), got {value!r}")
    return x


def physical_memory() -> int | None:
    """Bytes of physical memory, or None where the platform does not say."""
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):  # pragma: no cover - platform dependent
        return None


def set_memory_limit(limit: MemoryLimit) -> None:
    """Set the memory limit that ``refine`` and ``subdivide`` enforce, for this process.

    Parameters
    ----------
    limit : int, float, str or None
        Bytes (``inf``: no limit), or a string such as ``"16G"`` (10⁹ bytes), ``"16GiB"``
        (2³⁰ bytes) or ``"none"``. ``None`` restores the default: the environment variable
        ``HYBRIDSUB_MAX_MEMORY`` if set, else 80 % of the physical memory.

    Examples
    --------
    >>> import hybridsub
    >>> hybridsub.set_memory_limit("32G")
    >>> hybridsub.get_memory_limit()
    32000000000.0
    >>> hybridsub.set_memory_limit(None)
    """
    global _limit
    _limit = None if limit is None else parse_limit(limit, "the memory limit")


def get_memory_limit(max_memory: MemoryLimit = None) -> float:
    """The memory limit in force, in bytes (``inf`` if there is none).

    ``max_memory`` (a per-call value, as ``refine`` takes it) wins over
    :func:`set_memory_limit`, which wins over ``HYBRIDSUB_MAX_MEMORY``, which wins over the
    default (80 % of the physical memory).
    """
    limit, _ = _resolve(max_memory)
    return limit


def _resolve(max_memory) -> tuple[float, str]:
    """(limit in bytes, where it came from, for messages)."""
    if max_memory is not None:
        return parse_limit(max_memory, "max_memory"), "max_memory"
    if _limit is not None:
        return _limit, "hybridsub.set_memory_limit"
    env = os.environ.get(ENV_VAR)
    if env is not None and env.strip():
        return parse_limit(env, f"the environment variable {ENV_VAR}"), ENV_VAR
    phys = physical_memory()
    if phys is None:  # pragma: no cover - platform dependent
        return float(FALLBACK_LIMIT), "the default (8 GiB: the physical memory could not be read)"
    return DEFAULT_FRACTION * phys, f"the default (80 % of this machine's {fmt_bytes(phys)} of RAM)"


def _both(x: float) -> str:
    """'8.0 GB (8,000,000,000 bytes)', or just '512 bytes'."""
    short = fmt_bytes(x)
    return short if short.endswith("bytes") or not math.isfinite(x) else f"{short} ({x:,.0f} bytes)"


def fmt_bytes(x: float) -> str:
    if not math.isfinite(x):
        return "unlimited"
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if x >= size:
            return f"{x / size:.1f} {unit}"
    return f"{int(x)} bytes"


# --------------------------------------------------------------------------------------
# Counting


@dataclass
class Counts:
    """Sizes of one level, and of the step that refines it (exact or upper bounds)."""

    n: float  # vertices
    m: float  # faces
    sharp: float  # sharp faces
    boundary: float  # boundary edges
    split: float  # split edges (one new point each)
    trisect: float  # trisected edges (two new points each; Kobbelt's even steps)
    incid: float  # (smooth face, split edge) incidences: extra children of smooth faces
    face_points: float

    @property
    def edges(self) -> float:
        return (3 * self.m + self.boundary) / 2


@dataclass(frozen=True)
class Estimate:
    """What ``levels`` steps from some level will make and need."""

    vertices: int  # of the finest level
    faces: int
    nnz: int  # all step matrices together
    bytes: float  # peak estimate


def counts_of(level, plan) -> Counts:
    """Exact counts of a level and of the step ``plan`` (from ``_topology.plan_step``)."""
    m = level.n_faces
    boundary_he = level.twin < 0
    split = plan.hkind == R.EDGE_SPLIT
    trisect = plan.hkind == R.EDGE_TRISECT
    smooth = ~level.face_sharp

    def n_edges(mask):  # an interior edge has two halfedges, a boundary edge one
        return int(np.count_nonzero(mask & boundary_he)) + int(np.count_nonzero(mask & ~boundary_he)) // 2

    incid = int(np.count_nonzero(split.reshape(m, 3)[smooth])) if m else 0
    return Counts(
        n=level.n_vertices, m=m, sharp=int(np.count_nonzero(level.face_sharp)),
        boundary=int(np.count_nonzero(boundary_he)), split=n_edges(split), trisect=n_edges(trisect),
        incid=incid, face_points=int(np.count_nonzero(plan.face_point >= 0)),
    )


def _next(c: Counts, scheme: str, step: int) -> Counts:
    """Upper bounds on the counts of the next level and of the step after it.

    ``step`` is the (1-based) number of the step that makes the next level from ``c``.
    """
    smooth = c.m - c.sharp
    n = c.n + c.split + 2 * c.trisect + c.face_points
    if scheme == "sqrt3":
        m = 3 * c.m
        boundary = c.boundary * (3 if c.trisect else 1)
        odd_next = (step + 1) % 2 == 1
        return Counts(n, m, 0, boundary, 0, 0 if odd_next else boundary, 0, m)
    m = 4 * c.sharp + 3 * smooth + c.incid
    sharp = 4 * c.sharp
    # Children of split edges (two each) stay split at most; edges inside sharp faces are new
    # split edges (three per sharp face); edges made inside smooth faces are flip edges.
    return Counts(n, m, sharp, 2 * c.boundary, 2 * c.split + 3 * c.sharp, 0, 2 * c.incid, m - sharp)


def estimate(first: Counts, scheme: str, step: int, levels: int, keeps_steps: bool = True) -> Estimate:
    """Sizes and peak memory of steps ``step .. levels`` starting from level ``step - 1``.

    ``keeps_steps``: the result keeps every step's faces and matrix (``refine``); otherwise
    (``subdivide`` without ``return_matrix``) only one level's faces and positions live at a
    time, and no matrix is formed.
    """
    c = first
    kept = 0.0
    peak = 0.0
    nnz_total = 0
    big = False
    for k in range(step, levels + 1):
        e = c.edges
        nnz = c.n + 2 * e + 4 * c.split + 8 * c.trisect + 3 * c.face_points
        nxt = _next(c, scheme, k)
        nnz_total += nnz
        big = big or max(nnz, nxt.n, c.n) >= _stencils.INT32_LIMIT
        idx = 8 if big else 4
        # one step's temporaries: halfedge tables, plan arrays, the kernels' count/fill arrays
        transient = 8 * (11 * c.m + 7 * c.n + 6 * e) + 16 * nxt.m
        faces = nxt.m * (24 + 8 + 1) + 2 * c.split * 24  # faces, face parents, sharp mask, creases
        positions = 24 * (c.n + nxt.n)
        if keeps_steps:
            # kept: faces, face parent, sharp-face mask, crease tags (≤ 2 per split edge), S
            kept += faces + nnz * (8 + idx) + (nxt.n + 1) * idx
            peak = max(peak, kept + transient + 16 * nnz)
        else:
            peak = max(peak, c.m * 33 + faces + transient + positions)
        c = nxt
    if keeps_steps:
        peak += 2 * 24 * c.n  # the finest positions and the level before them, float64
    return Estimate(int(c.n), int(c.m), int(nnz_total), peak)


class Budget:
    """The memory check of one ``refine`` call: ``check`` once per step, before its matrix."""

    def __init__(self, levels: int, scheme: str, max_memory=None, keeps_steps: bool = True):
        self.levels = levels
        self.scheme = scheme
        self.keeps_steps = keeps_steps
        self.limit, self.source = _resolve(max_memory)

    def check(self, step: int, level, plan, also: tuple | None = None) -> None:
        """Refuse (OutputTooLargeError) if the steps ``1 .. levels`` would not fit.

        Called before every step; the estimate is made once, before the first step allocates
        anything, from that step's exact counts and upper bounds for the steps after it.
        ``also``: a second (level, plan) refined alongside (a UV index mesh), whose memory
        is added.
        """
        if step != 1 or not math.isfinite(self.limit):
            return
        est = estimate(counts_of(level, plan), self.scheme, step, self.levels, self.keeps_steps)
        if also is not None:
            extra = estimate(counts_of(*also), self.scheme, step, self.levels, self.keeps_steps)
            est = dataclasses.replace(est, nnz=est.nnz + extra.nnz, bytes=est.bytes + extra.bytes)
        if est.bytes > self.limit:
            raise OutputTooLargeError(self.message(est, level, step))

    def message(self, est: Estimate, level, step: int) -> str:
        start = "refining" if step == 1 else f"after {step - 1} of {self.levels} steps, refining"
        todo = self.levels - step + 1
        suggestion = _suggest(est.bytes)
        return (
            f"{start} {level.n_faces:,} faces by {todo} {'more ' if step > 1 else ''}"
            f"level{'s' if todo != 1 else ''} "
            f"(scheme {self.scheme!r}) would make about {est.faces:,} faces and {est.vertices:,} vertices "
            f"and need about {_both(est.bytes)} of memory (estimated before allocating), "
            f"more than the limit of {_both(self.limit)} set by "
            f"{self.source}. Ask for fewer levels, or raise the limit: max_memory={suggestion!r} in this "
            f"call, hybridsub.set_memory_limit({suggestion!r}) for the process, or the environment "
            f"variable {ENV_VAR}={suggestion}; 'none' turns the check off"
        )


def _suggest(nbytes: float) -> str:
    """A round limit above ``nbytes``, as a string like '24G'."""
    gb = max(1, math.ceil(1.25 * nbytes / 1e9))
    return f"{gb}G"


def check_product(A, B, max_memory=None, what="the composite refinement matrix") -> None:
    """Refuse to form ``A @ B`` (both CSR) if its estimated size exceeds the limit.

    The bound on the product's entries is exact for the pattern: row i of ``A @ B`` has at
    most ``sum(nnz(B[j]) for j in A[i])`` entries, and at most ``B.shape[1]``.
    """
    limit, source = _resolve(max_memory)
    if not math.isfinite(limit):
        return
    rows_b = np.diff(B.indptr).astype(np.int64)
    per_entry = rows_b[A.indices]
    row_of = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    bound = np.minimum(np.bincount(row_of, weights=per_entry, minlength=A.shape[0]), B.shape[1])
    nnz = float(bound.sum())
    idx = 8 if max(nnz, B.shape[1], A.shape[0]) >= _stencils.INT32_LIMIT else 4
    # the product, and scipy's temporaries (about as large again)
    need = 2 * (nnz * (8 + idx) + (A.shape[0] + 1) * idx)
    if need > limit:
        s = _suggest(need)
        raise OutputTooLargeError(
            f"forming {what} ({A.shape[0]:,} × {B.shape[1]:,}, up to {nnz:,.0f} entries) would need about "
            f"{_both(need)} of memory, more than the limit of {_both(limit)} set by {source}. "
            "Refine data with Refinement.apply (step by step, no "
            f"composite), or raise the limit: hybridsub.set_memory_limit({s!r}) or the environment "
            f"variable {ENV_VAR}={s}; 'none' turns the check off"
        )
