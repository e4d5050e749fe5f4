"""The descent as a walk through the patch cache (:mod:`.cache`).

Every point starts at the key of its input face's patch and, level by level, picks its child
face among the key's candidates (as ``descent.step`` does), moving to the child's key; the
candidates chosen are recorded. The walk runs in one kernel as far as the table knows the
way; keys met for the first time are refined in a batch and the walk goes on. At the end the
last interpolation's weights times the limit rows of its six vertices (or a regular patch's
quartic) give a row over the last patch, carried back through the recorded steps' rows to the
first patch and onto the control vertices: the same products as ``LimitSurface``'s direct
descent, in another order. Points on regular input faces skip all this: the box spline of
their twelve control vertices (:func:`ring_coefficients`).
"""

from __future__ import annotations

import functools

import numba
import numpy as np
import scipy.sparse as sp

from .._input import RefineInput, open_gate
from .._topology import use_threads
from ._carry_kernels import (
    back_points,
    back_points_serial,
    back_rows,
    forward_points,
    forward_points_serial,
)
from ._walk_kernels import (
    regular_rings,
    ring_points,
    ring_rows,
    stencil_points,
    walk_known,
    walk_known_serial,
)
from .cache import Grow, PatchTable
from .descent import start
from .regular import GRID, GRID_INVERSE, polynomial_weights, regular_torus

#: A point of the walk costs about what this many faces of a refinement step do (the
#: threshold of the threaded kernels, ``_topology.use_threads``, counts faces).
POINT_COST = 20
#: Derivative rows carried back lose digits like the inverse of the last face's size (their
#: weights grow so and cancel): past these levels (Loop faces, √3 faces), faces under 1e-6 of
#: the input face's size, a point's derivatives are applied to the data forward instead.
FORWARD_LEVELS = (20, 24)


def _threaded(q: int) -> bool:
    """Whether the walk's kernels run their threaded twins for ``q`` points: not on one
    thread, where (unlike the refinement's kernels) the serial ones are faster."""
    return use_threads(POINT_COST * q) and numba.get_num_threads() > 1


def _unit_gradients(q: int) -> np.ndarray:
    """∂b/∂(u, v) (3, 2) on the input face, ``b = (1 − u − v, u, v)``, for ``q`` points."""
    return np.repeat(np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])[None], q, axis=0)


class StartKeys:
    """The key of every input face's patch and the control vertex of each of its canonical
    vertices, found when a face is first evaluated."""

    def __init__(self, inp: RefineInput, table: PatchTable):
        self.inp, self.table = inp, table
        self.key = np.full(inp.n_faces, -1, np.int64)
        self.v0 = np.zeros(inp.n_faces, np.int64)
        self.vids = Grow((), np.int64)
        self.order = Grow((), np.int64)  # per face: its canonical positions by increasing vertex id
        self._rings = None

    @property
    def rings(self) -> np.ndarray:
        """The twelve control vertices of each regular input face, −1 rows elsewhere
        (:func:`._walk_kernels.regular_rings`; all −1 when the table does not stop at
        regular patches)."""
        if self._rings is None:
            lvl, m = self.inp.level, self.inp.n_faces
            self._rings = np.full((m, 12), -1, np.int64)
            if self.table.regular_stop:
                hs = np.zeros(3 * m) if lvl.hsharp is None else np.ascontiguousarray(lvl.hsharp, dtype=np.float64)
                regular_rings(np.ascontiguousarray(lvl.faces, dtype=np.int64), np.ascontiguousarray(lvl.twin, np.int64),
                              hs, lvl.face_sharp, self.inp.corner, self._rings)
        return self._rings

    def of(self, faces: np.ndarray) -> np.ndarray:
        new = np.unique(faces[self.key[faces] < 0])
        if len(new):
            inp = self.inp
            p, sel, fstart = start(inp, new)
            ids, vperm, vstart = self.table.register(p.level, p.corner, p.shape, p.face, fstart,
                                                     int(inp.scheme == "sqrt3"))
            self.key[new] = ids
            vids = sel.indices[vperm]
            node_v = np.repeat(np.arange(len(new)), np.diff(vstart))
            self.v0[new] = self.vids.append(vids) + vstart[:-1]
            self.order.append(np.lexsort((vids, node_v)) - vstart[node_v])
        return self.key[faces]


