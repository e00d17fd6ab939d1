//! Forward kinematics of one pose.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // setup failures in a bench should stop it loudly

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use upperpose_bench::Scene;
use upperpose_core::skeleton_from_pose;

fn bench(c: &mut Criterion) {
    let s = Scene::new();
    c.bench_function("forward_kinematics", |b| {
        b.iter(|| skeleton_from_pose(black_box(&s.pose), black_box(&s.root), black_box(&s.body)))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
