"""Ray casting of ellipsoids into a z-buffer, the one drawing primitive of the synthetic person.

Every solid of the synthetic body is a union of ellipsoids: a single ellipsoid for a head or a
hand, a dense row of them for a limb (a sphere-swept, tapered capsule) or the torso (a stack of
flat elliptic slabs, which together make a rounded, superquadric-like trunk). A pinhole camera
sits at the origin looking along +Z (OpenCV's camera frame, metres); each primitive is cast only
against the pixels of its own projected bounding box.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Ellipsoid:
    """One ellipsoid in the camera frame.

    Attributes:
        center: `(3,)` centre, metres.
        axes: `(3, 3)` rotation whose columns are the ellipsoid's own axes in the camera frame.
        radii: `(3,)` semi-axes along those columns, metres.
        group: index of the surface group (material and texture frame) it belongs to.
        axis: for an interior member of a swept row, the row's unit direction in the camera
            frame; the shading normal then follows the row's smooth envelope instead of the
            bumps between neighbouring members. None for a free solid.
        taper: how fast the row's radius shrinks along `axis` (- d radius / d length).
    """

    center: FloatArray
    axes: FloatArray
    radii: FloatArray
    group: int
    axis: FloatArray | None = None
    taper: float = 0.0


@dataclass(frozen=True)
class Trunk:
    """A smooth trunk: elliptic cross-sections whose half-axes vary along the trunk's own Y.

    In its own frame the surface is (x / w(y))^2 + (z / d(y))^2 = 1 for `y` within the profile,
    the ends capped flat. The profile is sampled finely and smoothed, so the surface and its
    shading have no creases.

    Attributes:
        origin: `(3,)` origin of the trunk frame, camera frame, metres.
        axes: `(3, 3)` trunk frame axes as columns (Y runs down the trunk).
        ys: `(K,)` ascending heights of the profile samples, metres.
        half_widths: `(K,)` w(y), metres.
        half_depths: `(K,)` d(y), metres.
        group: surface group.
    """

    origin: FloatArray
    axes: FloatArray
    ys: FloatArray
    half_widths: FloatArray
    half_depths: FloatArray
    group: int

    @classmethod
    def from_knots(
        cls, origin: FloatArray, axes: FloatArray, knots: list[tuple[float, float, float]], group: int
    ) -> Trunk:
        """A trunk through `(y, half-width, half-depth)` knots, smoothed over about 2 cm."""
        k = np.array(knots)
        ys = np.arange(k[0, 0], k[-1, 0] + 1e-9, 0.002)
        kernel = np.hanning(11)
        kernel /= kernel.sum()

        def smooth(v: FloatArray) -> FloatArray:
            padded = np.concatenate([np.full(5, v[0]), v, np.full(5, v[-1])])
            return np.convolve(padded, kernel, mode="valid")

        return cls(
            origin, axes, ys, smooth(np.interp(ys, k[:, 0], k[:, 1])), smooth(np.interp(ys, k[:, 0], k[:, 2])), group
        )

    def intersect(self, rays: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Ray parameters `(N,)` (inf on a miss) and unit normals `(N, 3)` for `(N, 3)` rays."""
        o = -(self.origin @ self.axes)
        d = rays @ self.axes
        t = -o[2] / d[:, 2]  # start where the ray crosses the trunk's mid-plane
        hit = np.ones(len(d), bool)
        for _ in range(4):  # fixed point: the ellipse at the height where the ray is
            y = o[1] + t * d[:, 1]
            w = np.interp(y, self.ys, self.half_widths)
            dd = np.interp(y, self.ys, self.half_depths)
            qa = (d[:, 0] / w) ** 2 + (d[:, 2] / dd) ** 2
            qb = (o[0] * d[:, 0]) / w**2 + (o[2] * d[:, 2]) / dd**2
            qc = (o[0] / w) ** 2 + (o[2] / dd) ** 2 - 1.0
            disc = qb * qb - qa * qc
            hit = disc > 0
            t = np.where(hit, (-qb - np.sqrt(np.maximum(disc, 0))) / qa, t)
        p = o + t[:, None] * d
        hit &= (p[:, 1] >= self.ys[0]) & (p[:, 1] <= self.ys[-1])
        w = np.interp(p[:, 1], self.ys, self.half_widths)
        dd = np.interp(p[:, 1], self.ys, self.half_depths)
        hit &= (p[:, 0] / w) ** 2 + (p[:, 2] / dd) ** 2 < 1.0 + 1e-3
        dw = np.interp(p[:, 1], self.ys, np.gradient(self.half_widths, self.ys))
        ddd = np.interp(p[:, 1], self.ys, np.gradient(self.half_depths, self.ys))
        grad = np.stack(
            [p[:, 0] / w**2, -(p[:, 0] ** 2) * dw / w**3 - (p[:, 2] ** 2) * ddd / dd**3, p[:, 2] / dd**2], axis=1
        )
        normal = grad @ self.axes.T
        normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
        return np.where(hit & (t > 0), t, np.inf), normal

    def half_extent(self) -> tuple[FloatArray, FloatArray]:
        """Centre and half-extents (camera axes) of a box around the trunk, metres."""
        corners = np.array(
            [
                [sx * self.half_widths.max(), y, sz * self.half_depths.max()]
                for sx in (-1, 1)
                for y in (self.ys[0], self.ys[-1])
                for sz in (-1, 1)
            ]
        )
        cam = corners @ self.axes.T + self.origin
        lo, hi = cam.min(axis=0), cam.max(axis=0)
        return (lo + hi) / 2, (hi - lo) / 2


