//! Scanline rasterisation of outlines into row spans and bit-packed masks.
//!
//! A pixel belongs to a shape when its centre (integer coordinates, see [`crate::camera`])
//! lies inside or on the exact outline. Every outline here is convex, so it covers one run of
//! pixels per row: a [`Span`]. Spans are the compact form the cost evaluation consumes;
//! [`BitMask`] packs 64 pixels per word so that masks compare by AND and popcount.

use crate::error::{CoreError, Result};
use crate::outline::{Ellipse, Outline};
use nalgebra::Vector2;

/// Largest image side rendered or scored: beyond it one mask takes gigabytes.
pub const MAX_IMAGE_SIDE: u32 = 8192;

/// A rectangle of the image: columns `x..x + width`, rows `y..y + height`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Roi {
    pub x: i32,
    pub y: i32,
    pub width: u32,
    pub height: u32,
}

impl Roi {
    /// The whole image.
    pub fn full(width: u32, height: u32) -> Self {
        Roi {
            x: 0,
            y: 0,
            width,
            height,
        }
    }

    /// A region that must be non-empty and lie inside a `width x height` image.
    pub fn inside(x: i64, y: i64, w: i64, h: i64, width: u32, height: u32) -> Result<Self> {
        for (name, side) in [("width", width), ("height", height)] {
            if side > MAX_IMAGE_SIDE {
                return Err(CoreError::OutOfRange {
                    name,
                    expected: "at most 8192 pixels",
                    value: f64::from(side),
                });
            }
        }
        // checked_add: a corner near i64::MAX must not wrap round into the image.
        let ok = w > 0
            && h > 0
            && x >= 0
            && y >= 0
            && x.checked_add(w).is_some_and(|end| end <= i64::from(width))
            && y.checked_add(h).is_some_and(|end| end <= i64::from(height));
        if !ok {
            return Err(CoreError::InvalidRoi {
                roi: (x, y, w, h),
                width,
                height,
            });
        }
        // The bounds check above keeps every value within the image's u32 size.
        Ok(Roi {
            x: i32::try_from(x).unwrap_or(i32::MAX),
            y: i32::try_from(y).unwrap_or(i32::MAX),
            width: u32::try_from(w).unwrap_or(0),
            height: u32::try_from(h).unwrap_or(0),
        })
    }

    fn x_end(&self) -> i32 {
        self.x + self.width as i32
    }

    fn y_end(&self) -> i32 {
        self.y + self.height as i32
    }
}

/// The half-open run of columns `x0..x1` of one row; empty when `x0 >= x1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Span {
    pub x0: i32,
    pub x1: i32,
}

impl Span {
    /// The empty span.
    pub const EMPTY: Span = Span { x0: 0, x1: 0 };

    /// Number of pixels.
    pub fn len(&self) -> u32 {
        (self.x1 - self.x0).max(0) as u32
    }

    /// Whether it holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.x1 <= self.x0
    }
}

/// One span per sampled row: rows `y0, y0 + step, ...` (`spans.len()` of them), in image
/// coordinates. `step` is 1 for a full rasterisation.
#[derive(Debug, Clone)]
pub struct RowSpans {
    pub y0: i32,
    pub step: i32,
    pub spans: Vec<Span>,
    /// Scratch: the exact x-interval of each row, kept to reuse its allocation.
    lo: Vec<f64>,
    hi: Vec<f64>,
}

impl Default for RowSpans {
    fn default() -> Self {
        RowSpans {
            y0: 0,
            step: 1,
            spans: Vec::new(),
            lo: Vec::new(),
            hi: Vec::new(),
        }
    }
}

impl PartialEq for RowSpans {
    fn eq(&self, other: &Self) -> bool {
        self.y0 == other.y0 && self.step == other.step && self.spans == other.spans
    }
}

impl RowSpans {
    /// Number of pixels covered.
    pub fn area(&self) -> u64 {
        self.spans.iter().map(|s| u64::from(s.len())).sum()
    }

