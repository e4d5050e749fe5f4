"""The patch cache: every distinct patch's step computed once.

Below the first levels the patches of the descent (:mod:`.descent`) repeat: regular √3 and
Loop neighbourhoods, crease and boundary sectors, the neighbourhood of an extraordinary
vertex. A patch is described by a *key*: its faces and vertices in a canonical order
(breadth first from the centre face, entered at its corner 0, each face's corners from the
one it was entered at), their connectivity, tags and shapes (each face's corners moved by a
rigid motion of its own, the whole patch scaled by the centre face's first edge, rounded to
:data:`GRID`: every face is equilateral in the chart, so the shapes only confirm it), and
Kobbelt's step parity for ``"sqrt3"``. Two patches with one key are the same tagged mesh up to the
numbering of their vertices, so one of them, the key's *representative*, stands for all: it
is refined once with the project's own step (``descent.step``'s machinery) and what the
walk needs is kept in flat tables:

- per key, its candidate child faces (those ``descent.step`` chooses among), each with the
  map ``M`` of the point's barycentric coordinates into the child's (its inverse transposed
  holds the child's corners over the centre face, to follow (u, v)) and, once a point has
  chosen it, the child's key and the step's rows restricted to (child patch × patch)
  vertices ``T`` (stored once per distinct content: keys of other connectivity often have
  the same rows);
- per key ending a descent, the interpolation stencil's six vertices with their exact limit
  rows over the patch (``descent.limit_rows``), and the stencil's per-patch data.

Everything is exact by construction: the tables hold the existing code's results on the
representatives.
"""

from __future__ import annotations

import threading

import numpy as np

from .._topology import Level
from .._refiner import barycentric
from ._cache_kernels import (
    canonical_order,
    face_records,
    gather_pieces,
    key_hashes,
    regular_flags,
    representative_rows,
    transition_hashes,
)
from .descent import (
    Patches,
    cut_children,
    limit_rows,
    refine_patches,
    stencil_nodes,
)

#: Shapes in a key are rounded to this (relative to the centre face's first edge).
GRID = 1e-9
#: Refined steps kept for cutting their candidates' children later.
KEPT = 4


