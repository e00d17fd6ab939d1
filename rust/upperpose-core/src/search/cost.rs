//! The cost of a candidate part against one frame (thesis Eq. 3.4.8-2; SPEC 5; docs/cost.md):
//!
//! `cost = w_sil Sil - w_edge Edge - w_motion Motion + w_skin Skin + w_arm Arm + w_ratio Ratio
//!         + w_cover Cover`
//!
//! Each stage of the hierarchical fit scores one part (torso with neck and head, or one arm)
//! inside one fixed region `R`, with the rest of the body (the *base*: parts already fitted or
//! held at their prediction) drawn as it stands. The model silhouette is `base | part`, so the
//! silhouette the base already explains is not asked of the part (the false minimum of thesis
//! 3.4.5). Everything that does not depend on the candidate is counted once per stage, so a
//! particle only pays for its own spans:
//!
//! - `|sil ^ (base | part)| = |sil ^ base| + |part & !base| - 2 |part & !base & sil|`
//! - Edge and Motion count feature pixels under the part's one-pixel contour.

use crate::image::{FrameView, PixelBox};
use crate::raster::{BitMask, Roi, RowSpans, Scanner, Span};
use nalgebra::Vector2;
use std::borrow::Cow;

/// Weights of the terms (thesis: 3, 20, 15, 250, 4, 400 for its own normalisations of the
/// first six; Cover is ours).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostWeights {
    pub sil: f64,
    pub edge: f64,
    pub motion: f64,
    pub skin: f64,
    pub arm: f64,
    pub ratio: f64,
    pub cover: f64,
}

impl Default for CostWeights {
    /// See docs/cost.md for how they were chosen. The Arm term is off: with the base drawn
    /// in, Sil already scores the arm against the silhouette outside the torso, and counting
    /// it twice only adds noise and time.
    fn default() -> Self {
        CostWeights {
            sil: 12.0,
            edge: 2.0,
            motion: 0.5,
            skin: 3.0,
            arm: 0.0,
            ratio: 0.5,
            cover: COVER_WEIGHT,
        }
    }
}

/// The default weight of the Cover term (docs/cost.md).
pub const COVER_WEIGHT: f64 = 12.0;

/// The terms for one part, each normalised (ranges in docs/cost.md).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CostTerms {
    /// `|sil ^ model| / A` (A: the part's nominal area, or `|R|`; docs/cost.md), in [0, |R| / A].
    pub sil: f64,
    /// Share of the part's contour on (dilated) edge pixels, in [0, 1].
    pub edge: f64,
    /// Share of the part's contour on (dilated) motion pixels, in [0, 1].
    pub motion: f64,
    /// Summed distance of matched skin points to their joints / shoulder width, >= 0.
    pub skin: f64,
    /// `|arm_sil ^ (part & !torso)| / A` for arms (0 for the torso), in [0, |R| / A].
    pub arm: f64,
    /// `| |model & R| / |sil & R| - 1 |`, >= 0.
    pub ratio: f64,
    /// For arms, `|front_skin & R & !part| / A`: skin over the fitted torso that neither arm
    /// covers (front_skin leaves out the other arm), in [0, |R| / A]; 0 for the torso.
    pub cover: f64,
}

impl CostTerms {
    /// The weighted cost; lower is better. Not bounded below by zero.
    pub fn total(&self, w: &CostWeights) -> f64 {
        w.sil * self.sil - w.edge * self.edge - w.motion * self.motion
            + w.skin * self.skin
            + w.arm * self.arm
            + w.ratio * self.ratio
            + w.cover * self.cover
    }
}

