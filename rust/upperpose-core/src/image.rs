//! Borrowed views of one frame's features, in the bit-packed layout of [`crate::raster::BitMask`]:
//! `u64` words, least significant bit = leftmost pixel, `ceil(W / 64)` words per row.

use crate::error::{CoreError, Result};
use nalgebra::Vector2;

/// One binary feature image.
#[derive(Debug, Clone, Copy)]
pub struct BitPlane<'a> {
    pub words: &'a [u64],
    pub stride: usize,
}

impl BitPlane<'_> {
    /// Whether pixel `(x, y)` is set (no bounds check beyond the slice's).
    pub fn get(&self, x: usize, y: usize) -> bool {
        self.words[y * self.stride + x / 64] >> (x % 64) & 1 == 1
    }
}

/// An axis-aligned box in pixels: its least and greatest corners.
pub type PixelBox = [Vector2<f64>; 2];

/// The skin points the cost compares with the model's joints.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SkinPoints {
    /// Head, right hand, left hand in pixels; `None` when absent or merged with another blob.
    pub points: [Option<Vector2<f64>>; 3],
    /// For a part whose blob also holds another part (hand on face, hands together): the
    /// merged blob's bounding box. The blob gives no point for the part, but the part is in it.
    pub merged: [Option<PixelBox>; 3],
}

/// The features the search matches against.
#[derive(Debug, Clone, Copy)]
pub struct FrameView<'a> {
    pub width: u32,
    pub height: u32,
    /// I_sil: the silhouette.
    pub sil: BitPlane<'a>,
    /// I_edge, dilated so a one-pixel offset still counts.
    pub edge: BitPlane<'a>,
    /// I_motion, dilated likewise.
    pub motion: BitPlane<'a>,
    pub skin: SkinPoints,
    /// I_skin without the head's blob, for the Cover term (docs/cost.md); `None`: no term.
    pub skin_mask: Option<BitPlane<'a>>,
}

/// The widest image the search accepts (the cost's per-row counts are 16 bits wide).
pub const MAX_WIDTH: u32 = 65535;

/// Words per row of a bit-packed image `width` pixels wide.
pub fn stride_for(width: u32) -> usize {
    (width as usize).div_ceil(64)
}

impl<'a> FrameView<'a> {
    /// Checks that every plane holds `height` rows of `ceil(width / 64)` words. Images are at
    /// most [`MAX_WIDTH`] pixels wide: the cost counts pixels of a row in 16-bit fields.
    pub fn new(
        width: u32,
        height: u32,
        sil: &'a [u64],
        edge: &'a [u64],
        motion: &'a [u64],
        skin: SkinPoints,
    ) -> Result<Self> {
        if width == 0 || height == 0 {
            return Err(CoreError::InvalidShape {
                name: "features",
                expected: "a non-empty image".into(),
                got: format!("{width}x{height}"),
            });
        }
        if width > MAX_WIDTH {
            return Err(CoreError::InvalidShape {
                name: "features",
                expected: format!("an image at most {MAX_WIDTH} pixels wide"),
                got: format!("{width}x{height}"),
            });
        }
        let stride = stride_for(width);
        let want = stride * height as usize;
        for (name, plane) in [("sil", sil), ("edge", edge), ("motion", motion)] {
            if plane.len() != want {
                return Err(CoreError::InvalidShape {
                    name,
                    expected: format!("({height}, {stride}) words for a {width}x{height} image"),
                    got: format!("{} words", plane.len()),
                });
            }
        }
        Ok(FrameView {
            width,
            height,
            sil: BitPlane { words: sil, stride },
            edge: BitPlane {
                words: edge,
                stride,
            },
            motion: BitPlane {
                words: motion,
                stride,
            },
            skin,
            skin_mask: None,
        })
    }

    /// The same view with the skin mask the Cover term matches (same layout as the planes).
    pub fn with_skin_mask(mut self, words: &'a [u64]) -> Result<Self> {
        let stride = stride_for(self.width);
        let want = stride * self.height as usize;
        if words.len() != want {
            return Err(CoreError::InvalidShape {
                name: "skin_mask",
                expected: format!(
                    "({}, {stride}) words for a {}x{} image",
                    self.height, self.width, self.height
                ),
                got: format!("{} words", words.len()),
            });
        }
        self.skin_mask = Some(BitPlane { words, stride });
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn images_wider_than_the_counts_allow_are_rejected() {
        let w = MAX_WIDTH + 1;
        let plane = vec![0u64; stride_for(w)];
        let err = FrameView::new(w, 1, &plane, &plane, &plane, SkinPoints::default()).unwrap_err();
        assert!(
            err.to_string().contains("at most 65535 pixels wide"),
            "{err}"
        );
        let plane = vec![0u64; stride_for(MAX_WIDTH)];
        assert!(
            FrameView::new(MAX_WIDTH, 1, &plane, &plane, &plane, SkinPoints::default()).is_ok()
        );
    }

    #[test]
    fn a_skin_mask_of_another_size_is_rejected() {
        let plane = vec![0u64; stride_for(100) * 10];
        let view = FrameView::new(100, 10, &plane, &plane, &plane, SkinPoints::default()).unwrap();
        assert!(view.with_skin_mask(&plane).unwrap().skin_mask.is_some());
        let err = view.with_skin_mask(&plane[1..]).unwrap_err();
        assert!(err.to_string().contains("skin_mask"), "{err}");
    }
}
