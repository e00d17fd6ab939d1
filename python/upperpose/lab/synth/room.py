"""Procedural rooms: the cluttered backgrounds behind the synthetic person.

A room is a wall, a floor and furniture drawn with OpenCV at twice the resolution and shrunk
(for smooth edges): a door, a bookshelf full of books, a sofa, pictures, a plant, a lamp, a
clock, and a few skin-coloured things (a cardboard box, a wooden table top, a beige canvas)
that a skin detector must learn to ignore. The layout and colours follow the seed.
"""

from __future__ import annotations

import cv2
import numpy as np
import numpy.typing as npt

FloatImage = npt.NDArray[np.float32]

WALL_COLOURS = [(190, 205, 215), (200, 200, 196), (170, 190, 200), (185, 200, 180), (210, 215, 225), (160, 175, 190)]
WOOD_COLOURS = [(40, 70, 110), (60, 100, 150), (30, 45, 70), (90, 130, 170)]
SKIN_OBJECTS = [(110, 150, 200), (90, 130, 185), (140, 170, 215)]  # tan, BGR


def _c(rng: np.random.Generator, palette: list[tuple[int, int, int]], jitter: float = 12.0) -> tuple[float, ...]:
    base = np.array(palette[int(rng.integers(len(palette)))], float)
    return tuple(np.clip(base + rng.normal(0, jitter, 3), 0, 255).tolist())


def _rect(
    img: npt.NDArray[np.uint8], x0: float, y0: float, x1: float, y1: float, colour: tuple[float, ...], thick: int = -1
) -> None:
    cv2.rectangle(img, (int(x0), int(y0)), (int(x1), int(y1)), colour, thick, cv2.LINE_AA)


def _door(img: npt.NDArray[np.uint8], x: float, top: float, floor: float, w: float, rng: np.random.Generator) -> None:
    wood = _c(rng, WOOD_COLOURS + [(200, 200, 200), (230, 230, 230)], 8)
    frame = tuple(v * 0.8 for v in wood)
    _rect(img, x - w * 0.08, top - w * 0.08, x + w * 1.08, floor, frame)
    _rect(img, x, top, x + w, floor, wood)
    for row in range(2):
        py0 = top + (floor - top) * (0.06 + 0.5 * row)
        py1 = py0 + (floor - top) * 0.4
        _rect(img, x + w * 0.15, py0, x + w * 0.85, py1, tuple(v * 0.88 for v in wood), max(int(w * 0.02), 2))
    knob = (int(x + w * 0.86), int(top + (floor - top) * 0.52))
    cv2.circle(img, knob, max(int(w * 0.04), 3), (60, 150, 190), -1, cv2.LINE_AA)


def _shelf(img: npt.NDArray[np.uint8], x: float, top: float, floor: float, w: float, rng: np.random.Generator) -> None:
    wood = _c(rng, WOOD_COLOURS, 8)
    _rect(img, x, top, x + w, floor, tuple(v * 0.6 for v in wood))
    board = max((floor - top) * 0.025, 4)
    levels = int(rng.integers(3, 6))
    step = (floor - top) / levels
    for k in range(levels):
        y_bottom = top + step * (k + 1)
        bx = x + board * 1.5
        while bx < x + w - board * 4:
            bw = float(rng.uniform(0.025, 0.07)) * w
            if rng.random() < 0.12:  # a gap, a box, or a skin-coloured carton
                if rng.random() < 0.5:
                    _rect(img, bx, y_bottom - step * 0.55, bx + bw * 3, y_bottom - board, _c(rng, SKIN_OBJECTS, 6))
                bx += bw * 3.5
                continue
            bh = float(rng.uniform(0.55, 0.88)) * (step - board)
            colour = tuple(float(v) for v in rng.integers(20, 230, 3))
            _rect(img, bx, y_bottom - board - bh, bx + bw, y_bottom - board, colour)
            _rect(
                img,
                bx,
                y_bottom - board - bh * 0.8,
                bx + bw,
                y_bottom - board - bh * 0.72,
                tuple(v * 0.6 for v in colour),
            )
            bx += bw + 1
        _rect(img, x, y_bottom - board, x + w, y_bottom, wood)
    _rect(img, x, top, x + board * 1.5, floor, wood)
    _rect(img, x + w - board * 1.5, top, x + w, floor, wood)
    _rect(img, x, top, x + w, top + board, wood)