/// Running counts of up to four bit planes over a region: for each sampled row of the region
/// and each column `x` of `roi.x..=roi.x + width`, the number of set pixels of every plane in
/// columns `roi.x..x`, packed as four 16-bit lanes of one `u64`. The counts of a run `x0..x1`
/// are then one subtraction, for all four planes at once (lanes never borrow: each count only
/// grows). A lane holds at most the region's width, so regions are at most 65535 pixels wide
/// ([`FrameView::new`] rejects wider images). Only the rows the stage samples are built.
#[derive(Debug, Clone)]
struct CountTable {
    /// The region's first column.
    x0: i32,
    /// The first sampled row and the rows between sampled rows: table row `r` is image row
    /// `y0 + r * step`.
    y0: i32,
    step: i32,
    /// Cells per table row: the region's width + 1.
    row_len: usize,
    cells: Vec<u64>,
}

/// Bit `i` of a byte moved to bit `4 i`: eight pixels of one plane spread into nibbles.
const NIBBLES: [u32; 256] = {
    let mut t = [0u32; 256];
    let mut v = 0;
    while v < 256 {
        let mut i = 0;
        while i < 8 {
            t[v] |= ((v as u32 >> i) & 1) << (4 * i);
            i += 1;
        }
        v += 1;
    }
    t
};

/// The packed increment of one pixel whose four plane bits form the nibble `k`.
const INCREMENT: [u64; 16] = {
    let mut t = [0u64; 16];
    let mut v = 0;
    while v < 16 {
        let mut k = 0;
        while k < 4 {
            t[v] |= ((v as u64 >> k) & 1) << (16 * k);
            k += 1;
        }
        v += 1;
    }
    t
};

/// The count of plane `k` in a packed entry or difference of entries.
#[inline]
fn lane(v: u64, k: u32) -> u32 {
    (v >> (16 * k)) as u32 & 0xffff
}

impl CountTable {
    /// `planes` are full-frame bit planes with `stride` words per row; rows that are multiples
    /// of `step` are built.
    fn new(roi: Roi, step: i32, stride: usize, planes: [&[u64]; 4]) -> Self {
        let row_len = roi.width as usize + 1;
        let step = step.max(1);
        let rows: Vec<i32> = (roi.y..roi.y + roi.height as i32)
            .filter(|y| y % step == 0)
            .collect();
        let mut cells = vec![0u64; row_len * rows.len()];
        let (x0, x1) = (roi.x as usize, roi.x as usize + roi.width as usize);
        for (&y, out) in rows.iter().zip(cells.chunks_exact_mut(row_len)) {
            let base = y as usize * stride;
            let mut acc = 0u64;
            let mut i = 1;
            let mut x = x0;
            // Word by word; most words of a plane are all clear or all set over the piece
            // read, and then every pixel adds the same packed increment.
            while x < x1 {
                let (w, b) = (base + x / 64, x % 64);
                let n = (64 - b).min(x1 - x);
                let mask = u64::MAX >> (64 - n);
                let bits = planes.map(|p| p[w] >> b & mask);
                if bits.iter().all(|&v| v == 0 || v == mask) {
                    let inc = (0..4).fold(0u64, |a, k| a | u64::from(bits[k] != 0) << (16 * k));
                    for c in &mut out[i..i + n] {
                        acc += inc;
                        *c = acc;
                    }
                } else {
                    // Eight pixels at a time: their four plane bits as eight nibbles, each
                    // nibble's packed increment looked up.
                    for (q, chunk) in out[i..i + n].chunks_mut(8).enumerate() {
                        let byte = |k: usize| NIBBLES[(bits[k] >> (8 * q)) as usize & 0xff];
                        let nib = byte(0) | byte(1) << 1 | byte(2) << 2 | byte(3) << 3;
                        for (j, c) in chunk.iter_mut().enumerate() {
                            acc += INCREMENT[(nib >> (4 * j)) as usize & 15];
                            *c = acc;
                        }
                    }
                }
                i += n;
                x += n;
            }
        }
        CountTable {
            x0: roi.x,
            y0: rows.first().copied().unwrap_or(roi.y),
            step,
            row_len,
            cells,
        }
    }

    /// The table row of image row `y`, a sampled row of the region.
    #[inline]
    fn index(&self, y: i32) -> usize {
        ((y - self.y0) / self.step) as usize
    }

