"""Sector normals from positions: the stationary tangent masks where a sector has them, the
control fan where nothing better exists, and the runs estimate that local refinement uses
for crease sectors of √3 faces (``docs/limit.md``)."""

from __future__ import annotations

import numpy as np

from .._topology import Level, Sectors
from ._normal_kernels import fan_area_vectors
from .mask_plan import SEC_CORNER, SEC_FAN, SEC_TRANSIENT, LimitPlan


def unit(A: np.ndarray) -> np.ndarray:
    """Rows of ``A`` scaled to length 1 (zero rows stay zero).

    >>> unit(np.array([[3.0, 4.0, 0.0], [0.0, 0.0, 0.0]])).tolist()
    [[0.6, 0.8, 0.0], [0.0, 0.0, 0.0]]
    """
    nrm = np.linalg.norm(A, axis=-1, keepdims=True)
    return np.divide(A, nrm, out=np.zeros_like(A), where=nrm > 0)


def fan_normals(level: Level, sec: Sectors, X: np.ndarray) -> np.ndarray:
    """Area vector of each sector's control fan, Σ (p_j − v) × (p_{j+1} − v)."""
    return fan_area_vectors(np.ascontiguousarray(level.faces, dtype=np.int64),
                            np.ascontiguousarray(sec.slots, dtype=np.int64),
                            np.ascontiguousarray(sec.slot_sector, dtype=np.int64),
                            np.ascontiguousarray(X, dtype=np.float64), len(sec.vertex))


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise cross product of two (k, 3) arrays (``np.cross`` without its generality).

    >>> cross(np.array([[1.0, 0, 0]]), np.array([[0.0, 1, 0]])).tolist()
    [[0.0, 0.0, 1.0]]
    """
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def sector_normals(level: Level, plan: LimitPlan, X: np.ndarray) -> np.ndarray:
    """Unit normal of every sector whose kind is not SEC_TRANSIENT (rows of those: zero)."""
    T1, T2 = plan.tangent_csr(level.n_vertices)
    t1, t2 = T1 @ X, T2 @ X
    nrm = cross(t1, t2)
    fan = fan_normals(level, plan.sectors, X)
    kind = plan.sec_kind
    corner = kind == SEC_CORNER
    flip = corner & (np.einsum("ij,ij->i", nrm, fan) < 0)
    nrm[flip] *= -1.0
    size = np.linalg.norm(nrm, axis=1)
    scale = np.linalg.norm(t1, axis=1) * np.linalg.norm(t2, axis=1)
    weak = (size <= 1e-12 * scale) | (kind == SEC_FAN)
    nrm[weak] = fan[weak]
    nrm[kind == SEC_TRANSIENT] = 0.0
    return unit(nrm)


def _smooth_runs(sec: Sectors, face_sharp: np.ndarray):
    """The runs of √3 (not sharp) faces of every sector, as the ring entries they bring.

    Cyclic sectors are rotated to start at a sharp → smooth change, so no run wraps. Each
    smooth slot ``j`` of a run brings ``q_j``, its last slot ``b`` brings ``q_{b+1}`` as well.
    Returns ``(run_sector, entry_run, entry_sector, entry_q, entry_pos, has_run)``:
    ``entry_pos`` is an entry's position in its run.
    """
    nsec = len(sec.vertex)
    k = sec.n_faces
    op = sec.open
    sid = sec.slot_sector
    firsts = np.cumsum(k) - k
    j = np.arange(k.sum()) - np.repeat(firsts, k)
    smooth_raw = ~face_sharp[sec.slots[np.repeat(sec.slot_start[:-1], k) + j] // 3]
    prev = np.roll(smooth_raw, 1)
    prev[firsts] = smooth_raw[firsts + k - 1]
    change = smooth_raw & ~prev & ~op[sid]
    big = np.iinfo(np.int64).max
    j0 = np.full(nsec, big)
    np.minimum.at(j0, sid[change], j[change])
    j0 = np.where(j0 == big, 0, j0)
    jr = (j + j0[sid]) % k[sid]  # slot index in the sector, after rotation
    smooth = ~face_sharp[sec.slots[sec.slot_start[:-1][sid] + jr] // 3]
    # Runs: maximal sequences of smooth slots (no wrap after the rotation).
    prev = np.roll(smooth, 1)
    prev[firsts] = False
    start = smooth & ~prev
    nxt = np.roll(smooth, -1)
    nxt[firsts + k - 1] = False
    end = smooth & ~nxt
    run = np.cumsum(start) - 1
    ent_run = np.r_[run[smooth], run[end]]
    ent_sec = np.r_[sid[smooth], sid[end]]
    ent_j = np.r_[j[smooth], j[end] + 1]
    ring_len = np.where(op, k + 1, k)[ent_sec]
    ent_q = sec.ring[sec.ring_start[:-1][ent_sec] + (ent_j + j0[ent_sec]) % ring_len]
    ent_pos = ent_j - j[start][ent_run]
    has_run = np.bincount(sid[smooth], minlength=nsec) > 0
    return sid[start], ent_run, ent_sec, ent_q, ent_pos, has_run


def run_estimate(level: Level, sec: Sectors, X: np.ndarray, face_sharp: np.ndarray):
    """Normal estimate of every sector, and where it is the robust one.

    Between two crease edges the runs of √3 (smooth) faces grow by one face per step. For
    each run, with ring ``q_0 … q_r`` (``e_j = q_j − v``), ``(Σ e_j) × (Σ j e_j)`` has, up to
    one common factor, the limit of the run's control fan area vector, and gets there
    geometrically where the fan's own normal creeps (``docs/limit.md``); the runs' vectors
    are summed. Where a run goes (nearly) all the way round — darts, mixed vertices — ``Σ e_j``
    nearly cancels and the estimate is unstable: those sectors, and sectors without a √3 face,
    get the fan normal (``robust`` False). Oriented like the fan normal.
    """
    nsec = len(sec.vertex)
    out = np.zeros((nsec, 3))
    if not nsec:
        return out, np.zeros(0, dtype=bool)
    fan = fan_normals(level, sec, X)
    run_sec, ent_run, ent_sec, ent_q, ent_pos, has_run = _smooth_runs(sec, face_sharp)
    n_run = len(run_sec)
    if n_run:
        e = X[ent_q] - X[sec.vertex[ent_sec]]
        s1 = np.zeros((n_run, 3))
        s2 = np.zeros((n_run, 3))
        np.add.at(s1, ent_run, e)
        np.add.at(s2, ent_run, ent_pos[:, None] * e)
        np.add.at(out, run_sec, np.cross(s1, s2))
    robust = has_run & sec.open & (sec.first_ring != sec.last_ring)
    out[~robust] = fan[~robust]
    flip = np.einsum("ij,ij->i", out, fan) < 0
    out[flip] *= -1.0
    return unit(out), robust


def vertex_normals(level: Level, plan, nrm: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Unit normal of every vertex: the normalized sum of its sectors' unit normals."""
    N = np.zeros((level.n_vertices, 3))
    np.add.at(N, plan.sectors.vertex, nrm)
    # Sectors facing opposite ways (a fin: a crease that turns back on itself) cancel; there
    # the vertex gets its control fan's normal instead.
    cancel = np.linalg.norm(N, axis=1) < 1e-6
    if cancel.any():
        Fl = level.faces
        fn = np.cross(X[Fl[:, 1]] - X[Fl[:, 0]], X[Fl[:, 2]] - X[Fl[:, 0]])
        fan = np.zeros_like(N)
        for i in range(3):
            np.add.at(fan, Fl[:, i], fn)
        N[cancel] = fan[cancel]
    return unit(N)