def _descend(table: PatchTable, keys0, bary, grad, depth, stop_regular: bool, vertex_stop: bool):
    """Every point down to its depth (``depth``, one per point or one for all), or to the
    first regular Loop patch (with ``stop_regular``), or (with ``vertex_stop``) to the first
    level where it is a vertex. Returns the keys met (q, max depth + 1), the candidates chosen
    (q, max depth), the level each point stopped at, and its barycentric coordinates there
    with their derivatives in (u, v) (``bary``, ``grad`` updated in place), and the first
    level where it is a vertex (−1: none). The walk goes as far as the table knows the way;
    keys and child patches met for the first time are refined in a batch, and the walk goes
    on."""
    q = len(keys0)
    depth = np.array(np.broadcast_to(depth, (q,)), np.int64)  # contiguous: the kernel's one type
    top = int(depth.max()) if q else 0
    keys = np.empty((q, top + 1), np.int64)
    path = np.empty((q, top), np.int64)
    stop = depth.copy()
    keys[:, 0] = keys0
    level = np.zeros(q, np.int64)
    state = np.zeros(q, np.int8)
    at_vertex = np.full(q, -1, np.int64)
    todo = np.arange(q)
    while len(todo):
        kernel = walk_known if _threaded(len(todo)) else walk_known_serial
        kernel(todo, level, state, keys, path, stop, bary, grad, table.cand_start.a, table.cand_count.a, table.M.a,
               table.child.a, table.regular.a, stop_regular, depth, at_vertex, vertex_stop,
               2 if table.scheme == "sqrt3" else 1)
        todo = todo[state[todo] != 0]
        steps = todo[state[todo] == 2]
        if len(steps):
            table.fill_steps(np.unique(keys[steps, level[steps]]))
        cut = todo[state[todo] == 1]
        if len(cut):
            table.fill_children(np.unique(path[cut, level[cut]]))
    return keys, path, stop, bary, grad, at_vertex


def _last_weights(table: PatchTable, keys0, bary, grad, n_rows: int, depth, stop_regular: bool,
                  vertex_stop: bool = False):
    """The walk down (:func:`_descend`) and each point's weights on its last patch: the
    arguments of :func:`._carry_kernels.back_rows` before its output; then the points that
    were a vertex of a level before their last (to be given the value of a walk stopped
    there, :func:`_at_vertices`)."""
    q = len(keys0)
    keys, path, stop, bary, grad, at_vertex = _descend(table, keys0, bary.copy(), grad.copy(), depth, stop_regular,
                                                       vertex_stop)
    last = keys[np.arange(q), stop]
    poly = table.regular_keys(last) if stop_regular else np.zeros(q, bool)
    W = np.empty((q, n_rows, 15))  # the kernels read a point's first slots[q] weights only
    block = np.empty(q, np.int64)
    if poly.any():
        lp = last[poly]
        lack = lp[table.poly.a[lp] < 0]
        if len(lack):
            fill_polynomials(table, np.unique(lack))
        block[poly] = table.poly.a[lp]
        W[poly] = polynomial_weights(bary[poly], grad[poly], n_rows)
    st = np.flatnonzero(~poly)
    if len(st):
        ls = last[st]
        lack = ls[table.final.a[ls] < 0]
        if len(lack):
            table.fill_stencils(np.unique(lack))
        rec = table.final.a[ls]
        Ws = np.empty((len(st), n_rows, 6))
        stencil_points(rec, bary[st], grad[st], table.st_inv.a, table.st_full.a, table.st_node.a, Ws)
        W[st, :, :6] = Ws
        block[st] = table.st_blk.a[rec]
    args = (W, np.where(poly, 15, 6), block, stop, path, keys, table.nv.a, table.blk_v0.a, table.blk_c0.a,
            table.blk_nc.a, table.blk_col.a, table.blk_val.a, table.t_start.a, table.t_end.a, table.t_row.a,
            table.t_col.a, table.t_val.a)
    return args, np.flatnonzero((at_vertex >= 0) & (at_vertex < stop))


def walk(table: PatchTable, keys0, bary, grad, n_rows: int, depth, stop_regular: bool):
    """Rows (q, nv_max, n_rows) of the points over their first patches' canonical vertices:
    value, then ∂/∂u, ∂/∂v, then ∂²/∂u², ∂²/∂u∂v, ∂²/∂v². A point that is a vertex of some
    level takes that vertex's limit position (:func:`_at_vertices`); its derivatives come
    from the walk to its depth."""
    args, at = _last_weights(table, keys0, bary, grad, n_rows, depth, stop_regular, n_rows == 1)
    out = np.zeros((len(keys0), int(table.nv.a[keys0].max()) if len(keys0) else 0, n_rows))
    back_rows(*args, out)
    if len(at):
        value, _ = _last_weights(table, keys0[at], bary[at], grad[at], 1, _pick(depth, at), stop_regular, True)
        part = np.zeros((len(at), out.shape[1], 1))
        back_rows(*value, part)
        out[at, :, 0] = part[:, :, 0]
    return out


