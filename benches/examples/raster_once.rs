//! Rasterises the bench scene's arm (pose -> spans, as `raster` `arm/pose_to_spans`) `reps`
//! times, for counting instructions with callgrind:
//!
//!     cargo build --release -p upperpose-bench --example raster_once
//!     valgrind --tool=callgrind target/release/examples/raster_once 1000
//!
//! The difference between two runs with different `reps` removes the set-up.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // a profiling aid: fail loudly

use std::hint::black_box;
use upperpose_bench::{arm_roi, Scene};
use upperpose_core::outline::outline_of_solid;
use upperpose_core::solid::solid_of_part;
use upperpose_core::{Part, RowSpans, Scanner};

fn main() {
    let reps: usize = std::env::args()
        .nth(1)
        .map_or(1, |s| s.parse().expect("reps"));
    let s = Scene::new();
    let skel = s.skeleton();
    let parts = Part::arm(s.side());
    let roi = arm_roi();
    let mut spans = [RowSpans::default(), RowSpans::default()];
    for _ in 0..reps {
        for (p, out) in parts.iter().zip(spans.iter_mut()) {
            if let Some(o) =
                outline_of_solid(&solid_of_part(*p, black_box(&skel), &s.body), &s.camera)
            {
                Scanner::new(&o).spans_into(&roi, out);
            }
        }
    }
    let pixels: u64 = spans.iter().map(RowSpans::area).sum();
    println!("pixels {pixels}");
}
