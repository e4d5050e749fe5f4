"""Smoothness analysis of the schemes: local subdivision matrices, spectra, characteristic maps.

The paper's appendix argues smoothness from the spectrum of the local subdivision matrix
around a vertex of valence n (eq. 7 for √3 applied twice, eq. 10 for Loop, conditions 8 and
9) and from "sketching the iso-parameter lines" of the characteristic map. This module
computes all of it **from the project's own refinement**: a model neighbourhood is refined
with :func:`hybridsub.refine` and the matrix is read off the step matrix, so what is analysed
is exactly what ``subdivide`` does. ``docs/analysis.md`` shows and discusses the results.

>>> from hybridsub import analysis
>>> M = analysis.subdivision_matrix(5, "loop")
>>> ev = analysis.eigenvalues(M)
>>> bool(abs(ev[1] - (3 + 2 * np.cos(2 * np.pi / 5)) / 8) < 1e-12)    # eq. (10)
True
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse.csgraph as csgraph

from ._rules import step_rules as R
from ._refiner import refine

__all__ = [
    "model_neighbourhood", "subdivision_matrix", "eigenvalues", "closed_form_spectrum", "Smoothness",
    "check_smoothness", "characteristic_map",
]

SCHEMES = ("sqrt3", "loop")


def _check_n(n, crease):
    if isinstance(n, bool) or int(n) != n:
        raise TypeError(f"n must be an integer, got {n!r}")
    n = int(n)
    lo = 1 if crease else 3
    if n < lo:
        what = "a crease sector needs at least 1 face" if crease else "an interior vertex has valence >= 3"
        raise ValueError(f"{what}, got n={n}")
    return n


def _check_scheme(scheme):
    if scheme not in SCHEMES:
        raise ValueError(f"scheme must be one of {SCHEMES} (the hybrid scheme is √3 on smooth faces and Loop "
                         f"on sharp ones; analyse each), got {scheme!r}")


def model_neighbourhood(n, rings, *, crease=False):
    """A model neighbourhood of a vertex: valence ``n``, ``rings`` rings of regular vertices.

    The centre is vertex 0; ring ``r`` (1 … ``rings``) holds ``n r`` vertices (``n r + 1`` for
    a crease), in counter-clockwise order from the spoke at angle 0. Every vertex but the
    centre has valence 6 inside the model. With ``crease=True`` the model is a half-disc of
    ``n`` wedges (a crease or boundary vertex with a sector of ``n`` faces): its boundary
    is the crease.

    Returns
    -------
    V : (N, 3) float
        A planar embedding, symmetric under rotation by 2π/n (reflection for a crease).
    F : (M, 3) int64
        Faces, counter-clockwise seen from +z.
    ring : (N,) int64
        Ring of each vertex (0 for the centre).

    Examples
    --------
    >>> V, F, ring = model_neighbourhood(5, 2)
    >>> V.shape, F.shape, np.bincount(ring).tolist()
    ((16, 3), (20, 3), [1, 5, 10])
    """
    n = _check_n(n, crease)
    rings = int(rings)
    if rings < 1:
        raise ValueError(f"rings must be >= 1, got {rings}")
    span = np.pi if crease else 2.0 * np.pi
    e = np.stack([np.cos(span * np.arange(n + 1) / n), np.sin(span * np.arange(n + 1) / n)], axis=1)
    per_ring = [1] + [n * r + (1 if crease else 0) for r in range(1, rings + 1)]
    start = np.concatenate([[0], np.cumsum(per_ring)[:-1]])

    def vid(r, s, t):  # lattice point t (0..r) of wedge s on ring r
        if r == 0:
            return 0
        i = s * r + t
        if not crease:
            i %= n * r
        return start[r] + i

    V = np.zeros((sum(per_ring), 3))
    ring = np.zeros(sum(per_ring), np.int64)
    F = []
    for r in range(1, rings + 1):
        for s in range(n):
            for t in range(r + 1):
                p = r * e[s] + t * (e[s + 1] - e[s])
                V[vid(r, s, t), :2] = p
                ring[vid(r, s, t)] = r
            for t in range(r):
                F.append((vid(r - 1, s, t), vid(r, s, t), vid(r, s, t + 1)))
            for t in range(r - 1):
                F.append((vid(r - 1, s, t), vid(r, s, t + 1), vid(r - 1, s, t + 1)))
    return V, np.array(F, dtype=np.int64), ring


def _canonical_order(V, F, n_vertices, rings, crease):
    """Vertices within ``rings`` of vertex 0, ordered by ring, then by angle from 0."""
    import scipy.sparse as sp

    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    A = sp.csr_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n_vertices, n_vertices))
    d = csgraph.shortest_path(A, unweighted=True, directed=False, indices=0)
    sel = np.flatnonzero(d <= rings)
    ang = np.mod(np.arctan2(V[sel, 1], V[sel, 0]), 2.0 * np.pi)
    ang[np.abs(ang - 2.0 * np.pi) < 1e-9] = 0.0
    ang[ang < 1e-9] = 0.0
    if crease:  # the spoke at angle π is the other end
        ang[np.abs(ang - np.pi) < 1e-9] = np.pi
    order = np.lexsort((ang, d[sel]))
    return sel[order], d[sel][order].astype(np.int64)


def subdivision_matrix(n, scheme="loop", *, steps=1, rings=1, crease=False, loop_weights="loop"):
    """Local subdivision matrix around a vertex of valence ``n``, from the project's rules.

    Parameters
    ----------
    n : int
        Valence of the centre (``crease=True``: number of faces of its sector).
    scheme : {"loop", "sqrt3"}
        Loop (with Hoppe's crease rule), or Kobbelt's √3 (with his boundary rule for a crease).
    steps : int
        Number of steps in one matrix. One √3 step rotates the ring by π/n (the matrix maps
        the ring onto the rotated ring, its spectrum is complex); two steps are aligned again
        (the paper's Fig. 8). Kobbelt's boundary is only stationary over two steps.
    rings : int
        Size of the neighbourhood: the centre and its ``rings`` rings, ``1 + n r (r+1)/2``
        vertices (``1 + …`` one more per ring for a crease).
    crease : bool
        Analyse a crease (or boundary) vertex with one sector of ``n`` faces: Hoppe's crease
        rule for Loop, Kobbelt's boundary rule for √3.
    loop_weights : {"loop", "warren"}
        Loop's vertex weights.

    Returns
    -------
    (N, N) ndarray
        ``p_{k+steps} = M p_k`` on the neighbourhood, in the order of
        :func:`model_neighbourhood` (centre, then each ring counter-clockwise from angle 0).

    Examples
    --------
    >>> M = subdivision_matrix(6, "sqrt3", steps=2)
    >>> M.shape, bool(np.allclose(M.sum(axis=1), 1))
    ((7, 7), True)
    """
    n = _check_n(n, crease)
    _check_scheme(scheme)
    steps = int(steps)
    if steps < 1:
        raise ValueError(f"steps must be >= 1, got {steps}")
    if scheme == "sqrt3" and crease and steps % 2:
        raise ValueError("Kobbelt's boundary rule alternates (odd steps keep the boundary, even steps "
                         "trisect it): its local matrix is stationary over two steps; use steps=2")
    rings = int(rings)
    if rings < 1:
        raise ValueError(f"rings must be >= 1, got {rings}")
    V, F, ring = model_neighbourhood(n, rings + 2 * steps + 1, crease=crease)
    r = refine(F, None, steps, n_vertices=len(V), scheme=scheme, loop_weights=loop_weights)
    V2 = r.apply(V)
    cols, _ = _canonical_order(V, F, len(V), rings, crease)
    rows, _ = _canonical_order(V2, r.faces, len(V2), rings, crease)
    if len(rows) != len(cols):
        raise RuntimeError(f"the {rings}-ring has {len(cols)} vertices before and {len(rows)} after "
                           f"{steps} step(s): not a stationary neighbourhood")
    S = r.matrix.tocsr()[rows]
    M = S[:, cols].toarray()
    leak = np.abs(S).sum(axis=1).A1 - np.abs(M).sum(axis=1)
    if leak.max() > 1e-12:
        raise RuntimeError(f"the {rings}-ring is not invariant under {steps} step(s) of {scheme}")
    return M


def eigenvalues(M):
    """Eigenvalues of a local subdivision matrix, by decreasing modulus (real if all are).

    Examples
    --------
    >>> eigenvalues(subdivision_matrix(4, "loop"))[:3].round(4).tolist()
    [1.0, 0.375, 0.375]
    """
    ev = np.linalg.eigvals(np.asarray(M, dtype=np.float64))
    ev = ev[np.lexsort((-ev.real, -np.abs(ev)))]
    if np.abs(ev.imag).max(initial=0.0) < 1e-12:
        return ev.real
    return ev


def closed_form_spectrum(n, scheme="sqrt3", *, loop_weights="loop", steps=None, crease=False):
    """The 1-ring spectrum in closed form, by decreasing modulus.

    - ``"sqrt3"``, two steps (default): the paper's eq. (7),
      ``1/9 [9, (2 − 3α_n)², 2 + 2cos(2πk/n), k = 1 … n−1]``; one step: ``1``, ``2/3 − α_n``
      and ``(1 + e^{2πik/n}) / 3`` (complex).
    - ``"loop"``: ``1``, ``5/8 − n β_n`` and ``(3 + 2cos(2πk/n)) / 8`` (eq. 10 gives the
      sub-dominant pair, k = 1, n − 1).
    - ``crease=True`` (a sector of ``n`` faces): the curve's ``1, 1/2, 1/4`` (Loop; per two
      √3 steps ``1, 1/3, 1/9``) and the sector's ``3/8 + 1/4 cos(πj/n)`` (two √3 steps:
      ``(2 + 2cos(πj/n)) / 9``), j = 1 … n − 1.

    Examples
    --------
    >>> closed_form_spectrum(6, "sqrt3").round(4)[:4].tolist()
    [1.0, 0.3333, 0.3333, 0.1111]
    """
    n = _check_n(n, crease)
    _check_scheme(scheme)
    if steps is None:
        steps = 2 if scheme == "sqrt3" else 1
    if crease:
        if scheme == "loop":
            ev = np.r_[1.0, 0.5, 0.25, 3.0 / 8.0 + 0.25 * np.cos(np.pi * np.arange(1, n) / n)] ** steps
        else:
            if steps % 2:
                raise ValueError("Kobbelt's boundary is stationary over two steps; use an even number")
            ev = np.r_[1.0, 1.0 / 3.0, 1.0 / 9.0, (2.0 + 2.0 * np.cos(np.pi * np.arange(1, n) / n)) / 9.0]
            ev = ev ** (steps // 2)
    elif scheme == "loop":
        b = float(R.loop_beta(n, loop_weights))
        ev = np.r_[1.0, 5.0 / 8.0 - n * b, (3.0 + 2.0 * np.cos(2.0 * np.pi * np.arange(1, n) / n)) / 8.0] ** steps
    else:
        a = float(R.kobbelt_alpha(n))
        k = np.arange(1, n)
        if steps % 2 == 0:
            ev = np.r_[9.0, (2.0 - 3.0 * a) ** 2, 2.0 + 2.0 * np.cos(2.0 * np.pi * k / n)] / 9.0
            ev = ev ** (steps // 2)
        else:
            # An odd number of steps: one rotating step after (steps − 1)/2 aligned pairs, which
            # share the Fourier eigenvectors.
            one = np.r_[1.0, 2.0 / 3.0 - a, (1.0 + np.exp(2j * np.pi * k / n)) / 3.0]
            two = np.r_[1.0, (2.0 / 3.0 - a) ** 2, (2.0 + 2.0 * np.cos(2.0 * np.pi * k / n)) / 9.0]
            ev = one * two ** ((steps - 1) // 2)
    ev = np.asarray(ev)
    ev = ev[np.lexsort((-ev.real, -np.abs(ev)))]
    return ev


class Smoothness(NamedTuple):
    """Result of :func:`check_smoothness`.

    Attributes
    ----------
    eigenvalues : ndarray
        Spectrum of the local matrix, by decreasing modulus.
    subdominant : tuple of float
        λ₂, λ₃ (moduli).
    next : float
        ``|λ₄|``, the largest modulus below the sub-dominant pair.
    condition8 : bool
        The paper's (8): λ₁ = 1 > λ₂ = λ₃ > ``|λᵢ|``, i ≥ 4.
    condition9 : bool
        The paper's (9): λ₁ = 1 > λ₂ ≥ λ₃ > ``|λ₄|`` (λ₂ and λ₃ real).
    crease_tangent : bool or None
        Crease sectors only: the crease curve's tangent eigenvalue (1/2 for Loop, 1/3 per
        two √3 steps) is one of λ₂, λ₃ and above ``|λ₄|``. Without it the two sub-dominant
        eigenvectors both vanish on the crease, the characteristic map is not injective and
        the sector has no tangent plane at the vertex, whatever (9) says.
    """

    eigenvalues: np.ndarray
    subdominant: tuple
    next: float
    condition8: bool
    condition9: bool
    crease_tangent: bool | None


def check_smoothness(n, scheme="sqrt3", *, steps=None, rings=1, crease=False, loop_weights="loop", tol=1e-10):
    """Spectral conditions (8) and (9) of the paper for valence ``n``, from the project's rules.

    Parameters
    ----------
    n, scheme, rings, crease, loop_weights
        As for :func:`subdivision_matrix`.
    steps : int, optional
        Default 2 for ``"sqrt3"`` (aligned), 1 for ``"loop"``.
    tol : float
        Tolerance of the comparisons.

    Examples
    --------
    >>> r = check_smoothness(7, "sqrt3")
    >>> r.condition8, r.condition9
    (True, True)
    >>> c = check_smoothness(8, "loop", crease=True)     # Hoppe's crease rule, 8 faces
    >>> c.condition9, c.crease_tangent
    (True, False)
    """
    if steps is None:
        steps = 2 if scheme == "sqrt3" else 1
    M = subdivision_matrix(n, scheme, steps=steps, rings=rings, crease=crease, loop_weights=loop_weights)
    ev = eigenvalues(M)
    mod = np.abs(ev)
    l1, l2, l3 = mod[0], mod[1], mod[2]
    l4 = mod[3] if len(mod) > 3 else 0.0
    real23 = abs(np.imag(ev[1])) < tol and abs(np.imag(ev[2])) < tol and np.real(ev[1]) > 0 and np.real(ev[2]) > 0
    c8 = abs(l1 - 1.0) < tol and l2 < 1.0 - tol and abs(l2 - l3) < tol and l3 > l4 + tol
    c9 = abs(l1 - 1.0) < tol and l2 < 1.0 - tol and bool(real23) and l3 > l4 + tol
    ct = None
    if crease:
        t = 0.5 ** steps if scheme == "loop" else (1.0 / 3.0) ** (steps // 2)
        ct = bool((abs(l2 - t) < tol or abs(l3 - t) < tol) and l3 > l4 + tol)
    return Smoothness(ev, (float(l2), float(l3)), float(l4), bool(c8), bool(c9), ct)


def characteristic_map(n, scheme="loop", *, levels=4, crease=False, loop_weights="loop"):
    """The characteristic map around a vertex of valence ``n``, sampled on a refined mesh.

    The control net is the sub-dominant eigenvector pair of the local subdivision matrix
    (4 rings; Loop's ``(3 + 2cos(2π/n))/8``, √3's ``(2 + 2cos(2π/n))/9`` per two steps; for a
    crease, the two largest eigenvalues below 1), put in the plane as (x, y). It is refined
    ``levels`` times with the project's rules and pushed to the limit with
    :func:`hybridsub.limit_positions`; only the faces that descend from the faces around the
    centre are returned (the rest feel the model's artificial rim). Drawing their edges
    "sketches the iso-parameter lines" (the paper, after Kobbelt): a regular, injective map
    is the sufficient condition for C¹ of Reif.

    Returns
    -------
    P : (N, 2) float
        Points of the characteristic map (limit positions of the refined net).
    F : (M, 3) int64
        Faces over the patches around the centre (indices into ``P``).
    eigenvalues : (2,) float
        The two eigenvalues used (x from the first, y from the second).

    Examples
    --------
    >>> P, F, lam = characteristic_map(5, "loop", levels=2)
    >>> P.shape[1], F.shape[1], bool(np.isclose(lam[0], (3 + 2 * np.cos(2 * np.pi / 5)) / 8))
    (2, 3, True)
    """
    from ._surface import limit_positions

    n = _check_n(n, crease)
    _check_scheme(scheme)
    levels = int(levels)
    if levels < 0:
        raise ValueError(f"levels must be >= 0, got {levels}")
    rings = 4
    steps = 2 if scheme == "sqrt3" else 1
    M = subdivision_matrix(n, scheme, steps=steps, rings=rings, crease=crease, loop_weights=loop_weights)
    V, F, ring = model_neighbourhood(n, rings, crease=crease)
    order, _ = _canonical_order(V, F, len(V), rings, crease)
    w, Rv = np.linalg.eig(M)
    if crease:
        # The two largest eigenvalues below 1, each with its own (real) eigenvector.
        idx = [i for i in np.lexsort((-w.real, -np.abs(w))) if abs(w[i] - 1.0) > 1e-9][:2]
        lam = w[idx].real
        X = Rv[:, idx].real
        # x: the eigenvector more like the embedding's x (odd under the mirror: along the
        # crease), y: the other; signs and scales normalized (the map is defined up to a
        # linear map, which keeps regularity and injectivity).
        Vo = V[order]
        if abs(X[:, 1] @ Vo[:, 0]) * np.linalg.norm(X[:, 0]) > abs(X[:, 0] @ Vo[:, 0]) * np.linalg.norm(X[:, 1]):
            X, lam = X[:, ::-1].copy(), lam[::-1].copy()
        for c in range(2):
            if X[:, c] @ Vo[:, c] < 0:
                X[:, c] *= -1.0
            X[:, c] /= np.abs(X[:, c]).max()
    else:
        # Project the symmetric embedding's x and y on the sub-dominant eigenspace.
        target = ((3.0 + 2.0 * np.cos(2.0 * np.pi / n)) / 8.0 if scheme == "loop"
                  else (2.0 + 2.0 * np.cos(2.0 * np.pi / n)) / 9.0)
        pick = np.flatnonzero(np.abs(w - target) < 1e-8)
        if len(pick) != 2:
            raise RuntimeError(f"expected a double eigenvalue {target}, found {len(pick)}")
        Rs = Rv[:, pick]
        Lfull = np.linalg.inv(Rv)
        Ls = Lfull[pick]
        X = (Rs @ (Ls @ V[order][:, :2])).real
        lam = np.full(2, target)
    P0 = np.zeros((len(V), 3))
    P0[order, :2] = X
    sub = ring <= rings
    Fm = F[sub[F].all(axis=1)]
    r = refine(Fm, None, levels, n_vertices=len(V), scheme=scheme, loop_weights=loop_weights)
    Pl = limit_positions(r.apply(P0), r.faces, scheme=scheme, loop_weights=loop_weights)
    keep = (Fm[r.face_parent] == 0).any(axis=1)
    Fk = r.faces[keep]
    used = np.unique(Fk)
    new = np.full(len(Pl), -1, np.int64)
    new[used] = np.arange(len(used))
    return Pl[used, :2], new[Fk], lam