    /// The span of image row `y` (empty outside the rows held or between sampled rows).
    #[inline]
    pub fn row(&self, y: i32) -> Span {
        let d = y - self.y0;
        if d < 0 || d % self.step != 0 {
            return Span::EMPTY;
        }
        self.spans
            .get((d / self.step) as usize)
            .copied()
            .unwrap_or(Span::EMPTY)
    }

    /// The image row of entry `i`.
    #[inline]
    pub fn y(&self, i: usize) -> i32 {
        self.y0 + i as i32 * self.step
    }
}

// Plain comparisons compile to single min/max instructions; f64::min/max also order NaN,
// which costs several more per call on the hottest loop of the tracker. No NaN reaches here.
#[inline]
fn fmin(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

#[inline]
fn fmax(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// The entries of a buffer holding rows `first, first + step, ...` (`n` of them) that lie
/// in `rows`.
#[inline]
fn overlap(rows: (i32, i32), first: i32, step: i32, n: usize) -> std::ops::Range<usize> {
    let up = |v: i32| {
        if v <= 0 {
            0
        } else {
            ((v + step - 1) / step) as usize
        }
    };
    let a = up(rows.0 - first).min(n);
    let b = up(rows.1 - first).min(n);
    a..b.max(a)
}

/// Row-span evaluation of one ellipse, with its per-row constants precomputed.
#[derive(Debug, Clone, Copy)]
struct EllipseRows {
    cx: f64,
    cy: f64,
    syy: f64,
    shear: f64,
    width2: f64,
    /// Pixel rows whose centre line meets the ellipse: `rows.0..rows.1`.
    rows: (i32, i32),
}

impl EllipseRows {
    /// `None` for an ellipse of (numerically) no area: it holds no pixel centre.
    fn new(e: &Ellipse) -> Option<Self> {
        let det = e.det();
        if !(det > 1e-18 && e.syy > 0.0) {
            return None;
        }
        let h = e.syy.sqrt();
        Some(EllipseRows {
            cx: e.cx,
            cy: e.cy,
            syy: e.syy,
            shear: e.sxy / e.syy,
            width2: det / (e.syy * e.syy),
            rows: row_range(e.cy - h, e.cy + h),
        })
    }

    /// The x-interval at height `y`, for a row inside `rows`.
    #[inline]
    fn at(&self, y: f64) -> (f64, f64) {
        let dy = y - self.cy;
        let t = fmax(self.syy - dy * dy, 0.0);
        let mid = self.cx + self.shear * dy;
        let half = (self.width2 * t).sqrt();
        (mid - half, mid + half)
    }

    /// Widens the intervals of rows `y0, y0 + step, ...` to hold the ellipse.
    #[inline]
    fn widen(&self, y0: i32, step: i32, lo: &mut [f64], hi: &mut [f64]) {
        for (i, (l, h)) in lo.iter_mut().zip(hi.iter_mut()).enumerate() {
            let (a, b) = self.at(f64::from(y0) + (i as f64) * f64::from(step));
            *l = fmin(*l, a);
            *h = fmax(*h, b);
        }
    }
}

/// `ceil(v)` as an integer, saturating at +-1e9, far outside any image. By truncation and a
/// compare, which needs no rounding instruction on any target.
#[inline]
fn ceil_i32(v: f64) -> i32 {
    let t = fmax(fmin(v, 1e9), -1e9) as i32;
    t + i32::from(f64::from(t) < v)
}

/// `floor(v)` as an integer, saturating (see [`ceil_i32`]).
#[inline]
fn floor_i32(v: f64) -> i32 {
    let t = fmax(fmin(v, 1e9), -1e9) as i32;
    t - i32::from(f64::from(t) > v)
}

/// The pixels whose centres lie in `[lo, hi]`, clipped to the columns of `roi`.
///
/// All in floats, so that the loop over rows runs two rows per instruction: rounded by SSE4.1
/// (the crate builds for x86-64-v2, `.cargo/config.toml`), clipped into the region's columns
/// (which also makes the +inf/-inf of a missed row finite), then converted by [`int_of`].
#[inline]
fn clipped_span(lo: f64, hi: f64, roi: &Roi) -> Span {
    let (left, right) = (f64::from(roi.x), f64::from(roi.x_end()));
    let x0 = fmin(fmax(lo.ceil(), left), right);
    let x1 = fmax(fmin(hi.floor() + 1.0, right), left);
    // An empty interval (lo > hi, including a missed row) gives x0 >= x1.
    if x0 < x1 {
        Span {
            x0: int_of(x0),
            x1: int_of(x1),
        }
    } else {
        Span::EMPTY
    }
}

/// An integer-valued float of i32 range as an i32, exactly. Adding 1.5 * 2^52 moves the
/// integer into the low bits of the mantissa without rounding (it has no fraction), as two's
/// complement; unlike `as`, this needs no saturation checks and vectorises.
#[inline]
fn int_of(v: f64) -> i32 {
    const SHIFT: f64 = 6_755_399_441_055_744.0; // 1.5 * 2^52
    (v + SHIFT).to_bits() as u32 as i32
}

/// Integer rows `first..end` whose centres lie in `[lo, hi]`.
fn row_range(lo: f64, hi: f64) -> (i32, i32) {
    if !(lo <= hi) {
        return (0, 0);
    }
    let first = ceil_i32(lo);
    (first, (floor_i32(hi) + 1).max(first))
}

/// A convex polygon as bounds on x per row: `x >= a + b y` for each lower line and
/// `x <= a + b y` for each upper line, valid for the rows `rows.0..rows.1`. A horizontal edge
/// bounds no x (it lies at the polygon's top or bottom, which the row range covers). The other
/// edges run down on one side and up on the other (around a cycle y cannot only grow), so each
/// side has one to three lines; spare slots repeat a line of their side, which changes no
/// maximum or minimum, so every row evaluates three of each without branching.
#[derive(Debug, Clone, Copy)]
struct QuadRows {
    lower: [(f64, f64); 3],
    upper: [(f64, f64); 3],
    rows: (i32, i32),
}

/// Up to three lines of one side of a [`QuadRows`].
#[derive(Default)]
struct BoundLines {
    lines: [(f64, f64); 3],
    n: usize,
}

impl BoundLines {
    /// Adds a line; a side never has four (see [`QuadRows`]), so none is ever dropped.
    fn push(&mut self, line: (f64, f64)) {
        if self.n < 3 {
            self.lines[self.n] = line;
            self.n += 1;
        }
    }

    /// The lines, spare slots filled with the first; `None` without any line (which a
    /// polygon of positive area cannot have).
    fn padded(&self) -> Option<[(f64, f64); 3]> {
        let first = *self.lines[..self.n].first()?;
        let mut l = self.lines;
        l[self.n..].fill(first);
        Some(l)
    }
}

impl QuadRows {
    fn new(quad: &[Vector2<f64>; 4]) -> Option<Self> {
        let area2: f64 = (0..4)
            .map(|i| {
                let (a, b) = (quad[i], quad[(i + 1) % 4]);
                a.x * b.y - a.y * b.x
            })
            .sum();
        if !(area2.abs() >= 1e-9) {
            return None; // A quadrilateral of no area adds no pixel to the ellipses.
        }
        let s = area2.signum();
        let (mut lower, mut upper) = (BoundLines::default(), BoundLines::default());
        for i in 0..4 {
            let (a, b) = (quad[i], quad[(i + 1) % 4]);
            let (ex, ey) = (b.x - a.x, b.y - a.y);
            // Inside is where s * cross(e, p - a) >= 0, i.e. s*ey*(x - ax) <= s*ex*(y - ay).
            if ey != 0.0 {
                let slope = ex / ey;
                let line = (a.x - slope * a.y, slope);
                if s * ey > 0.0 {
                    upper.push(line);
                } else {
                    lower.push(line);
                }
            }
        }
        let y_lo = quad.iter().map(|v| v.y).fold(f64::INFINITY, f64::min);
        let y_hi = quad.iter().map(|v| v.y).fold(f64::NEG_INFINITY, f64::max);
        Some(QuadRows {
            lower: lower.padded()?,
            upper: upper.padded()?,
            rows: row_range(y_lo, y_hi),
        })
    }

    #[inline]
    fn at(&self, y: f64) -> (f64, f64) {
        let mut lo = f64::NEG_INFINITY;
        let mut hi = f64::INFINITY;
        for k in 0..3 {
            lo = fmax(lo, self.lower[k].0 + self.lower[k].1 * y);
            hi = fmin(hi, self.upper[k].0 + self.upper[k].1 * y);
        }
        (lo, hi)
    }

    /// Sets the intervals of rows `y0, y0 + step, ...` to the quadrilateral's.
    #[inline]
    fn set(&self, y0: i32, step: i32, lo: &mut [f64], hi: &mut [f64]) {
        for (i, (l, h)) in lo.iter_mut().zip(hi.iter_mut()).enumerate() {
            (*l, *h) = self.at(f64::from(y0) + (i as f64) * f64::from(step));
        }
    }
}

/// An outline prepared for scanning rows.
#[derive(Debug, Clone, Copy)]
pub struct Scanner {
    ellipses: [Option<EllipseRows>; 2],
    quad: Option<QuadRows>,
    /// All rows any piece covers.
    rows: (i32, i32),
}

impl Scanner {
    /// Prepares an outline for rasterisation.
    pub fn new(outline: &Outline) -> Self {
        let ellipses = outline
            .ellipses
            .map(|e| e.as_ref().and_then(EllipseRows::new));
        let quad = outline.quad.as_ref().and_then(QuadRows::new);
        let mut rows = (i32::MAX, i32::MIN);
        for r in ellipses
            .iter()
            .flatten()
            .map(|e| e.rows)
            .chain(quad.map(|q| q.rows))
        {
            if r.0 < r.1 {
                rows = (rows.0.min(r.0), rows.1.max(r.1));
            }
        }
        if rows.0 >= rows.1 {
            rows = (0, 0);
        }
        Scanner {
            ellipses,
            quad,
            rows,
        }
    }

    /// The exact x-interval of the outline at pixel row `y`; lo > hi when the row misses.
    #[inline]
    pub fn interval(&self, y: i32) -> (f64, f64) {
        let yf = f64::from(y);
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        if let Some(q) = &self.quad {
            if y >= q.rows.0 && y < q.rows.1 {
                (lo, hi) = q.at(yf);
            }
        }
        for e in self.ellipses.iter().flatten() {
            if y >= e.rows.0 && y < e.rows.1 {
                let (a, b) = e.at(yf);
                lo = fmin(lo, a);
                hi = fmax(hi, b);
            }
        }
        (lo, hi)
    }

    /// The pixel rows the outline may cover, clipped to `roi`: `(first, end)`, half-open.
    pub fn row_range(&self, roi: &Roi) -> (i32, i32) {
        let first = self.rows.0.max(roi.y);
        let end = self.rows.1.min(roi.y_end());
        (first, end.max(first))
    }

    /// The pixel run of row `y` clipped to the columns of `roi`.
    #[inline]
    pub fn span(&self, y: i32, roi: &Roi) -> Span {
        let (lo, hi) = self.interval(y);
        clipped_span(lo, hi, roi)
    }

    /// The pixel run of row `y`, not clipped to any region.
    #[inline]
    pub fn span_unclipped(&self, y: i32) -> Span {
        let (lo, hi) = self.interval(y);
        if !(lo <= hi) {
            return Span::EMPTY;
        }
        let x0 = ceil_i32(lo);
        let x1 = floor_i32(hi) + 1;
        if x0 < x1 {
            Span { x0, x1 }
        } else {
            Span::EMPTY
        }
    }

    /// Sets in `mask` the outline's one-pixel contour inside the mask's region: pixels of the
    /// shape with a 4-neighbour outside the shape. Neighbours beyond the region are judged by
    /// the shape itself, so the region's border is never mistaken for the shape's.
    pub fn contour_into(&self, mask: &mut BitMask) {
        let roi = mask.roi;
        let (first, end) = self.row_range(&roi);
        let clip = |a: i32, b: i32| (a.max(roi.x), b.min(roi.x_end()));
        for y in first..end {
            let c = self.span_unclipped(y);
            if c.is_empty() {
                continue;
            }
            let (up, down) = (self.span_unclipped(y - 1), self.span_unclipped(y + 1));
            // Interior pixels have all four neighbours in the shape; each row is one run.
            let in0 = (c.x0 + 1).max(up.x0).max(down.x0);
            let in1 = (c.x1 - 1).min(up.x1).min(down.x1);
            let row = (y - roi.y) as usize;
            let bits = &mut mask.words[row * mask.stride..(row + 1) * mask.stride];
            let mut put = |a: i32, b: i32| {
                let (a, b) = clip(a, b);
                if a < b {
                    set_run(bits, (a - roi.x) as usize, (b - roi.x) as usize);
                }
            };
            if up.is_empty() || down.is_empty() || in0 >= in1 {
                put(c.x0, c.x1);
            } else {
                put(c.x0, in0);
                put(in1, c.x1);
            }
        }
    }

    /// Rasterises into `out`, reusing its allocation. Each piece fills the rows it covers in
    /// one tight loop (the compiler vectorises them), then the intervals become spans.
    pub fn spans_into(&self, roi: &Roi, out: &mut RowSpans) {
        self.sampled_spans_into(roi, 1, out);
    }

    /// Rasterises only the rows that are multiples of `step` (so that every outline sampled
    /// with the same step shares rows), into `out`.
    pub fn sampled_spans_into(&self, roi: &Roi, step: i32, out: &mut RowSpans) {
        let step = step.max(1);
        let (first, end) = self.row_range(roi);
        let first = first + (step - first.rem_euclid(step)) % step;
        let n = if end > first {
            ((end - first + step - 1) / step) as usize
        } else {
            0
        };
        out.y0 = first;
        out.step = step;
        // Rows start as missed (+inf, -inf), except those the quadrilateral sets anyway:
        // filling only the others halves the writes (`resize` writes one value at a time).
        out.lo.resize(n, f64::INFINITY);
        out.hi.resize(n, f64::NEG_INFINITY);
        let set = self.quad.map_or(0..0, |q| overlap(q.rows, first, step, n));
        for r in [0..set.start, set.end..n] {
            out.lo[r.clone()].fill(f64::INFINITY);
            out.hi[r].fill(f64::NEG_INFINITY);
        }
        if let Some(q) = &self.quad {
            q.set(
                first + set.start as i32 * step,
                step,
                &mut out.lo[set.clone()],
                &mut out.hi[set],
            );
        }
        for e in self.ellipses.iter().flatten() {
            let r = overlap(e.rows, first, step, n);
            e.widen(
                first + r.start as i32 * step,
                step,
                &mut out.lo[r.clone()],
                &mut out.hi[r],
            );
        }
        out.spans.clear();
        out.spans.extend(
            out.lo
                .iter()
                .zip(&out.hi)
                .map(|(&lo, &hi)| clipped_span(lo, hi, roi)),
        );
    }
}

/// Rasterises an outline inside `roi`.
pub fn spans_of_outline(outline: &Outline, roi: &Roi) -> RowSpans {
    let mut out = RowSpans::default();
    Scanner::new(outline).spans_into(roi, &mut out);
    out
}

/// A binary image over a region, 64 pixels per `u64` word, least significant bit leftmost.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BitMask {
    pub roi: Roi,
    /// Words per row.
    pub stride: usize,
    pub words: Vec<u64>,
}

impl BitMask {
    /// An empty mask over `roi`.
    pub fn new(roi: Roi) -> Self {
        let stride = (roi.width as usize).div_ceil(64);
        BitMask {
            roi,
            stride,
            words: vec![0; stride * roi.height as usize],
        }
    }

    /// Clears every bit, keeping the allocation.
    pub fn clear(&mut self) {
        self.words.fill(0);
    }

    /// The words of one row (row index relative to the region).
    pub fn row(&self, r: usize) -> &[u64] {
        &self.words[r * self.stride..(r + 1) * self.stride]
    }

    /// Whether image pixel `(x, y)` is set (false outside the region).
    pub fn get(&self, x: i32, y: i32) -> bool {
        let (cx, cy) = (x - self.roi.x, y - self.roi.y);
        if cx < 0 || cy < 0 || cx >= self.roi.width as i32 || cy >= self.roi.height as i32 {
            return false;
        }
        let (cx, cy) = (cx as usize, cy as usize);
        self.words[cy * self.stride + cx / 64] >> (cx % 64) & 1 == 1
    }

    /// Number of set pixels.
    pub fn count(&self) -> u64 {
        self.words.iter().map(|w| u64::from(w.count_ones())).sum()
    }

    /// Sets the pixels of the spans (given in image coordinates and already inside the region).
    pub fn fill(&mut self, spans: &RowSpans) {
        for (i, span) in spans.spans.iter().enumerate() {
            if span.is_empty() {
                continue;
            }
            let r = (spans.y(i) - self.roi.y) as usize;
            let row = &mut self.words[r * self.stride..(r + 1) * self.stride];
            set_run(
                row,
                (span.x0 - self.roi.x) as usize,
                (span.x1 - self.roi.x) as usize,
            );
        }
    }

    /// `self &= !other` (same region).
    pub fn subtract(&mut self, other: &BitMask) {
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a &= !b;
        }
    }

    /// `self |= other` (same region).
    pub fn union(&mut self, other: &BitMask) {
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a |= b;
        }
    }
}

