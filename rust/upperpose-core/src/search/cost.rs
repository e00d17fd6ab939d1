//! The cost of a candidate part against one frame (thesis Eq. 3.4.8-2; SPEC 5; docs/cost.md):
//!
//! `cost = w_sil Sil - w_edge Edge - w_motion Motion + w_skin Skin + w_arm Arm + w_ratio Ratio`
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

use crate::image::{BitPlane, FrameView};
use crate::raster::{BitMask, Roi, RowSpans, Scanner, Span};
use nalgebra::Vector2;

/// Weights of the six terms (thesis: 3, 20, 15, 250, 4, 400 for its own normalisations).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CostWeights {
    pub sil: f64,
    pub edge: f64,
    pub motion: f64,
    pub skin: f64,
    pub arm: f64,
    pub ratio: f64,
}

impl Default for CostWeights {
    /// Chosen on the development set (docs/cost.md). The Arm term is off: with the base
    /// drawn in, Sil already scores the arm against the silhouette outside the torso, and
    /// counting it twice made fits worse (3.51 against 3.38 px) and slower.
    fn default() -> Self {
        CostWeights {
            sil: 20.0,
            edge: 2.0,
            motion: 0.5,
            skin: 1.5,
            arm: 0.0,
            ratio: 0.5,
        }
    }
}

/// The six terms for one part, each normalised (ranges in docs/cost.md).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CostTerms {
    /// `|sil ^ model| / |R|`, in [0, 1].
    pub sil: f64,
    /// Share of the part's contour on (dilated) edge pixels, in [0, 1].
    pub edge: f64,
    /// Share of the part's contour on (dilated) motion pixels, in [0, 1].
    pub motion: f64,
    /// Summed distance of matched skin points to their joints / shoulder width, >= 0.
    pub skin: f64,
    /// `|arm_sil ^ (part & !torso)| / |R|` for arms (0 for the torso), in [0, 1].
    pub arm: f64,
    /// `| |model & R| / |sil & R| - 1 |`, >= 0.
    pub ratio: f64,
}

impl CostTerms {
    /// The weighted cost; lower is better. Not bounded below by zero.
    pub fn total(&self, w: &CostWeights) -> f64 {
        w.sil * self.sil - w.edge * self.edge - w.motion * self.motion
            + w.skin * self.skin
            + w.arm * self.arm
            + w.ratio * self.ratio
    }
}

/// Pixels of `plane` in columns `x0..x1` of row `y` (image coordinates inside the plane).
#[inline]
fn count_run(words: &[u64], stride: usize, y: i32, x0: i32, x1: i32) -> u32 {
    if x0 >= x1 {
        return 0;
    }
    let base = y as usize * stride;
    let (x0, x1) = (x0 as usize, x1 as usize - 1);
    let (w0, w1) = (x0 >> 6, x1 >> 6);
    let head = u64::MAX << (x0 & 63);
    let tail = u64::MAX >> (63 - (x1 & 63));
    if w0 == w1 {
        return (words[base + w0] & head & tail).count_ones();
    }
    let mut c = (words[base + w0] & head).count_ones() + (words[base + w1] & tail).count_ones();
    for w in &words[base + w0 + 1..base + w1] {
        c += w.count_ones();
    }
    c
}

/// What an arm stage matches besides the silhouette: the arm silhouette (silhouette outside
/// the torso region, thesis 3.4.5) against the part outside that region.
#[derive(Debug, Clone)]
struct ArmPlanes {
    /// `R & !torso`.
    outside: Vec<u64>,
    /// `R & !torso & sil`: the arm silhouette.
    feature: Vec<u64>,
    feature_area: f64,
}

