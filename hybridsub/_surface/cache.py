"""The patch cache: every distinct patch's step computed once.

Below the first levels the patches of the descent (:mod:`.descent`) repeat: regular √3 and
Loop neighbourhoods, crease and boundary sectors, the neighbourhood of an extraordinary
vertex, each level's shapes the same up to a rigid motion and a scale. A patch is described
by a *key*: its faces and vertices in a canonical order (breadth first from the centre face,
entered at its corner 0, each face's corners from the one it was entered at), their
connectivity, tags and shapes (each face's corners moved by a rigid motion of its own, the
whole patch scaled by the centre face's first edge, rounded to :data:`GRID`), and Kobbelt's
step parity for ``"sqrt3"``. Two patches with one key are the same tagged mesh up to the
numbering of their vertices, so one of them, the key's *representative*, stands for all: it
is refined once with the project's own step (``descent.step``'s machinery) and what the
walk needs is kept in flat tables:

- per key, its candidate child faces (those ``descent.step`` chooses among), each with the
  map ``M`` of the point's barycentric coordinates into the child's (its inverse transposed
  holds the child's corners over the centre face, to follow (u, v)) and, once a point has
  chosen it, the child's key and the step's rows restricted to (child patch × patch)
  vertices ``T`` (stored once per distinct content: they depend on the connectivity and tags
  alone, so keys that differ in shape share them);
- per key ending a descent, the interpolation stencil's six vertices with their exact limit
  rows over the patch (``descent.limit_rows``), and the stencil's per-patch data.

Everything is exact by construction: the tables hold the existing code's results on the
representatives.
"""

from __future__ import annotations

import numpy as np

from .._topology import Level
from .._refiner import barycentric
from ._cache_kernels import canonical_order, face_records, key_hashes, regular_flags
from .descent import (
    Patches,
    cut_children,
    limit_rows,
    refine_patches,
    stencil_nodes,
)

#: Shapes in a key are rounded to this (relative to the centre face's first edge).
GRID = 1e-9