def _pick(depth, idx: np.ndarray):
    """``depth`` (one per point or one for all) of the points ``idx``."""
    d = np.asarray(depth)
    return d[idx] if d.ndim else d


def fill_polynomials(table: PatchTable, keys: np.ndarray):
    """The quartic of each regular Loop patch in ``keys`` (:mod:`.regular`): its 15 Bernstein
    coefficients as rows over the patch's vertices, from the exact limit rows at ``GRID``."""
    if not len(keys):
        return
    k = len(keys)
    rows = walk(table, np.repeat(keys, 15), np.tile(GRID, (k, 1)), _unit_gradients(15 * k), 1, 2, False)[:, :, 0]
    coef = GRID_INVERSE @ rows.reshape(k, 15, -1)  # (k, 15, nv_max)
    nv = table.nv.a[keys]
    table.poly.a[keys] = table.add_blocks(np.concatenate([coef[i, :, :nv[i]].ravel() for i in range(k)]), 15, nv)


def _ring_rows(rings: np.ndarray, b: np.ndarray, n_rows: int, n: int) -> list:
    """The rows of points on regular input faces (their rings ``rings`` (q, 12)): the box
    spline's quartic (:func:`ring_coefficients`) at ``b``, as CSR matrices (q, n)."""
    q = len(rings)
    ids = np.empty((q, 12), np.int64)
    vals = np.empty((n_rows, q, 12))
    ring_rows(polynomial_weights(b, _unit_gradients(q), n_rows), ring_coefficients(), rings, ids, vals)
    indptr = np.arange(0, 12 * q + 1, 12)
    mats = []
    for r in range(n_rows):
        M = sp.csr_matrix((vals[r].ravel(), ids.ravel(), indptr), shape=(q, n))
        M.has_canonical_format = True
        M.eliminate_zeros()  # e.g. at a vertex: only its own ring
        mats.append(M)
    return mats


def walk_rows(table: PatchTable, starts: StartKeys, f: np.ndarray, b: np.ndarray, n_rows: int, depth):
    """Rows over the control vertices of the points (face ``f``, bary ``b``, walked to
    ``depth``, one per point or one for all): value, then ∂/∂u, ∂/∂v, then ∂²/∂u², ∂²/∂u∂v,
    ∂²/∂v² (``n_rows`` of them, each a (q, n) CSR matrix). Points on regular input faces
    take the box spline directly."""
    n = starts.inp.n_vertices
    depth = np.broadcast_to(np.asarray(depth, np.int64), (len(f),))
    rings = starts.rings[f]
    fast = rings[:, 0] >= 0
    if fast.any():
        rest = np.flatnonzero(~fast)
        where = np.empty(len(f), np.int64)  # each point's row in [rest; fast]
        where[rest] = np.arange(len(rest))
        where[fast] = len(rest) + np.arange(int(fast.sum()))
        slow = walk_rows(table, starts, f[rest], b[rest], n_rows, depth[rest]) if len(rest) else [None] * n_rows
        quick = _ring_rows(rings[fast], b[fast], n_rows, n)
        return [sp.csr_matrix(sp.vstack([a, c] if a is not None else [c]))[where] for a, c in zip(slow, quick)]
    q = len(f)
    keys0 = starts.of(f)
    out = walk(table, keys0, b, _unit_gradients(q), n_rows, depth, table.regular_stop)
    nv0 = table.nv.a[keys0]
    # Onto the control vertices: each point's first patch, by increasing vertex id.
    row, k = np.nonzero(np.arange(out.shape[1])[None, :] < nv0[:, None])
    base = starts.v0[f][row]
    loc = starts.order.a[base + k]
    cols = starts.vids.a[base + loc]
    indptr = np.concatenate([[0], np.cumsum(nv0)])
    mats = []
    for r in range(n_rows):
        M = sp.csr_matrix((out[row, loc, r], cols, indptr), shape=(q, n))
        M.has_canonical_format = True  # sorted, no duplicates: one patch's distinct vertices
        M.eliminate_zeros()  # the vertices of the first patch a row does not reach
        mats.append(M)
    return mats