@dataclass(frozen=True)
class Hits:
    """The nearest hit of every pixel the solids cover, as flat per-pixel arrays.

    Attributes:
        width: image width, pixels.
        height: image height, pixels.
        pixels: `(M,)` flat pixel indices (row * width + column), ascending.
        depth: `(M,)` Z of the hit, metres.
        normal: `(M, 3)` unit surface normal, camera frame.
        point: `(M, 3)` hit point, camera frame, metres.
        group: `(M,)` surface group of the hit.
    """

    width: int
    height: int
    pixels: npt.NDArray[np.int64]
    depth: FloatArray
    normal: FloatArray
    point: FloatArray
    group: npt.NDArray[np.int64]

    def mask(self, selection: npt.NDArray[np.bool_] | None = None) -> npt.NDArray[np.bool_]:
        """`(H, W)` mask of the hit pixels (or of a selection of them)."""
        out = np.zeros(self.height * self.width, bool)
        out[self.pixels if selection is None else self.pixels[selection]] = True
        return out.reshape(self.height, self.width)


def _boxes(
    centers: FloatArray, half: FloatArray, width: int, height: int, focal: float, cx: float, cy: float
) -> npt.NDArray[np.int64]:
    """`(P, 4)` pixel boxes `x0, y0, x1, y1` (exclusive ends, empty when x1 <= x0) of boxes in 3D."""
    near = np.maximum(centers[:, 2] - half[:, 2], 1e-3)
    far = centers[:, 2] + half[:, 2]
    lo, hi = centers[:, :2] - half[:, :2], centers[:, :2] + half[:, :2]
    cand = np.stack([lo / near[:, None], lo / far[:, None], hi / near[:, None], hi / far[:, None]])
    pmin, pmax = cand.min(axis=0) * focal, cand.max(axis=0) * focal
    x0 = np.clip(np.floor(pmin[:, 0] + cx) - 1, 0, width)
    x1 = np.clip(np.ceil(pmax[:, 0] + cx) + 2, 0, width)
    y0 = np.clip(np.floor(pmin[:, 1] + cy) - 1, 0, height)
    y1 = np.clip(np.ceil(pmax[:, 1] + cy) + 2, 0, height)
    boxes = np.stack([x0, y0, x1, y1], axis=1).astype(np.int64)
    boxes[centers[:, 2] - half[:, 2] <= 1e-3] = 0  # reaches behind the camera: not drawn
    return boxes