/// Sets bits `x0..x1` of a bit row.
#[inline]
pub fn set_run(row: &mut [u64], x0: usize, x1: usize) {
    if x0 >= x1 {
        return;
    }
    let (w0, w1) = (x0 / 64, (x1 - 1) / 64);
    let head = u64::MAX << (x0 % 64);
    let tail = u64::MAX >> (63 - (x1 - 1) % 64);
    if w0 == w1 {
        row[w0] |= head & tail;
    } else {
        row[w0] |= head;
        for w in &mut row[w0 + 1..w1] {
            *w = u64::MAX;
        }
        row[w1] |= tail;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn int_of_is_exact_over_the_i32_range_of_images() {
        for v in (-70_000..70_000).chain([i32::MIN + 1, -1_000_000_000, 1_000_000_000, i32::MAX]) {
            assert_eq!(int_of(f64::from(v)), v);
        }
    }

    #[test]
    fn clipped_span_matches_rounding_by_integers() {
        let roi = Roi {
            x: -7,
            y: 0,
            width: 40,
            height: 1,
        };
        // The definition: the pixel centres in [lo, hi], by integer rounding, then clipped.
        let reference = |lo: f64, hi: f64| {
            let x0 = ceil_i32(lo).max(roi.x);
            let x1 = (floor_i32(hi) + 1).min(roi.x_end());
            if x0 < x1 {
                Span { x0, x1 }
            } else {
                Span::EMPTY
            }
        };
        let mut values = vec![f64::INFINITY, f64::NEG_INFINITY, 1e300, -1e300, 0.0, -0.0];
        for k in -120..120 {
            let v = f64::from(k) * 0.25;
            values.extend([
                v,
                v + 1e-12,
                v - 1e-12,
                v * (1.0 + f64::EPSILON),
                v * (1.0 - f64::EPSILON),
            ]);
        }
        for &lo in &values {
            for &hi in &values {
                assert_eq!(clipped_span(lo, hi, &roi), reference(lo, hi), "{lo} {hi}");
            }
        }
    }
}