    /// Table row `r`, to count runs of it with [`RowCounts::run`].
    #[inline]
    fn row(&self, r: usize) -> RowCounts<'_> {
        let start = r * self.row_len;
        RowCounts {
            x0: self.x0,
            cells: &self.cells[start..start + self.row_len],
        }
    }
}

/// The running counts of one sampled row.
#[derive(Clone, Copy)]
struct RowCounts<'a> {
    x0: i32,
    cells: &'a [u64],
}

impl RowCounts<'_> {
    /// The packed counts of columns `region.x..x` (`x` inside the region or at its end).
    #[inline]
    fn at(&self, x: i32) -> u64 {
        self.cells[(x - self.x0) as usize]
    }

    /// The packed counts of columns `x0..x1` (inside the region, `x0 <= x1`).
    #[inline]
    fn run(&self, x0: i32, x1: i32) -> u64 {
        self.at(x1) - self.at(x0)
    }
}

/// Lanes of the stage's main table.
const FREE: u32 = 0; // R & !base
const SIL_FREE: u32 = 1; // R & !base & sil
const EDGE: u32 = 2;
const MOTION: u32 = 3;
/// Lanes of the arm stages' table.
const OUTSIDE: u32 = 0; // R & !torso
const ARM_SIL: u32 = 1; // R & !torso & sil: the arm silhouette
const FRONT_SKIN: u32 = 2; // R & front_skin

/// What an arm stage matches besides the silhouette: the arm silhouette (silhouette outside
/// the torso region, thesis 3.4.5) against the part outside that region, and the skin in
/// front of the torso that the part should cover (Cover). Either may be left out.
#[derive(Debug, Clone)]
struct ArmPlanes {
    counts: CountTable,
    /// `|arm_sil & R|`, when the Arm term is counted.
    feature_area: Option<f64>,
    /// `|front_skin & R|`, when the Cover term is counted.
    cover_area: Option<f64>,
}

/// The full-frame masks a stage is scored with, besides the frame's features.
#[derive(Debug, Clone, Copy)]
pub struct StageMasks<'m> {
    /// The rest of the body, drawn as it stands.
    pub base: &'m BitMask,
    /// The fitted torso, neck and head: for arm stages whose Arm term is weighed.
    pub torso: Option<&'m BitMask>,
    /// The skin over the fitted torso cone that the other arm leaves uncovered: for arm stages
    /// whose Cover term is weighed.
    pub front_skin: Option<&'m BitMask>,
    /// The other arm: its edge and motion pixels do not count for the candidate.
    pub claimed: Option<&'m BitMask>,
}

impl<'m> StageMasks<'m> {
    /// Only the base: no Arm or Cover term, every edge and motion pixel counts.
    pub fn base(base: &'m BitMask) -> Self {
        StageMasks {
            base,
            torso: None,
            front_skin: None,
            claimed: None,
        }
    }
}

/// Everything about one stage's region that does not depend on the candidate.
#[derive(Debug, Clone)]
pub struct StageRegion {
    pub roi: Roi,
    row_step: i32,
    counts: CountTable,
    arm: Option<ArmPlanes>,
    sil_area: f64,
    /// `|(sil ^ base) & R|`.
    xor0: f64,
    /// `|base & R|`.
    base_area: f64,
    /// What the Sil and Arm terms' mismatch is divided by: the region's area, or the part's
    /// own nominal area (see [`StageRegion::normalised_by`]).
    sil_norm: f64,
}

/// A full-frame mask of the region `roi`.
fn region_mask(width: u32, height: u32, roi: Roi) -> BitMask {
    let mut m = BitMask::new(Roi::full(width, height));
    for y in roi.y..roi.y + roi.height as i32 {
        let r = y as usize;
        let row = &mut m.words[r * m.stride..(r + 1) * m.stride];
        crate::raster::set_run(row, roi.x as usize, (roi.x + roi.width as i32) as usize);
    }
    m
}

fn count(words: &[u64]) -> f64 {
    words.iter().map(|w| f64::from(w.count_ones())).sum()
}

