//! Rasterising the body model: one arm (two cones) into its region, and the whole body into a
//! 640x480 frame. Target (issue 2): one arm in under 1 us on one core.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // setup failures in a bench should stop it loudly

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use upperpose_bench::{arm_roi, Scene};
use upperpose_core::outline::outline_of_solid;
use upperpose_core::solid::solid_of_part;
use upperpose_core::{BitMask, BodyRaster, Part, Roi, RowSpans, Scanner};

fn bench(c: &mut Criterion) {
    let s = Scene::new();
    let skel = s.skeleton();
    let parts = Part::arm(s.side());
    let outlines = parts.map(|p| {
        outline_of_solid(&solid_of_part(p, &skel, &s.body), &s.camera)
            .unwrap_or_else(|| panic!("arm not visible"))
    });
    let scanners = outlines.map(|o| Scanner::new(&o));
    let roi = arm_roi();
    let mut spans = [RowSpans::default(), RowSpans::default()];
    let mut mask = BitMask::new(roi);

    let mut g = c.benchmark_group("arm");
    g.bench_function("project_two_cones", |b| {
        b.iter(|| {
            parts.map(|p| outline_of_solid(&solid_of_part(p, black_box(&skel), &s.body), &s.camera))
        })
    });
    g.bench_function("scan_two_cones", |b| {
        b.iter(|| {
            for (sc, out) in scanners.iter().zip(spans.iter_mut()) {
                black_box(sc).spans_into(&roi, out);
            }
        })
    });
    g.bench_function("pose_to_spans", |b| {
        b.iter(|| {
            for (p, out) in parts.iter().zip(spans.iter_mut()) {
                if let Some(o) =
                    outline_of_solid(&solid_of_part(*p, black_box(&skel), &s.body), &s.camera)
                {
                    Scanner::new(&o).spans_into(&roi, out);
                }
            }
        })
    });
    g.bench_function("pose_to_bitmask", |b| {
        b.iter(|| {
            mask.clear();
            for (p, out) in parts.iter().zip(spans.iter_mut()) {
                if let Some(o) =
                    outline_of_solid(&solid_of_part(*p, black_box(&skel), &s.body), &s.camera)
                {
                    Scanner::new(&o).spans_into(&roi, out);
                    mask.fill(out);
                }
            }
        })
    });
    g.finish();
    let pixels: u64 = spans.iter().map(RowSpans::area).sum();
    let rows: usize = spans.iter().map(|s| s.spans.len()).sum();
    eprintln!("arm scene: {pixels} pixels over {rows} rows");

    let full = Roi::full(640, 480);
    c.bench_function("body_union_640x480", |b| {
        b.iter(|| BodyRaster::new(black_box(&skel), &s.body, &s.camera, full).union())
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