/// Everything about one stage's region that does not depend on the candidate.
#[derive(Debug, Clone)]
pub struct StageRegion {
    pub roi: Roi,
    stride: usize,
    /// `R & !base`.
    free: Vec<u64>,
    /// `R & !base & sil`.
    sil_free: Vec<u64>,
    arm: Option<ArmPlanes>,
    area: f64,
    sil_area: f64,
    /// `|(sil ^ base) & R|`.
    xor0: f64,
    /// `|base & R|`.
    base_area: f64,
    /// Whether any motion lies in the region: without it the Motion term is 0 and skipped.
    has_motion: bool,
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

impl StageRegion {
    /// Prepares a stage: `base` is a full-frame mask of the rest of the body; `torso` (for arm
    /// stages whose Arm term is weighed) a full-frame mask of the fitted torso, neck and head.
    pub fn new(frame: &FrameView, roi: Roi, base: &BitMask, torso: Option<&BitMask>) -> Self {
        let r = region_mask(frame.width, frame.height, roi);
        let sil = frame.sil.words;
        let zip = |f: &dyn Fn(usize) -> u64| -> Vec<u64> { (0..r.words.len()).map(f).collect() };
        let free = zip(&|i| r.words[i] & !base.words[i]);
        let sil_free = zip(&|i| free[i] & sil[i]);
        let xor = zip(&|i| r.words[i] & (sil[i] ^ base.words[i]));
        let base_in = zip(&|i| r.words[i] & base.words[i]);
        let sil_in = zip(&|i| r.words[i] & sil[i]);
        let arm = torso.map(|t| {
            let outside = zip(&|i| r.words[i] & !t.words[i]);
            let feature = zip(&|i| outside[i] & sil[i]);
            let feature_area = count(&feature);
            ArmPlanes {
                outside,
                feature,
                feature_area,
            }
        });
        let has_motion = r
            .words
            .iter()
            .zip(frame.motion.words)
            .any(|(a, b)| a & b != 0);
        StageRegion {
            roi,
            has_motion,
            stride: r.stride,
            area: f64::from(roi.width) * f64::from(roi.height),
            sil_area: count(&sil_in),
            xor0: count(&xor),
            base_area: count(&base_in),
            free,
            sil_free,
            arm,
        }
    }
}

/// Reusable buffers of one evaluating thread.
#[derive(Debug, Default)]
pub struct Scratch {
    spans: Vec<RowSpans>,
}

/// A skin point of the image and the model joint it should lie on, both in pixels.
#[derive(Debug, Clone, Copy)]
pub struct SkinPair {
    pub model: Vector2<f64>,
    pub image: Vector2<f64>,
}

/// Scores a candidate part, given as the scanners of its convex pieces.
///
/// Only every `row_step`-th image row is rasterised and counted (rows on a grid shared by all
/// pieces); area counts are scaled back by `row_step`, and a contour row's neighbours are the
/// sampled rows above and below. `row_step = 1` is the exact cost.
pub fn evaluate(
    region: &StageRegion,
    frame: &FrameView,
    pieces: &[Scanner],
    skin: &[SkinPair],
    shoulder_px: f64,
    row_step: i32,
    scratch: &mut Scratch,
) -> CostTerms {
    if scratch.spans.len() < pieces.len() {
        scratch.spans.resize_with(pieces.len(), RowSpans::default);
    }
    let step = row_step.max(1);
    let spans = &mut scratch.spans[..pieces.len()];
    for (s, out) in pieces.iter().zip(spans.iter_mut()) {
        s.sampled_spans_into(&region.roi, step, out);
    }
    let stride = region.stride;

    // Area terms over the union of the pieces, row by row.
    let (mut free, mut sil_free, mut arm_out, mut arm_feat) = (0u32, 0u32, 0u32, 0u32);
    let first = spans
        .iter()
        .filter(|s| !s.spans.is_empty())
        .map(|s| s.y0)
        .min()
        .unwrap_or(0);
    let end = spans.iter().map(|s| s.y(s.spans.len())).max().unwrap_or(0);
    let mut row: [Span; 4] = [Span::EMPTY; 4];
    for y in (first..end).step_by(step as usize) {
        let mut n = 0;
        for s in spans.iter() {
            let sp = s.row(y);
            if !sp.is_empty() && n < row.len() {
                // Insertion by x0 keeps the (at most four) runs sorted.
                let mut k = n;
                while k > 0 && row[k - 1].x0 > sp.x0 {
                    row[k] = row[k - 1];
                    k -= 1;
                }
                row[k] = sp;
                n += 1;
            }
        }
        let runs = &row[..n];
        let mut i = 0;
        while i < runs.len() {
            let mut run = runs[i];
            while i + 1 < runs.len() && runs[i + 1].x0 <= run.x1 {
                i += 1;
                run.x1 = run.x1.max(runs[i].x1);
            }
            free += count_run(&region.free, stride, y, run.x0, run.x1);
            sil_free += count_run(&region.sil_free, stride, y, run.x0, run.x1);
            if let Some(a) = &region.arm {
                arm_out += count_run(&a.outside, stride, y, run.x0, run.x1);
                arm_feat += count_run(&a.feature, stride, y, run.x0, run.x1);
            }
            i += 1;
        }
    }

    // Edge and motion under each piece's one-pixel contour.
    let (mut contour, mut edge, mut motion) = (0u32, 0u32, 0u32);
    for s in spans.iter() {
        for (i, c) in s.spans.iter().enumerate() {
            if c.is_empty() {
                continue;
            }
            let up = if i > 0 { s.spans[i - 1] } else { Span::EMPTY };
            let down = s.spans.get(i + 1).copied().unwrap_or(Span::EMPTY);
            let in0 = (c.x0 + 1).max(up.x0).max(down.x0);
            let in1 = (c.x1 - 1).min(up.x1).min(down.x1);
            let y = s.y(i);
            let add =
                |a: i32, b: i32, plane: &BitPlane| count_run(plane.words, plane.stride, y, a, b);
            let runs = if up.is_empty() || down.is_empty() || in0 >= in1 {
                [(c.x0, c.x1), (0, 0)]
            } else {
                [(c.x0, in0), (in1, c.x1)]
            };
            for (a, b) in runs {
                if a < b {
                    contour += (b - a) as u32;
                    edge += add(a, b, &frame.edge);
                    if region.has_motion {
                        motion += add(a, b, &frame.motion);
                    }
                }
            }
        }
    }

    let contour = f64::from(contour.max(1));
    let k = f64::from(step);
    let (free, sil_free, arm_out, arm_feat) = (
        k * f64::from(free),
        k * f64::from(sil_free),
        k * f64::from(arm_out),
        k * f64::from(arm_feat),
    );
    let model_area = region.base_area + free;
    let skin_sum: f64 = skin.iter().map(|p| (p.model - p.image).norm()).sum();
    CostTerms {
        sil: (region.xor0 + free - 2.0 * sil_free) / region.area,
        edge: f64::from(edge) / contour,
        motion: f64::from(motion) / contour,
        skin: skin_sum / shoulder_px.max(1.0),
        arm: region.arm.as_ref().map_or(0.0, |a| {
            (a.feature_area + arm_out - 2.0 * arm_feat) / region.area
        }),
        ratio: (model_area / region.sil_area.max(1.0) - 1.0).abs(),
    }
}