class Grow:
    """A flat array grown by appending blocks (capacity grown by half)."""

    def __init__(self, shape=(), dtype=np.float64, fill=0):
        self._a = np.full((16,) + tuple(shape), fill, dtype)
        self.fill = fill
        self.n = 0

    def append(self, block) -> int:
        if self._a.dtype == np.int16:  # small indices: widened once a block needs more
            block = np.asarray(block)
            if len(block) and (block.max() > 32767 or block.min() < -32768):
                self._a = self._a.astype(np.int32)
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
    :func:`._cache_kernels.face_records`), and ``entry`` (m) that corner of every face.
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
    return fperm, vperm, vstart, rec, norm, entry


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
        self.rep_F, self.rep_twin = Grow((3,), np.int16), Grow((3,), np.int16)
        self.rep_hs = Grow((3,))
        self.rep_fs = Grow((), np.bool_)
        self.rep_corner = Grow((), np.float64 if vertex_sharpness else np.bool_)
        self.rep_shape = Grow((3,))  # corner 1's x, corner 2's x, y: corner 0 at the origin, 1 on +x
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
        self._kept = []  # the last steps refined (:meth:`_refine`), for cutting their children
        self._order = []  # the keys last given steps, by parity: the order children are registered in
        self._t_index: dict[tuple, int] = {}  # a transition's contents (hashed) → its first entry
        self.lock = threading.RLock()  # held while a walk fills the table
    def __getstate__(self) -> dict:
        return {k: v for k, v in vars(self).items() if k != "lock"}

    def __setstate__(self, state: dict) -> None:
        vars(self).update(state)
        self.lock = threading.RLock()

    @property
    def nbytes(self) -> int:
        """What the cache holds: its arrays' capacity (they grow by half), its two
        dictionaries estimated."""
        grown = sum(g.capacity_bytes for g in vars(self).values() if isinstance(g, Grow))
        return grown + 120 * (len(self.index) + len(self._t_index))

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
                        self.rep_corner.a[self.rep_v0.a[k]:][:self.nv.a[k]], _shapes(self.rep_shape.a[f])))
        return out

    def _canonical(self, level, corner, shape, centre, fstart):
        """:func:`canonicalise`'s output, the pieces' corner tags in canonical order and their
        regular flags (:func:`regular_flags`)."""
        fperm, vperm, vstart, rec, norm, entry = canonicalise(level, corner, shape, centre, fstart)
        cv = corner[vperm]
        if cv.dtype != self.rep_corner.a.dtype:
            raise AssertionError("corner tags and the table disagree on vertex sharpness")  # pragma: no cover
        reg = np.empty(len(centre), np.int8)
        regular_flags(rec, fstart, cv != 0 if self.vertex_sharpness else cv, vstart, reg)
        return fperm, vperm, vstart, rec, norm, entry, cv, reg

    def register(self, level, corner, shape, centre, fstart, parity):
        """Key ids of the pieces of ``level`` (new keys get the piece as representative) and
        the canonical vertex orders: ``vperm``, ``vstart``."""
        fperm, vperm, vstart, rec, norm, _, cv, reg = self._canonical(level, corner, shape, centre, fstart)
        return self._keys_of(rec, fstart, cv, vstart, norm, level.face_sharp[fperm], reg, parity), vperm, vstart

    def _bits(self, cv: np.ndarray) -> np.ndarray:
        """Corner tags as the words hashed: a sharpness by its bits."""
        return cv.view(np.int64) if self.vertex_sharpness else cv.astype(np.int64)

    def _keys_of(self, rec, fstart, cv, vstart, norm, fs, reg, parity):
        """Key ids of pieces given canonical: face records ``rec`` (:func:`canonicalise`) of
        faces ``fstart[i]:fstart[i + 1]``, corner tags ``cv`` of vertices
        ``vstart[i]:vstart[i + 1]``, normalised shapes ``norm``, sharp faces ``fs``, regular
        flags ``reg``; new keys get the piece as representative."""
        h = np.empty((len(fstart) - 1, 2), np.uint64)  # 128 bits: a collision is not a practical concern
        key_hashes(rec, fstart, self._bits(cv), vstart, parity, h)
        ids = np.empty(len(h), np.int64)
        new = []
        for i, key in enumerate(zip(h[:, 0].tolist(), h[:, 1].tolist())):
            kid = self.index.get(key)
            if kid is None:
                kid = self.index[key] = self.n_keys + len(new)
                new.append(i)
            ids[i] = kid
        if new:
            self._add_representatives(np.array(new), rec, fstart, fs, cv, vstart, norm, parity)
            self.parity.append(np.full(len(new), parity))
            self.regular.append(reg[new])
        n = self.n_keys
        for g in (self.cand_start, self.final, self.poly):
            g.extend_to(n)
        self.cand_count.extend_to(n)
        return ids

    def _add_representatives(self, new, rec, fstart, fs, cv, vstart, norm, parity):
        """The pieces ``new`` of a batch (:meth:`_keys_of`'s arrays) become the representatives
        of the next keys, in order (:func:`._cache_kernels.representative_rows`)."""
        nf = fstart[new + 1] - fstart[new]
        nv = vstart[new + 1] - vstart[new]
        m, k = int(nf.sum()), len(new)
        F, tw, hb = np.empty((m, 3), np.int64), np.empty((m, 3), np.int64), np.empty((m, 3), np.int64)
        crec, fsn, shape3 = np.empty((m, 10), np.int64), np.empty(m, np.bool_), np.empty((m, 3))
        cvn, sharp = np.empty(int(nv.sum()), cv.dtype), np.empty(k, np.bool_)
        representative_rows(new, rec, fstart, norm, fs, cv, vstart, F, tw, fsn, shape3, hb, crec, cvn, sharp)
        f0, v0 = _firsts(nf), _firsts(nv)
        self.rep_f0.append(self.rep_F.n + f0)
        self.rep_nf.append(nf)
        self.rep_v0.append(self.rep_corner.n + v0)
        h0 = np.full(k, -1, np.int64)
        h0[sharp] = self.rep_hs.n + _firsts(nf[sharp])
        self.rep_h0.append(h0)
        self.rep_hs.append(hb[_ranges(f0[sharp], nf[sharp])].view(np.float64))
        self.rep_F.append(F)
        self.rep_twin.append(tw)
        self.rep_fs.append(fsn)
        self.rep_shape.append(shape3)
        self.rep_corner.append(cvn)
        self.nv.append(nv)
    def regular_keys(self, keys: np.ndarray) -> np.ndarray:
        """Whether each key is a regular Loop patch (:func:`.regular.is_regular`)."""
        return self.regular.a[keys] == 1

    def _pieces(self, keys: np.ndarray):
        """The representatives of ``keys`` as flat arrays of disjoint pieces: faces, halfedge
        twins, face shapes, and the face and vertex offsets of each piece
        (:func:`._cache_kernels.gather_pieces`)."""
        keys = np.ascontiguousarray(keys, dtype=np.int64)
        foff = np.concatenate([[0], np.cumsum(self.rep_nf.a[keys])])
        voff = np.concatenate([[0], np.cumsum(self.nv.a[keys])])
        m = int(foff[-1])
        F, tw, shape = np.empty((m, 3), np.int64), np.empty(3 * m, np.int64), np.empty((m, 3, 2))
        gather_pieces(keys, self.rep_f0.a, self.rep_nf.a, self.rep_F.a, self.rep_twin.a, self.rep_shape.a, foff, voff,
                      F, tw, shape)
        return F, tw, shape, foff, voff

    def patches(self, keys: np.ndarray):
        """The representatives of ``keys`` as one mesh of disjoint pieces; also the face and
        vertex offsets of each piece (its centre is its first face)."""
        keys = np.asarray(keys, np.int64)
        F, tw, shape, foff, voff = self._pieces(keys)
        nf, nv = np.diff(foff), np.diff(voff)
        f = _ranges(self.rep_f0.a[keys], nf)
        h0 = self.rep_h0.a[keys]
        sharp = h0 >= 0
        hs = None
        if sharp.any():
            hs = np.zeros((len(f), 3))
            hs[_ranges(foff[:-1][sharp], nf[sharp])] = self.rep_hs.a[_ranges(h0[sharp], nf[sharp])]
            hs = hs.ravel()
        level = Level(F, int(voff[-1]), tw, hs, self.rep_fs.a[f])
        uv = np.repeat(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])[None], len(keys), axis=0)
        p = Patches(level, self.rep_corner.a[_ranges(self.rep_v0.a[keys], nv)], shape, foff[:-1].copy(), uv)
        return p, foff, voff

    def _refine(self, keys: np.ndarray):
        """One step of the representatives of ``keys`` (all of one parity)."""
        p, foff, voff = self.patches(keys)
        plan, S, faces1, child, shapes_of, cid, ccorn = refine_patches(p, self.scheme, 2 - int(self.parity.a[keys[0]]),
                                                                       self.loop_weights)
        return {"keys": keys, "p": p, "foff": foff, "voff": voff, "plan": plan, "S": S.tocsr(), "faces1": faces1,
                "child": child, "shapes_of": shapes_of, "cid": cid, "ccorn": ccorn}

    def _refined(self, keys: np.ndarray):
        """:meth:`_refine` per parity; the results are kept a while for :meth:`fill_children`."""
        out = []
        par = self.parity.a[keys]
        for b in np.unique(par):
            out.append(self._refine(keys[par == b]))
        self._kept = (self._kept + out)[-KEPT:]
        return out

    def fill_steps(self, keys: np.ndarray):
        """The candidates of ``keys`` (unique, not refined yet): their maps ``M``, numbered by
        parity, then key (the order :meth:`fill_children` is given them in)."""
        par = self.parity.a[keys]
        self._order = [keys[par == b] for b in np.unique(par)]
        parts = []
        for r in self._refined(keys):
            X = r["p"].shape[r["p"].face]  # (k, 3, 2)
            cid, cc = r["cid"], r["ccorn"]
            valid = cid >= 0
            kk, jj = np.nonzero(valid)
            parts.append((r["keys"], valid, np.swapaxes(barycentric(cc[kk, jj][:, None], X[kk]), 1, 2)))
        got, valid, M = (np.concatenate(x) for x in zip(*parts))
        order = np.concatenate(self._order)
        perm = _position(got, order)
        cnt = valid.sum(axis=1)
        self._add_candidates(order, valid[perm], M[_ranges(_firsts(cnt)[perm], cnt[perm])])

    def _add_candidates(self, keys, valid, M):
        """Candidates ``valid`` (k, 24) of ``keys`` with their maps ``M`` (in that order)."""
        cnt = valid.sum(axis=1)
        kk, jj = np.nonzero(valid)
        start = self.M.append(M)
        self.child.append(np.full(len(kk), -1))
        self.owner.append(keys[kk])
        self.slot.append(jj)
        self.t_start.append(np.zeros(len(kk), np.int64))
        self.t_end.append(np.zeros(len(kk), np.int64))
        self.cand_start.a[keys] = start + np.concatenate([[0], np.cumsum(cnt)[:-1]])
        self.cand_count.a[keys] = cnt

    def fill_children(self, cands: np.ndarray):
        """Cut the child patches of the candidates ``cands`` (unique) from their owners' steps
        (refined again where no longer kept): their keys and ``T``.

        The pieces are registered in one order whichever step they are cut from: those whose
        owner was among the last keys given steps (:meth:`fill_steps`, by parity), then the
        others by parity (the order of refining them all again). A key's representative
        is the first piece met with that key, so the order is part of the result."""
        owners = self.owner.a[cands]
        par = self.parity.a[owners]
        groups, rest = [], np.ones(len(cands), bool)
        for g in self._order:
            pick = rest & np.isin(owners, g)
            if pick.any():
                groups.append(np.flatnonzero(pick))
                rest &= ~pick
        if rest.any():
            self._order = [np.unique(owners[rest & (par == b)]) for b in np.unique(par[rest])]
            groups += [np.flatnonzero(rest & (par == b)) for b in np.unique(par[rest])]
        cut = np.ones(len(cands), bool)
        pool = list(self._kept)
        have = np.concatenate([r["keys"] for r in pool] + [np.zeros(0, np.int64)])
        lack = ~np.isin(owners, have)
        if lack.any():  # keys refined at an earlier level or call: refined again
            pool += self._refined(np.unique(owners[lack]))
        for idx in groups:
            parts, finish = [], []
            for r in pool[::-1]:  # the latest refining of an owner
                i = idx[cut[idx] & np.isin(owners[idx], r["keys"])]
                if len(i):
                    cut[i] = False
                    piece, more = self._cut_children(r, cands[i], owners[i])
                    parts.append(piece)
                    finish.append((i, more))
            where = np.concatenate([f[0] for f in finish])
            order = np.argsort(where)  # the pieces back in the order of idx (increasing)
            parity = int(par[idx[0]]) ^ 1 if self.scheme == "sqrt3" else 0
            kids = self._keys_of(*_pieces_in_order(parts, order), parity)
            at = np.empty(len(cands), np.int64)
            at[where[order]] = np.arange(len(where))
            for i, more in finish:
                self._finish_cuts(kids[at[i]], *more)

    def _cut_children(self, r, cands, owners):
        """The child patches of ``cands`` cut from their owners' step ``r``: their pieces
        (:func:`_pieces_in_order`'s parts) and what :meth:`_finish_cuts` needs once they
        have keys."""
        node = np.searchsorted(r["keys"], owners) if _sorted(r["keys"]) else _position(r["keys"], owners)
        centre = r["cid"][node, self.slot.a[cands]]
        parent = r["shapes_of"].parent  # the refined faces by parent: a piece's are a range
        within = (np.searchsorted(parent, r["foff"][node]), np.searchsorted(parent, r["foff"][node + 1]))
        nxt, corner_n, shape_n, cur, vsel, fstart, _ = cut_children(r["p"], r["plan"], r["faces1"], r["child"],
                                                                    r["shapes_of"], centre, within)
        fperm, vperm, vstart, rec, norm, _, cv, reg = self._canonical(nxt, corner_n, shape_n, cur, fstart)
        T = r["S"][vsel[vperm]].tocoo()  # rows: the children's vertices in canonical order
        # Columns: the parent piece's vertices (canonical: the representative's own order).
        row_node = np.searchsorted(vstart, T.row, side="right") - 1
        col = T.col - r["voff"][node[row_node]]
        row = T.row - vstart[row_node]
        bounds = np.searchsorted(row_node, np.arange(len(centre) + 1))
        piece = (rec, norm, nxt.face_sharp[fperm], cv, np.diff(fstart), np.diff(vstart), reg)
        return piece, (cands, row.astype(np.int32), col.astype(np.int32), T.data, bounds)

    def _finish_cuts(self, kids, cands, row, col, val, bounds):
        """:meth:`_cut_children`'s candidates given their child keys ``kids``: their
        transitions stored."""
        self._add_transitions(cands, row, col, val, bounds)
        self.child.a[cands] = kids

    def _add_transitions(self, cands, row, col, val, bounds):
        """Store candidate ``cands[i]``'s transition, entries ``bounds[i]:bounds[i + 1]`` of
        ``row``, ``col``, ``val``, once per distinct content: keys of other connectivity often
        have the same step rows (the rows do not see a crease's far side, for one), so the
        table holds each once and the carry reads fewer distinct ones. Contents are told apart
        by a 128-bit hash of their entries (the weights by their bits), as keys are."""
        n = np.diff(bounds)
        start = np.empty(len(cands), np.int64)
        h = np.empty((len(cands), 2), np.uint64)  # 128 bits, as the keys'
        transition_hashes(row, col, np.ascontiguousarray(val, dtype=np.float64).view(np.int64), bounds, h)
        own = []
        end = self.t_row.n  # where the next new one goes
        for i, key in enumerate(zip(h[:, 0].tolist(), h[:, 1].tolist())):
            at = self._t_index.get(key)
            if at is None:
                at = self._t_index[key] = end
                own.append(i)
                end += int(n[i])
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


