"""Memory budget: estimate what a refinement will need before allocating it, refuse above a limit.

The limit, in bytes, is taken from (first found):

1. the ``max_memory=`` argument of ``refine`` / ``subdivide``;
2. :func:`set_memory_limit`;
3. the environment variable ``HYBRIDSUB_MAX_MEMORY`` (read at every call);
4. 80 % of the memory this process may use — the machine's physical memory, or a smaller cgroup
   limit (containers, Slurm jobs) — 8 GiB where neither can be read — the threshold
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

:func:`predict_levels` is the exact account, from level 0 alone: the faces, vertices and
edges of every level and the peak memory of the level-by-level run of the command line
(``hybridsub info`` prints it; the command refuses runs above 80 % of the RAM with it). Both
count a step's matrix entries with :func:`step_nnz`.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
from dataclasses import dataclass

import numpy as np

from .._rules import step_rules as R
from . import stencils as _stencils
from ._stencil_kernels import product_bound
from .._errors import OutputTooLargeError
from .._input import count_of
from .._topology import edge_keys, step_counts, undirected_edges
from .._units import bytes_and_count, fmt_bytes
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
    """Bytes of memory this process may use: the machine's physical memory, or less where a
    cgroup limits it (a container, a Slurm job; see :func:`memory_source`); None where neither
    can be read."""
    return memory_source()[0]


#: Where the cgroup file systems and this process's cgroup are read (tests point them elsewhere).
CGROUP_ROOT = "/sys/fs/cgroup"
PROC_CGROUP = "/proc/self/cgroup"


def memory_source() -> tuple[int | None, str]:
    """(bytes of memory this process may use, what limits it in words).

    The physical memory (``sysconf``), or a smaller cgroup limit: cgroup v2's ``memory.max``
    of this process's cgroup and its ancestors, cgroup v1's ``memory.limit_in_bytes`` (what
    Docker, Kubernetes and Slurm's ``--mem`` set). No library reads these, hence this function.

    Examples
    --------
    >>> n, words = memory_source()
    >>> n is None or n > 0
    True
    """
    phys: int | None
    try:
        phys = int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):  # pragma: no cover - platform dependent
        phys = None
    limit = cgroup_memory_limit()
    if limit is not None and (phys is None or limit < phys):
        return limit, f"the {fmt_bytes(limit)} cgroup memory limit of this process"
    if phys is None:  # pragma: no cover - platform dependent
        return None, "an unknown amount of RAM"
    return phys, f"this machine's {fmt_bytes(phys)} of RAM"


def cgroup_memory_limit() -> int | None:
    """The smallest cgroup memory limit over this process's cgroup and its ancestors, in bytes
    (v2 ``memory.max``, v1 ``memory.limit_in_bytes``), or None where there is none (``max``,
    v1's "unlimited" 2⁶³-page value) or the files cannot be read (no cgroups, not Linux)."""
    try:
        with open(PROC_CGROUP, encoding="ascii", errors="replace") as fh:
            lines = fh.read().splitlines()
    except OSError:
        return None
    found: list[int] = []
    for line in lines:
        parts = line.split(":", 2)
        if len(parts) != 3:
            continue
        _, controllers, rel = parts
        if controllers == "":  # cgroup v2: the unified hierarchy
            found += _limits_up(CGROUP_ROOT, rel, "memory.max")
        elif "memory" in controllers.split(","):  # cgroup v1: the memory controller's hierarchy
            found += _limits_up(os.path.join(CGROUP_ROOT, "memory"), rel, "memory.limit_in_bytes")
    return min(found) if found else None


def _limits_up(root: str, rel: str, name: str) -> list[int]:
    """The limits in file ``name`` of cgroup ``rel`` and its ancestors under ``root`` (inside a
    container the cgroup's path is often not mounted as named: its mount root counts too)."""
    parts = [p for p in rel.strip().split("/") if p and p != ".."]
    out = []
    for k in range(len(parts), -1, -1):
        try:
            with open(os.path.join(root, *parts[:k], name), encoding="ascii") as fh:
                text = fh.read().strip()
        except OSError:
            continue
        if text.isdigit() and int(text) < 2**62:  # v1 writes "unlimited" as 2^63 rounded to a page
            out.append(int(text))
    return out


def set_memory_limit(limit: MemoryLimit) -> None:
    """Set the memory limit that ``refine`` and ``subdivide`` enforce, for this process.

    Parameters
    ----------
    limit : int, float, str or None
        Bytes (``inf``: no limit), or a string such as ``"16G"`` (10⁹ bytes), ``"16GiB"``
        (2³⁰ bytes) or ``"none"``. ``None`` restores the default: the environment variable
        ``HYBRIDSUB_MAX_MEMORY`` if set, else 80 % of the memory this process may use
        (the physical memory, or a smaller cgroup limit).

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
    default (80 % of the physical memory, or of a smaller cgroup memory limit).
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
    phys, words = memory_source()
    if phys is None:  # pragma: no cover - platform dependent
        return float(FALLBACK_LIMIT), "the default (8 GiB: the physical memory could not be read)"
    return DEFAULT_FRACTION * phys, f"the default (80 % of {words})"


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


def step_nnz(n, edges, edge_points, face_points):
    """Entries of one step's matrix: a row of ``1 + valence`` per old vertex (``n + 2 edges``
    in all), four per edge point (a trisected edge has two), three per face point."""
    return n + 2 * edges + 4 * edge_points + 3 * face_points


@dataclass(frozen=True)
class Estimate:
    """What ``levels`` steps from some level will make and need."""

    vertices: int  # of the finest level
    faces: int
    nnz: int  # all step matrices together
    bytes: float  # peak estimate


def counts_of(level, plan) -> Counts:
    """Exact counts of a level and of the step ``plan`` (from ``_topology.plan_step``)."""
    c = np.empty(6, np.int64)
    step_counts(level.twin, plan.hkind, level.face_sharp, plan.face_point, c)
    boundary, split, trisect, incid, sharp, face_points = (int(x) for x in c)
    return Counts(n=level.n_vertices, m=level.n_faces, sharp=sharp, boundary=boundary, split=split, trisect=trisect,
                  incid=incid, face_points=face_points)


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
        nnz = step_nnz(c.n, e, c.split + 2 * c.trisect, c.face_points)
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
            f"{start} {level.n_faces:,} faces by {count_of(todo, 'more level' if step > 1 else 'level')} "
            f"(scheme {self.scheme!r}) would make about {est.faces:,} faces and {est.vertices:,} vertices "
            f"and need about {bytes_and_count(est.bytes)} of memory (estimated before allocating), "
            f"more than the limit of {bytes_and_count(self.limit)} set by "
            f"{self.source}. Ask for fewer levels, or raise the limit: max_memory={suggestion!r} in this "
            f"call, hybridsub.set_memory_limit({suggestion!r}) for the process, or the environment "
            f"variable {ENV_VAR}={suggestion}; 'none' turns the check off"
        )


class RegionBudget:
    """The memory check of an adaptive refinement: ``check`` before each step of a region.

    The output is not known ahead (a tolerance decides it level by level), so each step is
    checked as it comes: what the steps so far keep (``kept``, their exact sizes), plus upper
    bounds on the next step's. A step that refines ``r`` faces of an adaptive mesh of ``m``
    faces and ``n`` vertices makes at most ``m + 5 r`` faces (a smooth face with three split
    edges makes six) and ``n + 4 r + b`` vertices (a face point and at most three edge points
    per refined face, one more on each of the ``b`` boundary edges Kobbelt's step trisects),
    and its matrix at most ``n + 3 r`` entries for the old vertices (one each, a row of ``1 + valence`` for those all
    of whose faces are refined, their valences summing to at most ``3 r``) and four per new
    one. The next mesh (twins and tags per halfedge, per-face levels) and the step's
    temporaries are counted at twice the faces' and vertices' arrays. With face-varying data
    (``t`` UV values) the UV step is bounded the same way (a UV face per face, a face point and
    at most three edge points per refined face, a seam's two sides apart).
    """

    def __init__(self, scheme: str, max_memory=None):
        self.scheme = scheme
        self.limit, self.source = _resolve(max_memory)
        self.kept = 0.0

    def estimate(self, m: int, n: int, r: int, b: int = 0, t: int | None = None) -> Estimate:
        m1, n1 = m + 5 * r, n + 4 * r + b
        nnz = n + 3 * r + 4 * (n1 - n)
        idx = 8 if max(nnz, n1) >= _stencils.INT32_LIMIT else 4
        step = m1 * (24 + 8 + 1) + nnz * (8 + idx) + (n1 + 1) * idx
        mesh = m1 * (24 + 48 + 8 + 8 + 1 + 1 + 8) + 16 * n1
        total = self.kept + step + 2 * mesh + 2 * 24 * n1
        if t is not None:  # the UV index mesh's faces, matrix and corner mask, and their temporaries
            t1 = t + 4 * r
            uv_nnz = t + 3 * r + 4 * (t1 - t)
            total += 3 * m1 * 24 + uv_nnz * (8 + idx) + (t1 + 1) * idx + 2 * t1
        return Estimate(int(n1), int(m1), int(nnz), total)

    def check(self, k: int, m: int, n: int, r: int, b: int = 0, t: int | None = None) -> None:
        """Refuse (OutputTooLargeError) the step that refines ``r`` of the ``m`` faces of
        level ``k`` (``b``: the boundary edges it trisects; ``t``: the UV values, with
        face-varying data) if it would not fit."""
        if not math.isfinite(self.limit):
            return
        est = self.estimate(m, n, r, b, t)
        if est.bytes > self.limit:
            suggestion = _suggest(est.bytes)
            raise OutputTooLargeError(
                f"adaptive refinement (scheme {self.scheme!r}): refining {r:,} of the {m:,} faces at level {k} "
                f"would bring the output to up to {est.faces:,} faces and {est.vertices:,} vertices and need about "
                f"{bytes_and_count(est.bytes)} of memory (estimated before allocating, with the steps so far), more "
                f"than the limit of {bytes_and_count(self.limit)} set by {self.source}. Ask for fewer levels "
                f"(levels=, max_levels=) or a looser tolerance, or raise the limit: max_memory={suggestion!r} in "
                f"this call, hybridsub.set_memory_limit({suggestion!r}) for the process, or the environment "
                f"variable {ENV_VAR}={suggestion}; 'none' turns the check off")

    def add(self, faces: np.ndarray, matrix, uv_matrix=None) -> None:
        """Count a step made: its faces, face parents, sharp-face mask and matrix (and with
        face-varying data its UV faces and UV matrix)."""
        self.kept += faces.shape[0] * (24 + 8 + 1) + matrix.data.nbytes + matrix.indices.nbytes + matrix.indptr.nbytes
        if uv_matrix is not None:
            self.kept += faces.shape[0] * 24 + uv_matrix.data.nbytes + uv_matrix.indices.nbytes + uv_matrix.indptr.nbytes


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
    nnz = float(product_bound(A.indptr, A.indices, B.indptr, B.shape[1]))
    idx = 8 if max(nnz, B.shape[1], A.shape[0]) >= _stencils.INT32_LIMIT else 4
    # the product, and its pattern pass and copies (bounded by as much again)
    need = 2 * (nnz * (8 + idx) + (A.shape[0] + 1) * idx)
    if need > limit:
        s = _suggest(need)
        raise OutputTooLargeError(
            f"forming {what} ({A.shape[0]:,} × {B.shape[1]:,}, up to {nnz:,.0f} entries) would need about "
            f"{bytes_and_count(need)} of memory, more than the limit of {bytes_and_count(limit)} set by {source}. "
            "Refine data with Refinement.apply (step by step, no "
            f"composite), or raise the limit: hybridsub.set_memory_limit({s!r}) or the environment "
            f"variable {ENV_VAR}={s}; 'none' turns the check off"
        )


# --------------------------------------------------------------------------------------
# Exact counts per level (what ``hybridsub info`` and the command line's memory check read)

#: Bytes per face of one step's topology tables and classification (halfedge twins, edge
#: numbering, vertex→edge incidence, step plan). Measured as the peak RSS of
#: ``refine(F, levels=1)`` + ``apply`` minus everything else ``predict_levels`` counts:
#: 175–210 bytes per face on armadillo (L1, L2 inputs; hybrid, loop, sqrt3) and fandisk L3.
TOPOLOGY_BYTES_PER_FACE = 200


def _split_halfedges(F, pairs, eid, cnt, n_vertices, sharp_edges, sharpness, sharp_faces):
    """(sharp face mask, sharpness of each split halfedge of a smooth face) at level 0 of ``"hybrid"``."""
    m0, E = len(F), len(pairs)
    sharp = np.zeros(m0, bool)
    if sharp_faces is not None:
        sf = np.asarray(sharp_faces)
        if sf.dtype == bool:
            sharp |= sf
        else:
            sharp[sf.astype(np.int64)] = True
    es = np.zeros(E)
    if sharp_edges is not None and len(sharp_edges):
        se = np.asarray(sharp_edges, dtype=np.int64).reshape(-1, 2)
        s = (np.full(len(se), np.inf) if sharpness is None
             else R.normalize_sharpness(np.asarray(sharpness, dtype=np.float64)))
        key = edge_keys(se[:, 0], se[:, 1], n_vertices)
        ekey = edge_keys(pairs[:, 0], pairs[:, 1], n_vertices)
        pos = np.searchsorted(ekey, key)
        ok = (pos < E) & (ekey[np.minimum(pos, E - 1)] == key)
        np.maximum.at(es, pos[ok], s[ok])
    es[cnt == 1] = np.inf
    # for each halfedge, is the other face on its edge sharp?
    order = np.argsort(eid, kind="stable")
    other_sharp = np.zeros(3 * m0, bool)
    two = cnt[eid[order]] == 2
    h1, h2 = order[two][0::2], order[two][1::2]
    other_sharp[h1] = sharp[h2 // 3]
    other_sharp[h2] = sharp[h1 // 3]
    hs = np.where(other_sharp, np.inf, es[eid])
    return sharp, hs[~np.repeat(sharp, 3) & (hs > 0)]


def predict_levels(F: np.ndarray, n_vertices: int, levels: int, *, scheme: str = "hybrid", sharp_edges=None,
                   sharpness=None, sharp_faces=None, attributes: int = 3) -> list[dict]:
    """Exact counts of every level of ``subdivide``, and a memory estimate, from level 0 alone.

    Counting rules (exact for any valid input; ``tests/test_cli.py`` checks them against ``refine``):
    every edge lies in one or two faces, so ``E = (3F + B) / 2`` at every level (B: boundary
    edges), and the Euler characteristic ``V − E + F`` never changes; hence ``V`` follows from
    ``F`` and ``B``. ``"loop"``: ``F ← 4F``, ``B ← 2B``. ``"sqrt3"``: ``F ← 3F``; ``B`` is
    unchanged in odd steps and trisected (``B ← 3B``) in even ones. ``"hybrid"``: a sharp face
    makes 4 sharp faces, a smooth face ``3 + s`` smooth faces (``s`` split edges). A split
    halfedge of a smooth face has two split children in two smooth faces while its edge stays
    split: for ever on a boundary or next to a sharp face, ``⌈σ⌉`` levels for a crease of
    sharpness ``σ`` between smooth faces. So with ``Fs, Fh`` smooth and sharp faces and ``σ_h``
    the sharpness of each split halfedge of a smooth face at level 0,
    ``H_k = Σ_h 2^k [σ_h > k]``, ``Fs ← 3Fs + H_k``, ``Fh ← 4Fh``, ``B ← 2B``.

    Parameters
    ----------
    F : (m, 3) int64
        A valid mesh's faces (every edge in one or two faces).
    n_vertices, levels, scheme, sharp_edges, sharpness, sharp_faces
        As for ``refine``; ``sharp_faces`` as a boolean mask or indices.
    attributes : int
        Floats per vertex being refined (3 for positions, more with colours or UVs).

    Returns
    -------
    list of dict, one per level 1..levels
        ``faces``, ``vertices``, ``edges``, ``boundary_edges``, ``nnz`` (an upper bound of the
        step matrix's non-zeros), ``output_bytes`` (positions and faces, float64/int64) and
        ``peak_bytes`` (estimated peak working memory of that step, as ``hybridsub subdivide``
        runs it: the previous level, the step's tables and matrix, and the new level).

    Examples
    --------
    >>> import numpy as np
    >>> F = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]])   # a tetrahedron
    >>> [(p["faces"], p["vertices"]) for p in predict_levels(F, 4, 2, scheme="loop")]
    [(16, 10), (64, 34)]
    """
    F = np.asarray(F, dtype=np.int64)
    m0 = len(F)
    pairs, eid, cnt = undirected_edges(F, n_vertices)
    E = len(pairs)
    B = int((cnt == 1).sum())
    Fh = Fs = 0
    H = np.empty(0)
    if scheme == "loop":
        Fh = m0
    elif scheme == "hybrid":
        sharp, H = _split_halfedges(F, pairs, eid, cnt, n_vertices, sharp_edges, sharpness, sharp_faces)
        Fh, Fs = int(sharp.sum()), int((~sharp).sum())
    out = []
    n, m = n_vertices, m0
    for k in range(levels):
        step = k + 1
        if scheme == "loop":
            m2, B2, face_points = 4 * m, 2 * B, 0
        elif scheme == "sqrt3":
            odd = step % 2 == 1
            m2, B2 = 3 * m, (B if odd else 3 * B)
            face_points = m if odd else m - B
        else:
            Hk = int(np.sum(np.where(H > k, 2.0 ** k, 0.0)))
            Fs2, Fh2 = 3 * Fs + Hk, 4 * Fh
            m2, B2, face_points = Fs2 + Fh2, 2 * B, Fs
            Fs, Fh = Fs2, Fh2
        E2 = (3 * m2 + B2) // 2
        n2 = n + (E2 - E) - (m2 - m)
        nnz = step_nnz(n, E, n2 - n - face_points, face_points)
        out_bytes = 8 * attributes * n2 + 24 * m2
        peak = (8 * attributes * n + 24 * m  # the level being refined
                + TOPOLOGY_BYTES_PER_FACE * m  # its tables and the step plan
                + 12 * nnz + 8 * (n2 + 1)  # the step matrix (CSR)
                + out_bytes + 8 * m2)  # the new level and its face parents
        out.append({"level": step, "faces": int(m2), "vertices": int(n2), "edges": int(E2),
                    "boundary_edges": int(B2), "nnz": int(nnz), "output_bytes": int(out_bytes),
                    "peak_bytes": int(peak)})
        n, m, E, B = n2, m2, E2, B2
    return out
