//! Standard optimisation test functions for the optimisers' unit tests.

use crate::pose::DofRange;

/// Sphere with its minimum 0 at 0.3 in every dimension.
pub fn sphere(x: &[f64]) -> f64 {
    x.iter().map(|v| (v - 0.3) * (v - 0.3)).sum()
}

/// Rastrigin: global minimum 0 at the origin, a local minimum near every integer point.
pub fn rastrigin(x: &[f64]) -> f64 {
    10.0 * x.len() as f64
        + x.iter()
            .map(|v| v * v - 10.0 * (2.0 * std::f64::consts::PI * v).cos())
            .sum::<f64>()
}

/// The box `[lo, hi]^d`.
pub fn boxes(d: usize, lo: f64, hi: f64) -> Vec<DofRange> {
    (0..d).map(|_| DofRange::new(lo, hi).unwrap()).collect()
}