def _picture(
    img: npt.NDArray[np.uint8], x: float, y: float, w: float, h: float, rng: np.random.Generator, skin: bool
) -> None:
    _rect(img, x - 6, y - 6, x + w + 6, y + h + 6, _c(rng, WOOD_COLOURS + [(30, 30, 30), (220, 220, 220)], 6))
    if skin:  # a beige canvas with a few strokes: skin-coloured but no face
        _rect(img, x, y, x + w, y + h, _c(rng, SKIN_OBJECTS, 8))
        for _ in range(3):
            p0 = (int(x + rng.uniform(0, w)), int(y + rng.uniform(0, h)))
            p1 = (int(x + rng.uniform(0, w)), int(y + rng.uniform(0, h)))
            cv2.line(img, p0, p1, _c(rng, WOOD_COLOURS, 20), 5, cv2.LINE_AA)
        return
    sky = np.array(_c(rng, [(220, 180, 120), (200, 200, 230), (240, 200, 160)], 15))
    for k in range(int(h)):
        cv2.line(img, (int(x), int(y + k)), (int(x + w), int(y + k)), tuple((sky * (1 - 0.3 * k / h)).tolist()), 1)
    hills = np.array(
        [[x + w * f, y + h * (0.55 + 0.2 * np.sin(7 * f + rng.uniform(0, 6)))] for f in np.linspace(0, 1, 12)]
    )
    poly = np.vstack([hills, [[x + w, y + h], [x, y + h]]]).astype(np.int32)
    cv2.fillPoly(img, [poly], _c(rng, [(60, 120, 60), (70, 100, 90), (90, 140, 110)], 15), cv2.LINE_AA)


def _plant(img: npt.NDArray[np.uint8], x: float, floor: float, s: float, rng: np.random.Generator) -> None:
    pot = np.array(
        [
            [x - s * 0.3, floor - s * 0.55],
            [x + s * 0.3, floor - s * 0.55],
            [x + s * 0.22, floor],
            [x - s * 0.22, floor],
        ],
        np.int32,
    )
    cv2.fillPoly(img, [pot], _c(rng, [(50, 80, 160), (200, 200, 200), (40, 40, 40)], 10), cv2.LINE_AA)
    for _ in range(40):
        ang = rng.uniform(-2.6, -0.5)
        length = s * rng.uniform(0.5, 1.5)
        cx, cy = x + np.cos(ang) * length * 0.7, floor - s * 0.55 + np.sin(ang) * length * 0.9
        green = (rng.uniform(20, 70), rng.uniform(90, 160), rng.uniform(30, 80))
        axes = (int(s * 0.32), int(s * 0.09))
        cv2.ellipse(img, (int(cx), int(cy)), axes, float(np.degrees(ang)), 0, 360, green, -1, cv2.LINE_AA)


def _lamp(img: npt.NDArray[np.uint8], x: float, floor: float, h: float, rng: np.random.Generator) -> None:
    cv2.line(
        img, (int(x), int(floor)), (int(x), int(floor - h * 0.8)), (40, 40, 45), max(int(h * 0.015), 3), cv2.LINE_AA
    )
    shade = np.array(
        [
            [x - h * 0.1, floor - h * 0.8],
            [x + h * 0.1, floor - h * 0.8],
            [x + h * 0.06, floor - h],
            [x - h * 0.06, floor - h],
        ],
        np.int32,
    )
    cv2.fillPoly(img, [shade], _c(rng, [(200, 235, 245), (180, 220, 240)], 6), cv2.LINE_AA)
    cv2.ellipse(img, (int(x), int(floor)), (int(h * 0.08), int(h * 0.015)), 0, 0, 360, (40, 40, 45), -1, cv2.LINE_AA)


def _sofa(
    img: npt.NDArray[np.uint8], x0: float, x1: float, seat: float, floor: float, rng: np.random.Generator
) -> None:
    colour = _c(rng, [(60, 60, 140), (90, 90, 90), (120, 90, 50), (70, 110, 80), (40, 40, 50)], 10)
    dark = tuple(v * 0.75 for v in colour)
    back = seat - (floor - seat) * 0.9
    _rect(img, x0, back, x1, floor - (floor - seat) * 0.2, colour)
    _rect(img, x0 - 25, seat - (floor - seat) * 0.35, x0 + 30, floor - (floor - seat) * 0.2, dark)
    _rect(img, x1 - 30, seat - (floor - seat) * 0.35, x1 + 25, floor - (floor - seat) * 0.2, dark)
    n = int(rng.integers(2, 4))
    for k in range(n):
        cx0 = x0 + 30 + (x1 - x0 - 60) * k / n
        _rect(
            img,
            cx0 + 4,
            seat,
            cx0 + (x1 - x0 - 60) / n - 4,
            seat + (floor - seat) * 0.3,
            tuple(v * 1.1 for v in colour),
        )
        cv2.line(img, (int(cx0), int(back + 10)), (int(cx0), int(seat)), dark, 3, cv2.LINE_AA)