def cast(
    solids: list[Ellipsoid], width: int, height: int, focal: float, cx: float, cy: float, trunk: Trunk | None = None
) -> Hits:
    """Casts one ray per pixel centre against all solids and keeps the nearest hit.

    All solids are cast in one vectorised pass over (pixel, solid) pairs, each solid only over
    the pixels of its own projected bounding box.

    Args:
        solids: the ellipsoids.
        width: image width, pixels.
        height: image height, pixels.
        focal: focal length, pixels.
        cx: principal point x, pixels.
        cy: principal point y, pixels.
        trunk: a trunk solid cast as well.

    Returns:
        The hits.
    """
    empty = Hits(
        width, height, np.zeros(0, np.int64), np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, np.int64)
    )
    if not solids:
        return empty
    centers = np.array([e.center for e in solids])
    axes = np.array([e.axes for e in solids])
    radii = np.array([e.radii for e in solids])
    half = np.sqrt(((axes * radii[:, None, :]) ** 2).sum(axis=2))
    boxes = _boxes(centers, half, width, height, focal, cx, cy)
    bw = np.maximum(boxes[:, 2] - boxes[:, 0], 0)
    bh = np.maximum(boxes[:, 3] - boxes[:, 1], 0)
    sizes = bw * bh
    if sizes.sum() == 0:
        return empty
    # Every (pixel, solid) pair: `owner` is the solid, (xs, ys) the pixel.
    owner = np.repeat(np.arange(len(solids)), sizes)
    offset = np.arange(int(sizes.sum())) - np.repeat(np.cumsum(sizes) - sizes, sizes)
    ys = boxes[owner, 1] + offset // bw[owner]
    xs = boxes[owner, 0] + offset % bw[owner]
    rays = np.stack([(xs - cx) / focal, (ys - cy) / focal, np.ones(len(xs))], axis=1).astype(np.float32)
    # In each ellipsoid's unit-sphere coordinates the ray is t * a and the centre is b.
    to_unit = (axes / radii[:, None, :]).astype(np.float32)
    b = np.einsum("pj,pjk->pk", centers, axes) / radii
    a = np.einsum("nj,njk->nk", rays, to_unit[owner])
    qa = np.einsum("nk,nk->n", a, a)
    qb = np.einsum("nk,nk->n", a, b[owner].astype(np.float32))
    disc = qb * qb - qa * (np.einsum("pk,pk->p", b, b) - 1.0).astype(np.float32)[owner]
    hit = disc > 0
    t = (qb[hit] - np.sqrt(disc[hit])) / qa[hit]
    front = t > 0
    pix = (ys * width + xs)[hit][front]
    t, who, a = t[front], owner[hit][front], a[hit][front]
    if trunk is not None:  # its candidates carry the owner index len(solids)
        centre, extent = trunk.half_extent()
        tb = _boxes(centre[None], extent[None], width, height, focal, cx, cy)[0]
        tys, txs = np.mgrid[tb[1] : tb[3], tb[0] : tb[2]]
        tys, txs = tys.ravel(), txs.ravel()
        trays = np.stack([(txs - cx) / focal, (tys - cy) / focal, np.ones(len(txs))], axis=1)
        tt, tnormal = trunk.intersect(trays)
        on = np.isfinite(tt)
        trunk_pix, trunk_normal = (tys * width + txs)[on], tnormal[on]
        pix = np.concatenate([pix, trunk_pix])
        t = np.concatenate([t, tt[on].astype(np.float32)])
        who = np.concatenate([who, np.full(len(trunk_pix), len(solids))])
        a = np.concatenate([a, np.zeros((len(trunk_pix), 3), np.float32)])
    # Nearest hit per pixel: sort by pixel, then depth, and keep each pixel's first.
    order = np.lexsort((t, pix))
    first = np.ones(len(order), bool)
    first[1:] = pix[order][1:] != pix[order][:-1]
    keep = order[first]
    pix, t, who, a = pix[keep], t[keep].astype(np.float64), who[keep], a[keep].astype(np.float64)
    is_trunk = who == len(solids)
    if trunk is not None:
        trunk_rank = np.searchsorted(trunk_pix, pix[is_trunk])  # trunk_pix is ascending
        trunk_normal = trunk_normal[trunk_rank]
    who = np.where(is_trunk, 0, who)
    local = a * t[:, None] - b[who]
    grad = local / radii[who]
    # Members inside a swept row take the row's smooth envelope as their normal.
    swept = np.array([e.axis is not None for e in solids])[who] & ~is_trunk
    if swept.any():
        along_cam = np.array([e.axis if e.axis is not None else np.zeros(3) for e in solids])
        taper = np.array([e.taper for e in solids])
        along = np.einsum("nj,njk->nk", along_cam[who[swept]], axes[who[swept]])
        g = grad[swept]
        perp = g - (g * along).sum(axis=1, keepdims=True) * along
        grad[swept] = perp + np.linalg.norm(perp, axis=1, keepdims=True) * along * taper[who[swept]][:, None]
    normal = np.einsum("njk,nk->nj", axes[who], grad)
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-12)
    group = np.array([e.group for e in solids])[who]
    if trunk is not None:
        normal[is_trunk] = trunk_normal
        group[is_trunk] = trunk.group
    ray = np.stack([(pix % width - cx) / focal, (pix // width - cy) / focal, np.ones(len(pix))], axis=1)
    return Hits(width, height, pix, t, normal, ray * t[:, None], group)


def sweep(
    start: FloatArray,
    end: FloatArray,
    axes: FloatArray,
    radii_start: tuple[float, float],
    radii_end: tuple[float, float],
    group: int,
    spacing: float = 0.012,
    thickness: float | None = None,
    free_ends: tuple[bool, bool] = (True, True),
) -> list[Ellipsoid]:
    """A tapered capsule (or elliptic slab stack) from `start` to `end` as a row of ellipsoids.

    Args:
        start: `(3,)` first centre, metres.
        end: `(3,)` last centre, metres.
        axes: `(3, 3)` frame of the row: column 1 (Y) along the row, columns 0 and 2 across.
        radii_start: `(across X, across Z)` radii at `start`, metres.
        radii_end: the same at `end`.
        group: surface group of every member.
        spacing: largest distance between neighbouring centres, metres.
        thickness: radius of each member along the row; the larger cross radius when None
            (a capsule: round ends); smaller values give flat slabs with flat-ish ends.
        free_ends: whether the first and last members keep their own round normals (the ends
            of a solid) or follow the row's envelope (where another row continues it).

    Returns:
        The members, first to last.
    """
    length = float(np.linalg.norm(end - start))
    n = max(int(np.ceil(length / spacing)) + 1, 2)
    direction = (end - start) / max(length, 1e-12)
    slope_x = (radii_end[0] - radii_start[0]) / max(length, 1e-12)
    out = []
    for i in range(n):
        f = i / (n - 1)
        rx = radii_start[0] + f * (radii_end[0] - radii_start[0])
        rz = radii_start[1] + f * (radii_end[1] - radii_start[1])
        ry = thickness if thickness is not None else max(rx, rz)
        free = (i == 0 and free_ends[0]) or (i == n - 1 and free_ends[1])
        axis = None if free else direction
        out.append(Ellipsoid(start + f * (end - start), axes, np.array([rx, ry, rz]), group, axis, -slope_x))
    return out
