//! Fits the bench scene `reps` times, for profiling with callgrind:
//!
//!     cargo build --release -p upperpose-bench --example fit_once
//!     valgrind --tool=callgrind target/release/examples/fit_once right_arm 10
//!
//! Stages: `torso`, `right_arm`, `all` (every part, at default settings). Prints the
//! evaluations per frame so instruction counts can be divided by them. The difference between
//! two runs with different `reps` removes the set-up from a per-frame count.

#![allow(clippy::panic, clippy::unwrap_used, clippy::expect_used)] // a profiling aid: fail loudly

use upperpose_bench::{fit_request, ideal_features, Scene};
use upperpose_core::search::{fit_frame, SearchConfig};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let stage = args.get(1).map_or("all", String::as_str);
    let reps: usize = args.get(2).map_or(1, |s| s.parse().expect("reps"));
    let threads: usize = args.get(3).map_or(1, |s| s.parse().expect("threads"));
    let search = match stage {
        "torso" => [true, false, false],
        "right_arm" => [false, true, false],
        "all" => [true; 3],
        other => panic!("unknown stage {other}: torso, right_arm or all"),
    };
    let s = Scene::new();
    let f = ideal_features(&s);
    let req = fit_request(&s, f.view(), search); // the same request as benches/search.rs
    let config = SearchConfig {
        threads: Some(threads),
        ..SearchConfig::default()
    };
    let mut last = None;
    for _ in 0..reps {
        last = Some(fit_frame(&req, &config).unwrap());
    }
    if let Some(fit) = last {
        println!("evaluations {} cost {:.17e}", fit.evaluations, fit.cost);
        println!("pose {:?}", fit.pose.0);
    }
}