/// The count of the rows of `roi` that are multiples of `step`, times `step`: what a
/// candidate's sampled counts are compared with.
fn sampled_count(words: &[u64], stride: usize, roi: Roi, step: i32) -> f64 {
    let step = step.max(1);
    let rows = (roi.y..roi.y + roi.height as i32).filter(|y| y % step == 0);
    let n: f64 = rows
        .map(|y| count(&words[y as usize * stride..(y as usize + 1) * stride]))
        .sum();
    n * f64::from(step)
}

impl StageRegion {
    /// Prepares a stage with the masks of [`StageMasks`].
    /// Candidates are counted on rows that are multiples of `row_step` (see [`evaluate`]) and
    /// only inside `reach`, the part of `roi` they can cover: the running counts are built there.
    /// Edge and motion pixels under `claimed` (the other arm) do not count for the candidate,
    /// while its contour there still counts in the shares' denominators: an arm laid over the
    /// other arm would otherwise collect that arm's contour for free.
    pub fn new<'a>(
        frame: &FrameView<'a>,
        roi: Roi,
        reach: Roi,
        row_step: i32,
        masks: StageMasks<'_>,
    ) -> Self {
        let StageMasks {
            base,
            torso,
            front_skin,
            claimed,
        } = masks;
        let r = region_mask(frame.width, frame.height, roi);
        let stride = r.stride;
        let sil = frame.sil.words;
        let zip = |f: &dyn Fn(usize) -> u64| -> Vec<u64> { (0..r.words.len()).map(f).collect() };
        let unclaimed = |plane: &'a [u64]| -> Cow<'a, [u64]> {
            match claimed {
                Some(c) => Cow::Owned(zip(&|i| plane[i] & !c.words[i])),
                None => Cow::Borrowed(plane),
            }
        };
        let (edge, motion) = (unclaimed(frame.edge.words), unclaimed(frame.motion.words));
        let free = zip(&|i| r.words[i] & !base.words[i]);
        let sil_free = zip(&|i| free[i] & sil[i]);
        let xor = zip(&|i| r.words[i] & (sil[i] ^ base.words[i]));
        let base_in = zip(&|i| r.words[i] & base.words[i]);
        let sil_in = zip(&|i| r.words[i] & sil[i]);
        let counts = CountTable::new(reach, row_step, stride, [&free, &sil_free, &edge, &motion]);
        let arm = (torso.is_some() || front_skin.is_some()).then(|| {
            let outside = torso.map(|t| zip(&|i| r.words[i] & !t.words[i]));
            let feature = outside.as_ref().map(|o| zip(&|i| o[i] & sil[i]));
            let front = front_skin.map(|f| zip(&|i| r.words[i] & f.words[i]));
            let none = vec![0; r.words.len()];
            let planes = [&outside, &feature, &front].map(|p| p.as_deref().unwrap_or(&none));
            ArmPlanes {
                counts: CountTable::new(
                    reach,
                    row_step,
                    stride,
                    [planes[0], planes[1], planes[2], &none],
                ),
                feature_area: feature.as_deref().map(count),
                cover_area: front
                    .as_deref()
                    .map(|f| sampled_count(f, stride, roi, row_step)),
            }
        });
        StageRegion {
            roi,
            row_step: row_step.max(1),
            counts,
            sil_area: count(&sil_in),
            xor0: count(&xor),
            base_area: count(&base_in),
            sil_norm: f64::from(roi.width) * f64::from(roi.height),
            arm,
        }
    }

    /// Divides the Sil and Arm mismatch by `area` pixels instead of the region's area. With
    /// the part's own size there, a limb's misplaced silhouette weighs the same against its
    /// contour terms whatever the size of the region around it (a diagonal arm's box, the
    /// full-range search's disc).
    pub fn normalised_by(mut self, area: f64) -> Self {
        self.sil_norm = area.max(1.0);
        self
    }
}

/// Most pieces a candidate part has (the torso stage has three: torso, neck and head).
const MAX_PIECES: usize = 4;