def _shapes(stored: np.ndarray) -> np.ndarray:
    """Normalised face shapes (m, 3, 2) from their three stored numbers (m, 3)."""
    out = np.zeros((len(stored), 3, 2))
    out[:, 1, 0], out[:, 2, 0], out[:, 2, 1] = stored[:, 0], stored[:, 1], stored[:, 2]
    return out


def _firsts(lengths: np.ndarray) -> np.ndarray:
    """Where each of consecutive runs of ``lengths`` starts: their exclusive prefix sums."""
    out = np.zeros(len(lengths), np.int64)
    np.cumsum(lengths[:-1], out=out[1:])
    return out


def _ranges(starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """``concatenate([arange(s, s + n) for s, n in zip(starts, lengths)])``."""
    return np.repeat(starts - _firsts(lengths), lengths) + np.arange(int(lengths.sum()))


def _pieces_in_order(parts: list, order: np.ndarray) -> tuple:
    """Pieces given in parts, each ``(rec, norm, fs, cv, nf, nv, reg)`` (face records, shapes
    and sharp flags of its faces, corner tags of its vertices, per piece its faces, vertices
    and regular flag), concatenated and then taken in ``order``: the arguments of
    :meth:`PatchTable._keys_of` before ``parity``."""
    if len(parts) == 1 and _sorted(order):  # one part, in order already
        rec, norm, fs, cv, nf, nv, reg = parts[0]
        return rec, np.concatenate([[0], np.cumsum(nf)]), cv, np.concatenate([[0], np.cumsum(nv)]), norm, fs, reg
    rec, norm, fs, cv, nf, nv, reg = (np.concatenate(x) for x in zip(*parts))
    fsel = _ranges(_firsts(nf)[order], nf[order])
    vsel = _ranges(_firsts(nv)[order], nv[order])
    nf, nv = nf[order], nv[order]
    return (rec[fsel], np.concatenate([[0], np.cumsum(nf)]), cv[vsel], np.concatenate([[0], np.cumsum(nv)]),
            norm[fsel], fs[fsel], reg[order])


def _sorted(a: np.ndarray) -> bool:
    return bool(np.all(a[1:] >= a[:-1]))


def _position(keys: np.ndarray, x: np.ndarray) -> np.ndarray:
    order = np.argsort(keys)
    return order[np.searchsorted(keys[order], x)]
