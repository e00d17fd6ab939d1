//! The search: cost evaluations per second for one arm and for the torso, and one whole
//! frame's hierarchical fit at default settings. Targets (issue 5): >= 500,000 arm evaluations
//! per second per core; a whole frame's fit (every part searched) in <= 10 ms on 2 cores.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // setup failures in a bench should stop it loudly

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use upperpose_bench::{fit_request, ideal_features, Scene};
use upperpose_core::search::{fit_frame, SearchConfig};

fn bench(c: &mut Criterion) {
    let s = Scene::new();
    let f = ideal_features(&s);
    let frame = f.view();
    let req = |search: [bool; 3]| fit_request(&s, frame, search);

    // Evaluations per second: one stage searched on one thread, divided by its evaluations.
    let one_thread = SearchConfig {
        threads: Some(1),
        ..SearchConfig::default()
    };
    let mut g = c.benchmark_group("stage_1_thread");
    for (name, flags) in [
        ("torso", [true, false, false]),
        ("right_arm", [false, true, false]),
    ] {
        let n = fit_frame(&req(flags), &one_thread).unwrap().evaluations as u64;
        g.throughput(Throughput::Elements(n));
        g.bench_function(name, |b| {
            b.iter(|| fit_frame(black_box(&req(flags)), &one_thread).unwrap())
        });
    }
    g.finish();

    let mut g = c.benchmark_group("frame_fit");
    g.throughput(Throughput::Elements(1));
    for threads in [1usize, 2] {
        let config = SearchConfig {
            threads: Some(threads),
            ..SearchConfig::default()
        };
        g.bench_with_input(BenchmarkId::new("all_parts", threads), &config, |b, cfg| {
            b.iter(|| fit_frame(black_box(&req([true; 3])), cfg).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