def walk_points(table: PatchTable, starts: StartKeys, f: np.ndarray, b: np.ndarray, n_rows: int, depth,
                X: np.ndarray) -> np.ndarray:
    """``[R @ X for R in walk_rows(...)]`` (n_rows, q, d) without forming the walk's
    matrices, with the same bits; the derivatives of points walked past ``FORWARD_LEVELS``
    applied to the data forward instead (:func:`._carry_kernels.forward_points`), exact to
    rounding where the rows lose digits."""
    res = np.zeros((n_rows, len(f), X.shape[1]))
    depth = np.broadcast_to(np.asarray(depth, np.int64), (len(f),))
    fast = starts.rings[f, 0] >= 0
    on = np.flatnonzero(fast)
    if len(on):
        ring_points(polynomial_weights(b[on], _unit_gradients(len(on)), n_rows), ring_coefficients(), starts.rings[f[on]],
                    X, res, on)
    rest = np.flatnonzero(~fast)
    if len(rest):
        keys0 = starts.of(f[rest])
        by_key = np.argsort(keys0, kind="stable")  # points on one patch together: the tables they read stay cached
        rest, keys0 = rest[by_key], keys0[by_key]
        args, at = _last_weights(table, keys0, b[rest], _unit_gradients(len(rest)), n_rows, depth[rest],
                                 table.regular_stop, n_rows == 1)
        base = starts.v0[f[rest]]
        if len(at):  # a vertex of a level before the last: that vertex's limit position (see walk)
            value, _ = _last_weights(table, keys0[at], b[rest[at]], _unit_gradients(len(at)), 1, depth[rest[at]],
                                     table.regular_stop, True)
            vals = np.zeros((1, len(at), X.shape[1]))
            _carry_back(value, base[at], starts, X, vals, np.arange(len(at)))
        stop = args[3]
        deep = np.zeros(len(rest), bool)
        if n_rows > 1:
            deep = stop > np.where(np.asarray(starts.inp.face_sharp)[f[rest]], *FORWARD_LEVELS)
        if not deep.any():
            _carry_back(args, base, starts, X, res, rest)  # evaluation_matrix(...) @ X, to the bit
            if len(at):
                res[0, rest[at]] = vals[0]
            return res
        shallow, deep = np.flatnonzero(~deep), np.flatnonzero(deep)
        if len(shallow):
            _carry_back(_points_of(args, shallow), base[shallow], starts, X, res, rest[shallow])
        W, *per_point = _points_of(args, deep)
        value = (np.ascontiguousarray(W[:, :1]), *per_point)
        _carry_back(value, base[deep], starts, X, res, rest[deep])  # the value alone: its rows' bits
        out = np.zeros((n_rows, len(deep), X.shape[1]))
        kernel = forward_points if _threaded(len(deep)) else forward_points_serial
        kernel(W, *per_point, base[deep], starts.vids.a, X, out, 1)
        res[1:, rest[deep]] = out[1:]
        if len(at):
            res[0, rest[at]] = vals[0]
    return res


def _points_of(args, idx: np.ndarray) -> tuple:
    """:func:`_last_weights`' output for the points ``idx`` (its first six are per point)."""
    return tuple(a[idx] for a in args[:6]) + tuple(args[6:])


def _carry_back(args, base, starts: StartKeys, X: np.ndarray, res: np.ndarray, at: np.ndarray):
    """The rows of :func:`_last_weights`' ``args`` carried back and applied to ``X`` into
    ``res[:, at]`` (:func:`._carry_kernels.back_points`)."""
    kernel = back_points if _threaded(len(at)) else back_points_serial
    kernel(*args, base, starts.order.a, starts.vids.a, X, res, at)


@functools.cache
def ring_coefficients() -> np.ndarray:
    """The quartic's 15 Bernstein coefficients (:mod:`.regular`) over the twelve control
    vertices of a regular face, in the order of :func:`._walk_kernels.regular_rings`: the
    walk's own quartic on a face of a regular torus (the same for every regular face; Loop's
    and Warren's weights agree at valence 6), rounded to the 24ths they are."""
    V, F = regular_torus()
    inp = open_gate(F, None, 0, n_vertices=len(V), scheme="loop")
    table = PatchTable("loop", "loop")
    starts = StartKeys(inp, table)
    ring = starts.rings[0]
    keys0 = starts.of(np.zeros(15, np.int64))
    out = walk(table, keys0, GRID.copy(), _unit_gradients(15), 1, 2, True)[:, :, 0]  # (15, nv): on the first patch
    vids = starts.vids.a[starts.v0[0]:][:out.shape[1]]
    M = np.zeros((15, inp.n_vertices))
    M[:, vids] = out
    assert not M[:, np.setdiff1d(np.arange(inp.n_vertices), ring)].any()  # the box spline's support
    C = 24 * (GRID_INVERSE @ M[:, ring])
    assert np.abs(C - np.round(C)).max() < 1e-9  # the box spline's coefficients are k / 24: exactly so
    return np.round(C) / 24