class Grow:
    """A flat array grown by appending blocks (capacity grown by half)."""

    def __init__(self, shape=(), dtype=np.float64, fill=0):
        self._a = np.full((16,) + tuple(shape), fill, dtype)
        self.fill = fill
        self.n = 0

    def append(self, block) -> int:
        block = np.asarray(block, self._a.dtype)
        start, end = self.n, self.n + len(block)
        if end > len(self._a):
            new = np.empty((max(len(self._a) * 3 // 2, end),) + self._a.shape[1:], self._a.dtype)  # read to n only
            new[:self.n] = self._a[:self.n]
            self._a = new
        self._a[start:end] = block
        self.n = end
        return start

    def extend_to(self, n: int):
        if n > self.n:
            self.append(np.full((n - self.n,) + self._a.shape[1:], self.fill, self._a.dtype))

    @property
    def a(self) -> np.ndarray:
        return self._a[:self.n]

    @property
    def capacity_bytes(self) -> int:
        return self._a.nbytes


def canonicalise(level: Level, corner: np.ndarray, shape: np.ndarray, centre: np.ndarray, fstart: np.ndarray):
    """Canonical orders and key records of the pieces of ``level`` (node ``i``: faces
    ``fstart[i]:fstart[i + 1]``, centre face ``centre[i]``).

    Returns ``fperm``, ``vperm``, ``vstart`` (canonical faces and vertices, the vertex ranges
    per node), ``rec`` (m, 13) int64 per canonical face and ``norm`` (m, 3, 2) the normalised
    shapes, every face's corners from the one it was entered at (see
    :func:`._cache_kernels.face_records`).
    """
    F = np.ascontiguousarray(level.faces, dtype=np.int64)
    m, k = len(F), len(centre)
    fperm, vperm = np.empty(m, np.int64), np.empty(level.n_vertices, np.int64)
    vstart = np.empty(k + 1, np.int64)
    twin = np.ascontiguousarray(level.twin, dtype=np.int64)
    entry = np.zeros(m, np.int64)
    canonical_order(F, twin, level.n_vertices, fstart, centre, fperm, vperm, vstart, entry)
    frank = np.empty(m, np.int64)
    frank[fperm] = np.arange(m)
    node_f = np.repeat(np.arange(k), np.diff(fstart))
    vrank = np.empty(level.n_vertices, np.int64)
    vrank[vperm] = np.arange(len(vperm)) - np.repeat(vstart[:-1], np.diff(vstart))
    hs = np.zeros(3 * m) if level.hsharp is None else np.ascontiguousarray(level.hsharp, dtype=np.float64)
    sc = shape[centre]
    scale = np.hypot(sc[:, 1, 0] - sc[:, 0, 0], sc[:, 1, 1] - sc[:, 0, 1])
    rec = np.empty((m, 13), np.int64)
    norm = np.empty((m, 3, 2))
    face_records(F, twin, hs.view(np.int64), level.face_sharp, np.ascontiguousarray(shape, dtype=np.float64), fperm,
                 frank, vrank, entry, fstart, node_f, scale, GRID, rec, norm)
    return fperm, vperm, vstart, rec, norm


class PatchTable:
    """Keys, representatives and the transition tables of one scheme (see the module doc)."""

    def __init__(self, scheme: str, loop_weights: str, tol: float = 1e-12, max_levels: int = 60,
                 vertex_sharpness: bool = False):
        self.scheme, self.loop_weights = scheme, loop_weights
        # Corner tags as a mask, or (semi-sharp corners) as each vertex's sharpness left.
        self.vertex_sharpness = vertex_sharpness
        self.tol, self.max_levels = tol, max_levels
        self.index: dict[tuple, int] = {}  # key hash → key id
        # The representatives, canonical, one after another: key k's faces rep_f0[k]:+rep_nf[k]
        # (corners, twins, sharpness of its halfedges from rep_h0[k] if any, else −1, Loop
        # faces, shapes), its vertices rep_v0[k]:+nv[k] (corner tags).
        self.rep_f0, self.rep_nf = Grow((), np.int64), Grow((), np.int64)
        self.rep_v0, self.rep_h0 = Grow((), np.int64), Grow((), np.int64)
        self.rep_F, self.rep_twin = Grow((3,), np.int32), Grow((3,), np.int32)
        self.rep_hs = Grow((3,))
        self.rep_fs = Grow((), np.bool_)
        self.rep_corner = Grow((), np.float64 if vertex_sharpness else np.bool_)
        self.rep_shape = Grow((3, 2))
        self.parity = Grow((), np.int8)  # per key: 1 when the next step is odd ("sqrt3" only)
        self.nv = Grow((), np.int64)
        self.cand_start = Grow((), np.int64, -1)  # per key (−1: not refined yet)
        self.cand_count = Grow((), np.int64)
        self.M = Grow((3, 3))  # per candidate
        self.child = Grow((), np.int64, -1)  # the child's key (−1: not cut yet)
        self.owner = Grow((), np.int64)  # the key a candidate belongs to
        self.slot = Grow((), np.int64)  # its index among the key's 24 candidate slots
        self.t_start = Grow((), np.int64)  # T of each candidate: entries t_start:t_end
        self.t_end = Grow((), np.int64)
        self.t_row = Grow((), np.int32)
        self.t_col = Grow((), np.int32)
        self.t_val = Grow(())
        self.final = Grow((), np.int64, -1)  # per key: its stencil record (−1: none yet)
        self.regular_stop = scheme != "sqrt3"  # stop at regular Loop patches (regular.py)
        self.regular = Grow((), np.int8)  # per key: 1 a regular Loop patch (regular.is_regular), else 0
        self.poly = Grow((), np.int64, -1)  # per regular key: the block of its quartic's coefficients
        self.st_ids = Grow((6,), np.int64)  # per stencil record
        self.st_blk = Grow((), np.int64)  # per stencil record: the block of its six vertices' limit rows
        # Blocks: rows over a patch's vertices, kept by vertex (only those where a row is not
        # zero): block b's vertices blk_col[blk_c0[b]:][:blk_nc[b]], each with its rows' values
        # one after another in blk_val from blk_v0[b].
        self.blk_v0 = Grow((), np.int64)
        self.blk_c0 = Grow((), np.int64)
        self.blk_nc = Grow((), np.int64)
        self.blk_col = Grow((), np.int32)
        self.blk_val = Grow(())
        self.st_node = Grow((9,))  # c0 (2), scale (1), the face's corners (6)
        self.st_full = Grow((), np.bool_)
        self.st_inv = Grow((6, 6))  # the inverse of the interpolation matrix
        self._recent = None
        self._t_index: dict[bytes, int] = {}  # a transition's contents → its first entry
        self._t_key_bytes = 0

    @property
    def nbytes(self) -> int:
        """What the cache holds: its arrays' capacity (they grow by half), its two dictionaries
        estimated."""
        grown = sum(g.capacity_bytes for g in vars(self).values() if isinstance(g, Grow))
        return grown + 120 * (len(self.index) + len(self._t_index)) + self._t_key_bytes

    @property
    def n_keys(self) -> int:
        return self.nv.n

    @property
    def reps(self) -> list[tuple]:
        """The representatives as ``(F, twin, hsharp or None, face_sharp, corner, shape)`` per
        key (for inspection; the tables keep them flat)."""
        out = []
        for k in range(self.n_keys):
            f = slice(self.rep_f0.a[k], self.rep_f0.a[k] + self.rep_nf.a[k])
            h0 = self.rep_h0.a[k]
            hs = None if h0 < 0 else self.rep_hs.a[h0:h0 + self.rep_nf.a[k]].ravel()
            out.append((self.rep_F.a[f], self.rep_twin.a[f].ravel(), hs, self.rep_fs.a[f],
                        self.rep_corner.a[self.rep_v0.a[k]:][:self.nv.a[k]], self.rep_shape.a[f]))
        return out

    def register(self, level, corner, shape, centre, fstart, parity):
        """Key ids of the pieces of ``level`` (new keys get the piece as representative) and
        the canonical vertex orders: ``vperm``, ``vstart``."""
        fperm, vperm, vstart, rec, norm = canonicalise(level, corner, shape, centre, fstart)
        cv = corner[vperm]
        if cv.dtype != self.rep_corner.a.dtype:
            raise AssertionError("corner tags and the table disagree on vertex sharpness")  # pragma: no cover
        h = np.empty((len(centre), 2), np.uint64)  # 128 bits: a collision is not a practical concern
        bits = cv.view(np.int64) if self.vertex_sharpness else cv.astype(np.int64)  # a sharpness by its bits
        key_hashes(rec, fstart, bits, vstart, parity, h)
        reg = np.empty(len(centre), np.int8)
        regular_flags(rec, fstart, cv != 0 if self.vertex_sharpness else cv, vstart, reg)
        ids = np.empty(len(centre), np.int64)
        new = []
        for i, key in enumerate(zip(h[:, 0].tolist(), h[:, 1].tolist())):
            kid = self.index.get(key)
            if kid is None:
                kid = self.index[key] = self.n_keys + len(new)
                new.append(i)
            ids[i] = kid
        if new:
            self._add_representatives(np.array(new), rec, fstart, fperm, level.face_sharp, cv, vstart, norm)
            self.parity.append(np.full(len(new), parity))
            self.regular.append(reg[new])
        n = self.n_keys
        for g in (self.cand_start, self.final, self.poly):
            g.extend_to(n)
        self.cand_count.extend_to(n)
        return ids, vperm, vstart

    def _add_representatives(self, new, rec, fstart, fperm, face_sharp, cv, vstart, norm):
        """The pieces ``new`` of a batch (:meth:`register`'s arrays) become the representatives
        of the next keys, in order."""
        nf = fstart[new + 1] - fstart[new]
        nv = vstart[new + 1] - vstart[new]
        f = _ranges(fstart[new], nf)
        f0 = _firsts(nf)  # each piece's first face among f
        hs = np.ascontiguousarray(rec[f, 7:10]).view(np.float64)  # the halfedges' sharpness, rotated
        sharp = np.add.reduceat((hs != 0).any(axis=1), f0) > 0
        self.rep_f0.append(self.rep_F.n + f0)
        self.rep_nf.append(nf)
        self.rep_v0.append(self.rep_corner.n + _firsts(nv))
        h0 = np.full(len(new), -1, np.int64)
        h0[sharp] = self.rep_hs.n + _firsts(nf[sharp])
        self.rep_h0.append(h0)
        self.rep_hs.append(hs[_ranges(f0[sharp], nf[sharp])])
        self.rep_F.append(rec[f, :3])
        self.rep_twin.append(rec[f, 3:6])
        self.rep_fs.append(face_sharp[fperm[f]])
        self.rep_shape.append(norm[f])
        self.rep_corner.append(cv[_ranges(vstart[new], nv)])
        self.nv.append(nv)

    def regular_keys(self, keys: np.ndarray) -> np.ndarray:
        """Whether each key is a regular Loop patch (:func:`.regular.is_regular`)."""
        return self.regular.a[keys] == 1

    def patches(self, keys: np.ndarray):
        """The representatives of ``keys`` as one mesh of disjoint pieces; also the face and
        vertex offsets of each piece (its centre is its first face)."""
        keys = np.asarray(keys, np.int64)
        nf, nv = self.rep_nf.a[keys], self.nv.a[keys]
        foff = np.concatenate([[0], np.cumsum(nf)])
        voff = np.concatenate([[0], np.cumsum(nv)])
        f = _ranges(self.rep_f0.a[keys], nf)
        F = self.rep_F.a[f].astype(np.int64) + np.repeat(voff[:-1], nf)[:, None]
        tw = self.rep_twin.a[f].astype(np.int64)
        tw = np.where(tw >= 0, tw + 3 * np.repeat(foff[:-1], nf)[:, None], -1).ravel()
        h0 = self.rep_h0.a[keys]
        sharp = h0 >= 0
        hs = None
        if sharp.any():
            hs = np.zeros((len(f), 3))
            hs[_ranges(foff[:-1][sharp], nf[sharp])] = self.rep_hs.a[_ranges(h0[sharp], nf[sharp])]
            hs = hs.ravel()
        level = Level(F, int(voff[-1]), tw, hs, self.rep_fs.a[f])
        uv = np.repeat(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])[None], len(keys), axis=0)
        p = Patches(level, self.rep_corner.a[_ranges(self.rep_v0.a[keys], nv)], self.rep_shape.a[f],
                    foff[:-1].copy(), uv)
        return p, foff, voff

    def _refine(self, keys: np.ndarray):
        """One step of the representatives of ``keys`` (all of one parity)."""
        p, _, voff = self.patches(keys)
        plan, S, faces1, child, shapes_of, cid, ccorn = refine_patches(p, self.scheme, 2 - int(self.parity.a[keys[0]]),
                                                                       self.loop_weights)
        return {"keys": keys, "p": p, "voff": voff, "plan": plan, "S": S.tocsr(), "faces1": faces1, "child": child,
                "shapes_of": shapes_of, "cid": cid, "ccorn": ccorn}

    def _refined(self, keys: np.ndarray):
        """:meth:`_refine` per parity; the last result is kept for :meth:`fill_children`."""
        out = []
        par = self.parity.a[keys]
        for b in np.unique(par):
            out.append(self._refine(keys[par == b]))
        self._recent = out
        return out

    def fill_steps(self, keys: np.ndarray):
        """The candidates of ``keys`` (unique, not refined yet): their maps ``M``."""
        for r in self._refined(keys):
            X = r["p"].shape[r["p"].face]  # (k, 3, 2)
            cid, cc = r["cid"], r["ccorn"]
            M = np.swapaxes(barycentric(cc[:, :, None], X[:, None, :, :]), 2, 3)  # (k, 24, 3 bary, 3 corners)
            valid = cid >= 0
            cnt = valid.sum(axis=1)
            kk, jj = np.nonzero(valid)
            start = self.M.append(M[kk, jj])
            self.child.append(np.full(len(kk), -1))
            self.owner.append(r["keys"][kk])
            self.slot.append(jj)
            self.t_start.append(np.zeros(len(kk), np.int64))
            self.t_end.append(np.zeros(len(kk), np.int64))
            self.cand_start.a[r["keys"]] = start + np.concatenate([[0], np.cumsum(cnt)[:-1]])
            self.cand_count.a[r["keys"]] = cnt

    def fill_children(self, cands: np.ndarray):
        """Cut the child patches of the candidates ``cands`` (unique): their keys and ``T``."""
        owners = self.owner.a[cands]
        recent = list(self._recent or [])
        have = np.concatenate([r["keys"] for r in recent]) if recent else np.zeros(0, np.int64)
        other = ~np.isin(owners, have)
        if other.any():  # keys refined at an earlier level or call: again
            recent += self._refined(np.unique(owners[other]))
        for r in recent:
            pick = np.isin(owners, r["keys"])
            if pick.any():
                self._cut_children(r, cands[pick], owners[pick])

    def _cut_children(self, r, cands, owners):
        node = np.searchsorted(r["keys"], owners) if _sorted(r["keys"]) else _position(r["keys"], owners)
        centre = r["cid"][node, self.slot.a[cands]]
        nxt, corner_n, shape_n, cur, vsel, fstart = cut_children(r["p"], r["plan"], r["faces1"], r["child"],
                                                                 r["shapes_of"], centre)
        parity = int(self.parity.a[owners[0]]) ^ 1 if self.scheme == "sqrt3" else 0
        kids, vperm, vstart = self.register(nxt, corner_n, shape_n, cur, fstart, parity)
        T = r["S"][vsel[vperm]].tocoo()  # rows: the children's vertices in canonical order
        # Columns: the parent piece's vertices (canonical: the representative's own order).
        row_node = np.searchsorted(vstart, T.row, side="right") - 1
        col = T.col - r["voff"][node[row_node]]
        row = T.row - vstart[row_node]
        bounds = np.searchsorted(row_node, np.arange(len(centre) + 1))
        self._add_transitions(cands, row.astype(np.int32), col.astype(np.int32), T.data, bounds)
        self.child.a[cands] = kids

    def _add_transitions(self, cands, row, col, val, bounds):
        """Store candidate ``cands[i]``'s transition, entries ``bounds[i]:bounds[i + 1]`` of
        ``row``, ``col``, ``val``, once per distinct content: patches that differ in shape
        alone (most keys beside creases, and every input face's in a regular region) share
        their step's rows, so the table holds each once (a fifth of the entries on fandisk's
        hybrid) and the carry reads fewer distinct ones. Contents are told apart by their
        bytes (the weights by their bits), so sharing is exact."""
        n = np.diff(bounds)
        start = np.empty(len(cands), np.int64)
        own = []
        end = self.t_row.n  # where the next new one goes
        for i, (a, b) in enumerate(zip(bounds[:-1].tolist(), bounds[1:].tolist())):
            key = row[a:b].tobytes() + col[a:b].tobytes() + val[a:b].tobytes()
            at = self._t_index.get(key)
            if at is None:
                at = self._t_index[key] = end
                self._t_key_bytes += len(key)
                own.append(i)
                end += b - a
            start[i] = at
        keep = _ranges(bounds[own], n[own])
        self.t_row.append(row[keep])
        self.t_col.append(col[keep])
        self.t_val.append(val[keep])
        self.t_start.a[cands] = start
        self.t_end.a[cands] = start + n

    def fill_stencils(self, keys: np.ndarray):
        """The last interpolation's data of ``keys`` (unique, none yet): stencil vertices, their
        limit rows over the patch, the stencil matrix."""
        p, _, voff = self.patches(keys)
        ids, A, full, c0, scale, here = stencil_nodes(p)
        needed = np.unique(ids[ids >= 0])
        L = limit_rows(p, needed, self.scheme, self.loop_weights, self.tol, self.max_levels)
        rec = self.st_ids.append(np.where(ids >= 0, ids - voff[:-1, None], -1))
        self.st_inv.append(np.linalg.inv(A))
        self.st_full.append(full)
        self.st_node.append(np.concatenate([c0.reshape(-1, 2), scale.reshape(-1, 1), here.reshape(-1, 6)], axis=1))
        nv = np.diff(voff)
        starts = np.concatenate([[0], np.cumsum(6 * nv)[:-1]])
        flat = np.zeros(int(6 * nv.sum()))
        Lr = L[np.maximum(ids, 0).ravel()].tocoo()  # row 6 i + j: key i's slot j
        ok = (ids.ravel() >= 0)[Lr.row]
        key = Lr.row[ok] // 6
        np.add.at(flat, starts[key] + (Lr.row[ok] % 6) * nv[key] + Lr.col[ok] - voff[key], Lr.data[ok])
        self.st_blk.append(self.add_blocks(flat, 6, nv))
        self.final.a[keys] = rec + np.arange(len(keys))

    def add_blocks(self, dense: np.ndarray, rows: int, nv: np.ndarray) -> np.ndarray:
        """Store blocks given one after another in ``dense``, block ``i`` (rows × nv[i]); returns
        their ids. Vertices where every row is zero are left out."""
        k = len(nv)
        size = rows * nv
        starts = np.concatenate([[0], np.cumsum(size)])
        cstart = np.concatenate([[0], np.cumsum(nv)])
        blk = np.repeat(np.arange(k), size)
        pos = np.arange(len(dense)) - starts[blk]
        live = np.zeros(int(cstart[-1]), bool)
        live[(cstart[blk] + pos % nv[blk])[dense != 0]] = True
        kept = np.flatnonzero(live)
        bk = np.searchsorted(cstart, kept, side="right") - 1
        col = kept - cstart[bk]
        nc = np.bincount(bk, minlength=k)
        vals = dense[starts[bk][:, None] + np.arange(rows)[None, :] * nv[bk][:, None] + col[:, None]]
        ids = self.blk_nc.n + np.arange(k)
        self.blk_v0.append(self.blk_val.n + rows * np.concatenate([[0], np.cumsum(nc)[:-1]]))
        self.blk_c0.append(self.blk_col.n + np.concatenate([[0], np.cumsum(nc)[:-1]]))
        self.blk_nc.append(nc)
        self.blk_col.append(col)
        self.blk_val.append(vals.ravel())
        return ids


def _firsts(lengths: np.ndarray) -> np.ndarray:
    """Where each of consecutive runs of ``lengths`` starts: their exclusive prefix sums."""
    out = np.zeros(len(lengths), np.int64)
    np.cumsum(lengths[:-1], out=out[1:])
    return out


def _ranges(starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """``concatenate([arange(s, s + n) for s, n in zip(starts, lengths)])``."""
    return np.repeat(starts - _firsts(lengths), lengths) + np.arange(int(lengths.sum()))


def _sorted(a: np.ndarray) -> bool:
    return bool(np.all(a[1:] >= a[:-1]))


def _position(keys: np.ndarray, x: np.ndarray) -> np.ndarray:
    order = np.argsort(keys)
    return order[np.searchsorted(keys[order], x)]