def draw_room(width: int, height: int, rng: np.random.Generator) -> FloatImage:
    """A random room seen from about chest height: `(height, width, 3)` float32 BGR in 0..255."""
    s = 2
    w, h = width * s, height * s
    wall = np.array(_c(rng, WALL_COLOURS, 8))
    img = np.empty((h, w, 3), np.uint8)
    img[:] = wall.astype(np.uint8)
    floor = h * float(rng.uniform(0.8, 0.9))
    floor_colour = _c(rng, WOOD_COLOURS + [(120, 120, 125), (90, 110, 130)], 10)
    _rect(img, 0, floor, w, h, floor_colour)
    for k in range(-12, 13):  # planks receding to a vanishing point above the frame
        cv2.line(
            img,
            (int(w / 2 + k * w * 0.03), int(floor)),
            (int(w / 2 + k * w * 0.12), h),
            tuple(v * 0.85 for v in floor_colour),
            2,
            cv2.LINE_AA,
        )
    _rect(img, 0, floor - h * 0.02, w, floor, tuple(min(v * 1.15, 255) for v in wall))
    door_left = rng.random() < 0.5
    dw, sw = w * float(rng.uniform(0.15, 0.2)), w * float(rng.uniform(0.2, 0.28))
    door_x = w * float(rng.uniform(0.02, 0.08)) if door_left else w - dw - w * float(rng.uniform(0.02, 0.08))
    shelf_x = w - sw - w * float(rng.uniform(0.0, 0.05)) if door_left else w * float(rng.uniform(0.0, 0.05))
    _door(img, door_x, h * float(rng.uniform(0.05, 0.15)), floor, dw, rng)
    _shelf(img, shelf_x, h * float(rng.uniform(0.1, 0.3)), floor, sw, rng)
    _picture(
        img, w * float(rng.uniform(0.32, 0.42)), h * float(rng.uniform(0.05, 0.12)), w * 0.14, h * 0.13, rng, False
    )
    _picture(img, w * float(rng.uniform(0.55, 0.62)), h * float(rng.uniform(0.08, 0.18)), w * 0.09, h * 0.16, rng, True)
    clock = (int(w * rng.uniform(0.3, 0.7)), int(h * 0.33))
    cv2.circle(img, clock, int(h * 0.035), (230, 230, 230), -1, cv2.LINE_AA)
    cv2.circle(img, clock, int(h * 0.035), (40, 40, 40), 2, cv2.LINE_AA)
    cv2.line(img, clock, (clock[0] + int(h * 0.02), clock[1] - int(h * 0.01)), (20, 20, 20), 2, cv2.LINE_AA)
    _sofa(
        img,
        w * float(rng.uniform(0.25, 0.32)),
        w * float(rng.uniform(0.68, 0.75)),
        floor - h * 0.12,
        floor + h * 0.03,
        rng,
    )
    table_x = w * float(rng.uniform(0.26, 0.36)) if rng.random() < 0.5 else w * float(rng.uniform(0.6, 0.72))
    _rect(img, table_x, floor - h * 0.08, table_x + w * 0.1, floor - h * 0.065, _c(rng, SKIN_OBJECTS, 8))
    _rect(img, table_x + 6, floor - h * 0.065, table_x + 14, floor + h * 0.05, (40, 60, 90))
    _rect(img, table_x + w * 0.1 - 14, floor - h * 0.065, table_x + w * 0.1 - 6, floor + h * 0.05, (40, 60, 90))
    _plant(
        img,
        w * float(rng.uniform(0.2, 0.26)) if door_left else w * float(rng.uniform(0.74, 0.8)),
        floor + h * 0.05,
        h * 0.2,
        rng,
    )
    _lamp(
        img,
        w * float(rng.uniform(0.22, 0.3)) if not door_left else w * float(rng.uniform(0.7, 0.78)),
        floor,
        h * 0.75,
        rng,
    )
    box_x = w * float(rng.uniform(0.05, 0.9))
    _rect(img, box_x, floor - h * 0.12, box_x + w * 0.08, floor + h * 0.02, _c(rng, SKIN_OBJECTS, 6))
    out = cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA).astype(np.float32)
    # Light falls off away from a ceiling lamp; wall paint and plaster are not perfectly even.
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float32)
    lx, ly = width * float(rng.uniform(0.2, 0.8)), -height * 0.3
    falloff = 1.08 - 0.35 * np.hypot((xs - lx) / width, (ys - ly) / height) ** 2
    blotch = cv2.resize(rng.normal(0, 1, (12, 16)).astype(np.float32), (width, height), interpolation=cv2.INTER_CUBIC)
    out *= (falloff * (1.0 + 0.025 * blotch))[..., None]
    return out