/// Pixel counts over the union of a candidate's pieces, summed with signs (inclusion-exclusion).
#[derive(Debug, Default)]
struct UnionCounts {
    free: i64,
    sil_free: i64,
    arm_out: i64,
    arm_feat: i64,
    front_skin: i64,
}

impl UnionCounts {
    /// Adds `sign` times the counts of columns `x0..x1` of table row `r`, whose main-table
    /// counts are `c`.
    #[inline]
    fn add(&mut self, region: &StageRegion, c: u64, r: usize, x0: i32, x1: i32, sign: i64) {
        self.free += sign * i64::from(lane(c, FREE));
        self.sil_free += sign * i64::from(lane(c, SIL_FREE));
        if let Some(a) = &region.arm {
            let c = a.counts.row(r).run(x0, x1);
            self.arm_out += sign * i64::from(lane(c, OUTSIDE));
            self.arm_feat += sign * i64::from(lane(c, ARM_SIL));
            self.front_skin += sign * i64::from(lane(c, FRONT_SKIN));
        }
    }
}

/// Reusable buffers of one evaluating thread.
#[derive(Debug, Default)]
pub struct Scratch {
    spans: Vec<RowSpans>,
}

/// A model joint and where the image puts it, both in pixels: a skin point, or the box of a
/// merged blob that holds it somewhere (a point is a box of size zero).
#[derive(Debug, Clone, Copy)]
pub struct SkinPair {
    pub model: Vector2<f64>,
    pub image: PixelBox,
}

impl SkinPair {
    /// Distance from the model joint to the image's point or box; 0 inside the box.
    pub fn distance(&self) -> f64 {
        let [lo, hi] = self.image;
        let outside = (lo - self.model).sup(&(self.model - hi));
        outside.sup(&Vector2::zeros()).norm()
    }
}

