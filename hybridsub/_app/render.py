"""A small off-screen renderer: flat-shaded triangles and lines, z-buffered, in NumPy/Numba.

matplotlib's mplot3d could draw the panels (it does fandisk's level-2 hybrid, 124k faces, in
about 0.9 s at 400 × 456 pixels here), but it orders whole polygons by mean depth (the
painter's algorithm) and cannot hide a line behind a surface: the input panel's red sharp
edges would all show through the model. This rasteriser resolves visibility per pixel,
for faces and lines alike, and takes about 0.2 s for the same panel (``docs/usage.md``). It
needs no display and no OpenGL: triangles are filled over their bounding boxes with edge
functions and a depth buffer, at twice the final resolution, then averaged down
(anti-aliasing). Orthographic projection; shading by face normal with two lights.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Supersampling factor per axis.
SUPERSAMPLE = 2


def view_rotation(azimuth: float, elevation: float) -> np.ndarray:
    """Rotation taking world coordinates to camera coordinates (camera looks along −z, +y up).

    ``azimuth`` turns the model about the world's +y axis, ``elevation`` tilts the camera up
    (degrees), as a turntable: ``(0, 0)`` looks at the model's +z side.
    """
    a, e = np.radians(azimuth), np.radians(elevation)
    Ry = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
    Rx = np.array([[1, 0, 0], [0, np.cos(e), -np.sin(e)], [0, np.sin(e), np.cos(e)]])
    return Rx @ Ry


@njit(cache=True)
def _fill(P, F, W, H, depth, fid):  # pragma: no cover - compiled
    for f in range(F.shape[0]):
        a, b, c = F[f, 0], F[f, 1], F[f, 2]
        x0, y0, z0 = P[a, 0], P[a, 1], P[a, 2]
        x1, y1, z1 = P[b, 0], P[b, 1], P[b, 2]
        x2, y2, z2 = P[c, 0], P[c, 1], P[c, 2]
        area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if area == 0.0:
            continue
        xmin = max(int(np.floor(min(x0, min(x1, x2)))), 0)
        xmax = min(int(np.ceil(max(x0, max(x1, x2)))), W - 1)
        ymin = max(int(np.floor(min(y0, min(y1, y2)))), 0)
        ymax = min(int(np.ceil(max(y0, max(y1, y2)))), H - 1)
        inv = 1.0 / area
        for y in range(ymin, ymax + 1):
            py = y + 0.5
            for x in range(xmin, xmax + 1):
                px = x + 0.5
                w0 = ((x1 - px) * (y2 - py) - (x2 - px) * (y1 - py)) * inv
                w1 = ((x2 - px) * (y0 - py) - (x0 - px) * (y2 - py)) * inv
                w2 = 1.0 - w0 - w1
                if w0 < -1e-9 or w1 < -1e-9 or w2 < -1e-9:
                    continue
                z = w0 * z0 + w1 * z1 + w2 * z2
                if z > depth[y, x]:
                    depth[y, x] = z
                    fid[y, x] = f


@njit(cache=True)
def _lines(P, E, W, H, depth, radius, bias, mask):  # pragma: no cover - compiled
    for e in range(E.shape[0]):
        a, b = E[e, 0], E[e, 1]
        x0, y0, z0 = P[a, 0], P[a, 1], P[a, 2]
        x1, y1, z1 = P[b, 0], P[b, 1], P[b, 2]
        steps = int(max(abs(x1 - x0), abs(y1 - y0)) * 2.0) + 1
        r = int(np.ceil(radius))
        for i in range(steps + 1):
            t = i / steps
            x = x0 + t * (x1 - x0)
            y = y0 + t * (y1 - y0)
            z = z0 + t * (z1 - z0)
            for dy in range(-r, r + 1):
                for dx in range(-r, r + 1):
                    if dx * dx + dy * dy > radius * radius:
                        continue
                    px = int(x) + dx
                    py = int(y) + dy
                    if px < 0 or py < 0 or px >= W or py >= H:
                        continue
                    if z + bias >= depth[py, px]:
                        mask[py, px] = 1.0


def fit(V: np.ndarray, R: np.ndarray, width: int, height: int, margin: float = 0.06):
    """Scale and offset that fit ``V`` seen through ``R`` into a width × height image."""
    Q = V @ R.T
    lo, hi = Q[:, :2].min(axis=0), Q[:, :2].max(axis=0)
    span = np.maximum(hi - lo, 1e-12)
    scale = min(width * (1 - 2 * margin) / span[0], height * (1 - 2 * margin) / span[1])
    center = (lo + hi) / 2
    zspan = float(Q[:, 2].max() - Q[:, 2].min()) or 1.0
    return scale, center, zspan


def render(V, F, R, width: int, height: int, *, frame=None, lines=None, color=(0.78, 0.80, 0.84),
           line_color=(0.85, 0.05, 0.05), line_width: float = 1.6, background=(1.0, 1.0, 1.0),
           outline: bool = True, texture=None) -> np.ndarray:
    """Render a triangle mesh into an (height, width, 3) uint8 RGB image.

    Parameters
    ----------
    V, F : (n, 3) float, (m, 3) int
    R : (3, 3) rotation (``view_rotation``)
    frame : (scale, center, zspan), optional
        From ``fit`` on a reference mesh, so that several renders share one view. Default:
        fit ``V`` itself.
    lines : (k, 2) int, or list of ((k, 2) int, rgb), optional
        Vertex pairs drawn on top in ``line_color`` (or each set in its colour), hidden parts
        hidden, ``line_width`` pixels wide.
    outline : bool
        Darken depth discontinuities (silhouettes), which makes shapes easier to read.
    texture : (UV, FUV, image), optional
        Colour each pixel by ``image(uv)`` (a function of (k, 2) UVs returning (k, 3) RGB in
        [0, 1]) at the UV interpolated over its face, ``UV (t, 2)`` indexed per face corner
        by ``FUV (m, 3)`` (face-varying), instead of ``color``.
    """
    s = SUPERSAMPLE
    W, H = width * s, height * s
    V = np.asarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    scale, center, zspan = frame if frame is not None else fit(V, R, width, height)
    Q = V @ R.T
    P = np.empty_like(Q)
    P[:, 0] = (Q[:, 0] - center[0]) * scale * s + W / 2
    P[:, 1] = H / 2 - (Q[:, 1] - center[1]) * scale * s
    P[:, 2] = Q[:, 2]
    depth = np.full((H, W), -np.inf)
    fid = np.full((H, W), -1, np.int64)
    _fill(np.ascontiguousarray(P), F, W, H, depth, fid)

    T = Q[F]
    N = np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0])
    N /= np.maximum(np.linalg.norm(N, axis=1, keepdims=True), 1e-300)
    front = N[:, 2] >= 0
    N[~front] *= -1  # two-sided: back faces (inside of an open mesh) are lit like front ones
    key = np.array([-0.45, 0.6, 0.66])
    key /= np.linalg.norm(key)
    fill_l = np.array([0.6, -0.2, 0.77])
    fill_l /= np.linalg.norm(fill_l)
    half = key + np.array([0, 0, 1.0])
    half /= np.linalg.norm(half)
    diffuse = 0.62 * np.clip(N @ key, 0, None) + 0.25 * np.clip(N @ fill_l, 0, None)
    spec = 0.18 * np.clip(N @ half, 0, None) ** 40
    base = np.where(front[:, None], np.asarray(color), np.asarray(color) * np.array([0.85, 0.75, 0.7]))
    face_rgb = np.clip(base * (0.22 + diffuse)[:, None] + spec[:, None], 0, 1)

    hit = fid >= 0
    img = np.empty((H, W, 3))
    img[:] = background
    if texture is None:
        img[hit] = face_rgb[fid[hit]]
    else:
        UV, FUV, image = texture
        ys, xs = np.nonzero(hit)
        f = fid[ys, xs]
        rgb = image(_pixel_uv(P, F, f, xs + 0.5, ys + 0.5, np.asarray(UV, dtype=np.float64), np.asarray(FUV)))
        tint = np.where(front[:, None], 1.0, np.array([0.85, 0.75, 0.7]))
        img[ys, xs] = np.clip(rgb * tint[f] * (0.22 + diffuse[f])[:, None] + spec[f][:, None], 0, 1)
    if outline:
        d = np.where(hit, depth, np.nanmin(np.where(hit, depth, np.inf)) - zspan if hit.any() else 0)
        jump = 0.02 * zspan
        edge = np.zeros((H, W), bool)
        edge[:, 1:] |= np.abs(d[:, 1:] - d[:, :-1]) > jump
        edge[1:, :] |= np.abs(d[1:, :] - d[:-1, :]) > jump
        edge[:, :-1] |= edge[:, 1:].copy()
        img[edge] *= 0.35
    if lines is not None and not isinstance(lines, list):
        lines = [(lines, line_color)]
    for E, rgb in lines or []:
        if E is None or not len(E):
            continue
        mask = np.zeros((H, W))
        E = np.ascontiguousarray(E, dtype=np.int64).reshape(-1, 2)
        _lines(np.ascontiguousarray(P), E, W, H, depth, line_width * s / 2, 0.004 * zspan, mask)
        img = img * (1 - mask[..., None]) + np.asarray(rgb) * mask[..., None]
    img = img.reshape(height, s, width, s, 3).mean(axis=(1, 3))
    return np.clip(np.round(img * 255), 0, 255).astype(np.uint8)


def _pixel_uv(P, F, f, px, py, UV, FUV) -> np.ndarray:
    """UV at screen points (px, py) inside faces f: barycentric interpolation (the projection
    is orthographic, so screen barycentrics are the surface's)."""
    a, b, c = (P[F[f, k]] for k in range(3))
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    w0 = ((b[:, 0] - px) * (c[:, 1] - py) - (c[:, 0] - px) * (b[:, 1] - py)) / area
    w1 = ((c[:, 0] - px) * (a[:, 1] - py) - (a[:, 0] - px) * (c[:, 1] - py)) / area
    w2 = 1.0 - w0 - w1
    T = UV[FUV[f]]
    return w0[:, None] * T[:, 0] + w1[:, None] * T[:, 1] + w2[:, None] * T[:, 2]


def choose_view(V, F, lines=None, candidates=None) -> tuple[float, float]:
    """A turntable view that shows the model and its features: among 16 azimuths × 4
    elevations (±20°, ±35°), the one that shows the most sharp-edge pixels (when ``lines`` are
    given) plus a quarter of the covered pixels, all at one scale, rendered at 96 × 96 pixels.
    Deterministic; about a second for fandisk."""
    if candidates is None:
        candidates = [(az, el) for el in (35.0, -35.0, 20.0, -20.0) for az in np.arange(0.0, 360.0, 22.5)]
    V = np.asarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int64)
    c = (V.min(axis=0) + V.max(axis=0)) / 2
    radius = float(np.linalg.norm(V - c, axis=1).max()) or 1.0
    size = 96
    E = None if lines is None or not len(lines) else np.ascontiguousarray(lines, dtype=np.int64).reshape(-1, 2)
    best, best_score = candidates[0], -1.0
    for az, el in candidates:
        Q = (V - c) @ view_rotation(az, el).T
        P = np.empty_like(Q)
        P[:, 0] = Q[:, 0] / radius * (size / 2) + size / 2
        P[:, 1] = size / 2 - Q[:, 1] / radius * (size / 2)
        P[:, 2] = Q[:, 2]
        P = np.ascontiguousarray(P)
        depth = np.full((size, size), -np.inf)
        fid = np.full((size, size), -1, np.int64)
        _fill(P, F, size, size, depth, fid)
        score = 0.25 * float((fid >= 0).sum())
        if E is not None:
            mask = np.zeros((size, size))
            _lines(P, E, size, size, depth, 0.5, 0.01 * radius, mask)
            score += float(mask.sum())
        if score > best_score + 1e-9:
            best, best_score = (float(az), float(el)), score
    return best