def one_side_sectors(level: Level, sec) -> np.ndarray:
    """(n,) the sector that gives a vertex with several sectors its one side; -1 where no face is.

    OpenSubdiv's rule (Sdc's crease limit tangent masks take the span counter-clockwise from
    the first crease edge in the vertex's edge order, which starts at the outgoing edge of its
    first face): the sector of the vertex's first face corner (in face order) if that corner's
    outgoing edge starts the sector, else the next sector counter-clockwise.
    """
    n = level.n_vertices
    out = np.full(n, -1, dtype=np.int64)
    corners = level.faces.ravel()
    first = np.full(n, len(corners), dtype=np.int64)
    np.minimum.at(first, corners, np.arange(len(corners)))
    v = np.flatnonzero(first < len(corners))
    h0 = first[v]
    s0 = sec.he_sector[h0]
    at_start = (sec.slots[sec.slot_start[:-1][s0]] == h0) | ~sec.open[s0]
    key = sec.vertex * np.int64(n) + sec.first_ring  # the sector of a vertex that starts at q
    order = np.argsort(key, kind="stable")
    want = sec.vertex[s0] * np.int64(n) + sec.last_ring[s0]  # the next one starts where s0 ends
    i = np.minimum(np.searchsorted(key[order], want), len(order) - 1)
    found = key[order[i]] == want
    out[v] = np.where(at_start | ~found, s0, order[i])
    return out