/// Scores a candidate part, given as the scanners of its convex pieces.
///
/// Only every `row_step`-th image row (the region's) is rasterised and counted (rows on a grid shared by all
/// pieces); area counts are scaled back by `row_step`, and a contour row's neighbours are the
/// sampled rows above and below. `row_step = 1` is the exact cost.
pub fn evaluate(
    region: &StageRegion,
    pieces: &[Scanner],
    skin: &[SkinPair],
    shoulder_px: f64,
    scratch: &mut Scratch,
) -> CostTerms {
    if scratch.spans.len() < pieces.len() {
        scratch.spans.resize_with(pieces.len(), RowSpans::default);
    }
    let step = region.row_step;
    let spans = &mut scratch.spans[..pieces.len()];
    for (s, out) in pieces.iter().zip(spans.iter_mut()) {
        s.sampled_spans_into(&region.roi, step, out);
    }
    let t = &region.counts;

    // Every piece's rows lie on the grid of multiples of `step` that the count table holds:
    // entry `i` of piece `s` is table row `t.index(s.y0) + i`. Each piece adds its own runs to
    // the union's counts; where pieces overlap, inclusion-exclusion below takes the overlaps
    // out again, so no row has to merge runs.
    let mut union = UnionCounts::default();
    let (mut contour, mut edge, mut motion) = (0u32, 0u32, 0u32);
    for s in spans.iter().filter(|s| !s.spans.is_empty()) {
        let r0 = t.index(s.y0);
        for (i, &c) in s.spans.iter().enumerate() {
            if c.is_empty() {
                continue;
            }
            let counts = t.row(r0 + i);
            let (at0, at1) = (counts.at(c.x0), counts.at(c.x1));
            let whole = at1 - at0;
            union.add(region, whole, r0 + i, c.x0, c.x1, 1);
            // Edge and motion under the piece's one-pixel contour: its pixels with a
            // 4-neighbour outside it (the sampled rows above and below stand for the rows).
            // That is the whole run or its two ends (disjoint, each at least one pixel, so the
            // packed sum of their counts cannot carry); the ends share the whole run's outer
            // look-ups.
            let up = if i > 0 { s.spans[i - 1] } else { Span::EMPTY };
            let down = s.spans.get(i + 1).copied().unwrap_or(Span::EMPTY);
            let in0 = (c.x0 + 1).max(up.x0).max(down.x0);
            let in1 = (c.x1 - 1).min(up.x1).min(down.x1);
            let v = if up.is_empty() || down.is_empty() || in0 >= in1 {
                contour += (c.x1 - c.x0) as u32;
                whole
            } else {
                contour += ((in0 - c.x0) + (c.x1 - in1)) as u32;
                (counts.at(in0) - at0) + (at1 - counts.at(in1))
            };
            edge += lane(v, EDGE);
            motion += lane(v, MOTION);
        }
    }
    // Every group of two or more pieces: its rows in common, where each row's overlap is one
    // run (the pieces are convex), counted with the sign of inclusion-exclusion.
    let m = spans.len();
    debug_assert!(m <= MAX_PIECES, "{m} pieces: 2^{m} groups");
    for group in 1u32..(1 << m) {
        if group.count_ones() < 2 {
            continue;
        }
        let sign = if group.count_ones() % 2 == 0 { -1 } else { 1 };
        let members = || {
            (0..m)
                .filter(move |p| group >> p & 1 == 1)
                .map(|p| &spans[p])
        };
        let first = members().map(|s| s.y0).max().unwrap_or(0);
        let end = members().map(|s| s.y(s.spans.len())).min().unwrap_or(0);
        if end <= first {
            continue;
        }
        let mut at = [0usize; MAX_PIECES]; // each member's entry of row `first`
        for (k, s) in members().enumerate() {
            at[k] = ((first - s.y0) / step) as usize;
        }
        let r0 = t.index(first);
        for row in 0..((end - first) / step) as usize {
            let (mut x0, mut x1) = (i32::MIN, i32::MAX);
            for (k, s) in members().enumerate() {
                let c = s.spans[at[k] + row];
                (x0, x1) = (x0.max(c.x0), x1.min(c.x1));
            }
            if x0 < x1 {
                let c = t.row(r0 + row).run(x0, x1);
                union.add(region, c, r0 + row, x0, x1, sign);
            }
        }
    }
    let UnionCounts {
        free,
        sil_free,
        arm_out,
        arm_feat,
        front_skin,
    } = union;

    let contour = f64::from(contour.max(1));
    let k = f64::from(step);
    // Exact: the counts are integers far below 2^53.
    let (free, sil_free, arm_out, arm_feat, front_skin) = (
        k * free as f64,
        k * sil_free as f64,
        k * arm_out as f64,
        k * arm_feat as f64,
        k * front_skin as f64,
    );
    let model_area = region.base_area + free;
    let skin_sum: f64 = skin.iter().map(SkinPair::distance).sum();
    CostTerms {
        sil: (region.xor0 + free - 2.0 * sil_free) / region.sil_norm,
        edge: f64::from(edge) / contour,
        motion: f64::from(motion) / contour,
        skin: skin_sum / shoulder_px.max(1.0),
        arm: region
            .arm
            .as_ref()
            .and_then(|a| a.feature_area)
            .map_or(0.0, |f| (f + arm_out - 2.0 * arm_feat) / region.sil_norm),
        ratio: (model_area / region.sil_area.max(1.0) - 1.0).abs(),
        cover: region
            .arm
            .as_ref()
            .and_then(|a| a.cover_area)
            .map_or(0.0, |f| (f - front_skin) / region.sil_norm),
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // test code may fail loudly
    use super::*;
    use crate::image::{stride_for, SkinPoints};
    use crate::outline::{outline_of_solid, Ellipse, Outline};
    use crate::solid::{solid_of_part, Part};
    use crate::{skeleton_from_pose, BodyModel, Camera, Pose};
    use nalgebra::Vector3;

    #[test]
    fn skin_distance_is_to_the_point_or_outside_the_box() {
        let at = |x, y| Vector2::new(x, y);
        let point = SkinPair {
            model: at(3.0, 4.0),
            image: [at(0.0, 0.0), at(0.0, 0.0)],
        };
        assert!((point.distance() - 5.0).abs() < 1e-12);
        let merged = [at(10.0, 20.0), at(30.0, 40.0)];
        let inside = SkinPair {
            model: at(15.0, 39.0),
            image: merged,
        };
        assert_eq!(inside.distance(), 0.0);
        let beside = SkinPair {
            model: at(36.0, 25.0),
            image: merged,
        };
        assert!((beside.distance() - 6.0).abs() < 1e-12);
        let corner = SkinPair {
            model: at(33.0, 44.0),
            image: merged,
        };
        assert!((corner.distance() - 5.0).abs() < 1e-12);
    }

    /// One cone of the rest pose, its scanner and its full-frame mask.
    fn upper_arm(full: &Roi) -> (Scanner, BitMask) {
        let body = BodyModel::default();
        let skel = skeleton_from_pose(&Pose::default(), &Vector3::new(0.0, 0.0, 2.0), &body);
        let camera = Camera::perspective(300.0, 99.5, 99.5).unwrap();
        let solid = solid_of_part(Part::RightUpperArm, &skel, &body);
        let piece = Scanner::new(&outline_of_solid(&solid, &camera).unwrap());
        let mut spans = RowSpans::default();
        piece.spans_into(full, &mut spans);
        let mut mask = BitMask::new(*full);
        mask.fill(&spans);
        (piece, mask)
    }

    #[test]
    fn claimed_pixels_pay_no_edge_or_motion() {
        let full = Roi::full(200, 200);
        let (piece, mask) = upper_arm(&full);
        assert!(mask.count() > 300);
        let everywhere = vec![u64::MAX; mask.words.len()];
        let no_skin = SkinPoints::default();
        let frame =
            FrameView::new(200, 200, &mask.words, &everywhere, &everywhere, no_skin).unwrap();
        let base = BitMask::new(full);
        let score = |claimed: Option<&BitMask>| {
            let region = StageRegion::new(
                &frame,
                full,
                full,
                1,
                StageMasks {
                    claimed,
                    ..StageMasks::base(&base)
                },
            );
            evaluate(&region, &[piece], &[], 60.0, &mut Scratch::default())
        };
        let open = score(None);
        assert_eq!((open.edge, open.motion, open.sil), (1.0, 1.0, 0.0));
        // The same cone claimed by the other arm: its contour collects nothing.
        let claimed = score(Some(&mask));
        assert_eq!((claimed.edge, claimed.motion, claimed.sil), (0.0, 0.0, 0.0));
    }

    #[test]
    fn the_silhouette_mismatch_is_divided_by_the_region_or_the_given_area() {
        let full = Roi::full(200, 200);
        let (piece, mask) = upper_arm(&full);
        let nothing = vec![0u64; mask.words.len()];
        let no_skin = SkinPoints::default();
        let frame = FrameView::new(200, 200, &nothing, &nothing, &nothing, no_skin).unwrap();
        let base = BitMask::new(full);
        let region = StageRegion::new(&frame, full, full, 1, StageMasks::base(&base));
        let score = |r: &StageRegion| evaluate(r, &[piece], &[], 60.0, &mut Scratch::default()).sil;
        // The cone on an empty silhouette: every pixel of it is a mismatch.
        let n = mask.count() as f64;
        assert_eq!(score(&region), n / 40_000.0);
        assert_eq!(score(&region.normalised_by(500.0)), n / 500.0);
    }

    /// Pseudo-random bits, a fixed sequence.
    fn noise(n: usize, seed: u64) -> Vec<u64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                s ^ s >> 29
            })
            .collect()
    }

    fn disc(cx: f64, cy: f64, rx: f64, ry: f64, sxy: f64) -> Scanner {
        let e = Ellipse {
            cx,
            cy,
            sxx: rx * rx,
            sxy,
            syy: ry * ry,
        };
        Scanner::new(&Outline {
            ellipses: [Some(e), None],
            quad: None,
        })
    }

    /// The union, contour and area counts of `evaluate` (Sil, Edge, Motion, Cover) against
    /// counting pixel by pixel, for overlapping pieces (inclusion-exclusion) and sampled rows.
    #[test]
    fn counts_match_pixel_by_pixel() {
        let (w, h) = (150u32, 120u32);
        let n = stride_for(w) * h as usize;
        let (sil, edge, motion) = (noise(n, 1), noise(n, 2), noise(n, 3));
        let frame = FrameView::new(w, h, &sil, &edge, &motion, SkinPoints::default()).unwrap();
        let mut base = BitMask::new(Roi::full(w, h));
        base.words.copy_from_slice(&noise(n, 4));
        let mut front = BitMask::new(Roi::full(w, h));
        front.words.copy_from_slice(&noise(n, 5));
        let roi = Roi {
            x: 5,
            y: 3,
            width: 140,
            height: 110,
        };
        let groups = [
            vec![
                disc(50.0, 40.0, 30.0, 20.0, 100.0),
                disc(70.0, 50.0, 25.0, 30.0, -200.0),
            ],
            vec![
                disc(60.0, 50.0, 40.0, 35.0, 0.0),
                disc(75.0, 60.0, 20.0, 40.0, 300.0),
                disc(55.0, 45.0, 10.0, 12.0, 0.0),
            ],
            vec![
                disc(30.0, 30.0, 10.0, 10.0, 0.0),
                disc(110.0, 90.0, 12.0, 9.0, 0.0),
            ],
        ];
        for step in [1, 2, 3] {
            let region = StageRegion::new(
                &frame,
                roi,
                roi,
                step,
                StageMasks {
                    front_skin: Some(&front),
                    ..StageMasks::base(&base)
                },
            );
            for pieces in &groups {
                let got = evaluate(&region, pieces, &[], 100.0, &mut Scratch::default());
                // Pixel by pixel over the sampled rows.
                let inside = |p: &Scanner, x: i32, y: i32| {
                    let s = p.span(y, &roi);
                    x >= s.x0 && x < s.x1
                };
                let (mut free, mut sil_free, mut front_all, mut front_under) = (0.0, 0.0, 0.0, 0.0);
                let (mut contour, mut on_edge, mut on_motion) = (0.0, 0.0, 0.0);
                let bit = |plane: &[u64], x: i32, y: i32| {
                    plane[y as usize * stride_for(w) + x as usize / 64] >> (x % 64) & 1 == 1
                };
                for y in (roi.y..roi.y + roi.height as i32).filter(|y| y % step == 0) {
                    for x in roi.x..roi.x + roi.width as i32 {
                        let in_part = pieces.iter().any(|p| inside(p, x, y));
                        if bit(&front.words, x, y) {
                            front_all += 1.0;
                            front_under += f64::from(u8::from(in_part));
                        }
                        if in_part && !bit(&base.words, x, y) {
                            free += 1.0;
                            sil_free += f64::from(u8::from(bit(&sil, x, y)));
                        }
                        for p in pieces {
                            let out = |dx: i32, dy: i32| !inside(p, x + dx, y + dy);
                            if inside(p, x, y)
                                && (out(-1, 0) || out(1, 0) || out(0, -step) || out(0, step))
                            {
                                contour += 1.0;
                                on_edge += f64::from(u8::from(bit(&edge, x, y)));
                                on_motion += f64::from(u8::from(bit(&motion, x, y)));
                            }
                        }
                    }
                }
                let k = f64::from(step);
                let want_sil = (region.xor0 + k * free - 2.0 * (k * sil_free)) / region.sil_norm;
                assert_eq!(got.sil, want_sil, "step {step}");
                assert_eq!(got.edge, on_edge / contour, "step {step}");
                assert_eq!(got.motion, on_motion / contour, "step {step}");
                let want_cover = k * (front_all - front_under) / region.sil_norm;
                assert_eq!(got.cover, want_cover, "step {step}");
                assert!(got.cover > 0.0 && got.cover < k * front_all / region.sil_norm);
            }
        }
    }
}
