//! The posed body rasterised inside a region: per-part silhouettes, the combined silhouette in
//! which nearer parts occlude farther ones, and one-pixel contours of what is visible.

use crate::body::BodyModel;
use crate::camera::Camera;
use crate::kinematics::Skeleton;
use crate::outline::outline_of_solid;
use crate::raster::{BitMask, Roi, RowSpans, Scanner};
use crate::solid::{solid_of_part, Part, PART_COUNT};

/// The body's parts prepared for rasterisation inside one region.
#[derive(Debug, Clone)]
pub struct BodyRaster {
    pub roi: Roi,
    /// `None` for a part a perspective camera cannot see whole (too near or behind it).
    scanners: [Option<Scanner>; PART_COUNT],
    /// Part indices from nearest to farthest (painter's order by the depth of each solid's
    /// centre: exact for parts that do not overlap in depth, an approximation where they do).
    order: [usize; PART_COUNT],
}

impl BodyRaster {
    /// Projects every part of the posed body.
    pub fn new(skel: &Skeleton, body: &BodyModel, camera: &Camera, roi: Roi) -> Self {
        let solids = Part::ALL.map(|p| solid_of_part(p, skel, body));
        let scanners = solids.map(|s| outline_of_solid(&s, camera).map(|o| Scanner::new(&o)));
        let mut order: [usize; PART_COUNT] = std::array::from_fn(|i| i);
        order.sort_by(|&a, &b| solids[a].centre().z.total_cmp(&solids[b].centre().z));
        BodyRaster {
            roi,
            scanners,
            order,
        }
    }

    /// The part's scanner, if the camera sees it.
    pub fn scanner(&self, part: Part) -> Option<&Scanner> {
        self.scanners[part as usize].as_ref()
    }

    /// The part's row spans inside the region (empty when unseen).
    pub fn spans(&self, part: Part) -> RowSpans {
        let mut out = RowSpans::default();
        if let Some(s) = self.scanner(part) {
            s.spans_into(&self.roi, &mut out);
        }
        out
    }

    /// The part's whole silhouette, ignoring occlusion.
    pub fn silhouette(&self, part: Part) -> BitMask {
        let mut m = BitMask::new(self.roi);
        m.fill(&self.spans(part));
        m
    }

    /// The visible silhouettes of all parts (nearer parts cut out of farther ones), in part order.
    pub fn visible(&self) -> Vec<BitMask> {
        let mut covered = BitMask::new(self.roi);
        let mut out = vec![BitMask::new(self.roi); PART_COUNT];
        for &i in &self.order {
            let mut m = self.silhouette(Part::ALL[i]);
            m.subtract(&covered);
            covered.union(&self.silhouette(Part::ALL[i]));
            out[i] = m;
        }
        out
    }

    /// Part labels, one byte per pixel of the region, row-major: 0 for no part, `k + 1` where
    /// part `k` is the nearest covering the pixel (the labels of [`Self::visible`]). Painted
    /// from the farthest part to the nearest straight from the spans: no masks are built.
    pub fn labels(&self) -> Vec<u8> {
        let width = self.roi.width as usize;
        let mut labels = vec![0u8; width * self.roi.height as usize];
        for &i in self.order.iter().rev() {
            let spans = self.spans(Part::ALL[i]);
            for (r, span) in spans.spans.iter().enumerate() {
                if span.is_empty() {
                    continue;
                }
                let row = (spans.y(r) - self.roi.y) as usize * width;
                let (x0, x1) = (
                    (span.x0 - self.roi.x) as usize,
                    (span.x1 - self.roi.x) as usize,
                );
                labels[row + x0..row + x1].fill(i as u8 + 1);
            }
        }
        labels
    }

    /// The visible one-pixel contours of all parts, in part order: the part's own contour where
    /// no nearer part hides it.
    pub fn contours(&self) -> Vec<BitMask> {
        self.visible()
            .into_iter()
            .zip(Part::ALL)
            .map(|(mut vis, part)| {
                let mut c = BitMask::new(self.roi);
                if let Some(s) = self.scanner(part) {
                    s.contour_into(&mut c);
                }
                // Keep contour pixels that are visible: vis & c.
                for (a, b) in vis.words.iter_mut().zip(&c.words) {
                    *a &= b;
                }
                vis
            })
            .collect()
    }

    /// The combined silhouette: the union of all parts.
    pub fn union(&self) -> BitMask {
        let mut m = BitMask::new(self.roi);
        for part in Part::ALL {
            m.fill(&self.spans(part));
        }
        m
    }
}
