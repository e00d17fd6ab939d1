//! Downhill simplex (Nelder-Mead), the search of the thesis' baseline [1] (§4.3; SPEC 7;
//! docs/baselines.md).
//!
//! The textbook method (reflection 1, expansion 2, contraction 1/2, shrink 1/2) started from
//! the prediction, with one more vertex per dimension a quarter of the box's width away,
//! towards the roomier side. Every trial point is projected onto the box (onto the nearer wall
//! of a gap between two intervals), so no point outside the constraints is ever scored.
//! Dimensions whose range is a single value (the straight elbows of [1]) are not searched.
//! It stops when the vertices agree in cost and position, or when the evaluation budget is
//! spent. No random numbers and one evaluation at a time: the result cannot depend on threads.

use super::apso::SwarmResult;
use crate::pose::DofRange;

/// Settings of one simplex search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimplexConfig {
    /// Most cost evaluations.
    pub max_evaluations: usize,
    /// Edge of the starting simplex as a fraction of each dimension's width.
    pub initial_step: f64,
    /// Converged when every vertex is within this of the best (per coordinate) ...
    pub x_tolerance: f64,
    /// ... and within this of its cost.
    pub f_tolerance: f64,
}

impl Default for SimplexConfig {
    fn default() -> Self {
        SimplexConfig {
            max_evaluations: 400,
            initial_step: 0.25,
            x_tolerance: 1e-4,
            f_tolerance: 1e-6,
        }
    }
}

/// Minimises `cost` over the box from `start`.
pub fn minimise<F, S, I>(
    bounds: &[DofRange],
    start: &[f64],
    config: &SimplexConfig,
    init: I,
    cost: F,
) -> SwarmResult
where
    I: Fn() -> S,
    F: Fn(&mut S, &[f64]) -> f64,
{
    let mut scratch = init();
    let origin: Vec<f64> = bounds.iter().zip(start).map(|(b, &s)| b.clamp(s)).collect();
    let free: Vec<usize> = (0..bounds.len())
        .filter(|&k| bounds[k].hi() > bounds[k].lo())
        .collect();
    let budget = config.max_evaluations.max(1);
    let mut evaluations = 0;
    // The full point of a vertex in the free coordinates, projected onto the box.
    let place = |y: &[f64]| -> Vec<f64> {
        let mut x = origin.clone();
        for (&k, &v) in free.iter().zip(y) {
            x[k] = bounds[k].clamp(v);
        }
        x
    };
    let mut score = |y: &[f64], evaluations: &mut usize| -> (Vec<f64>, f64) {
        let y: Vec<f64> = {
            let x = place(y);
            free.iter().map(|&k| x[k]).collect()
        };
        *evaluations += 1;
        let c = cost(&mut scratch, &place(&y));
        (y, c)
    };

    let y0: Vec<f64> = free.iter().map(|&k| origin[k]).collect();
    let mut verts = vec![score(&y0, &mut evaluations)];
    for (j, &k) in free.iter().enumerate() {
        if evaluations >= budget {
            break;
        }
        let (lo, hi) = (bounds[k].lo(), bounds[k].hi());
        let step = config.initial_step * (hi - lo);
        let mut y = y0.clone();
        y[j] += if hi - y0[j] >= y0[j] - lo {
            step
        } else {
            -step
        };
        verts.push(score(&y, &mut evaluations));
    }

    let n = free.len();
    while n > 0 && verts.len() == n + 1 && evaluations < budget {
        // Stable sort, ties keep their order: deterministic.
        verts.sort_by(|a, b| a.1.total_cmp(&b.1));
        let (best, worst) = (verts[0].1, verts[n].1);
        let x_spread = verts[1..]
            .iter()
            .flat_map(|v| v.0.iter().zip(&verts[0].0).map(|(a, b)| (a - b).abs()))
            .fold(0.0, f64::max);
        if (worst - best).abs() <= config.f_tolerance && x_spread <= config.x_tolerance {
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|j| verts[..n].iter().map(|v| v.0[j]).sum::<f64>() / n as f64)
            .collect();
        let towards = |t: f64, p: &[f64]| -> Vec<f64> {
            centroid
                .iter()
                .zip(p)
                .map(|(c, x)| c + t * (x - c))
                .collect()
        };
        let reflected = score(&towards(-1.0, &verts[n].0), &mut evaluations);
        if reflected.1 < best {
            if evaluations >= budget {
                verts[n] = reflected;
                break;
            }
            let expanded = score(&towards(-2.0, &verts[n].0), &mut evaluations);
            verts[n] = if expanded.1 < reflected.1 {
                expanded
            } else {
                reflected
            };
            continue;
        }
        if reflected.1 < verts[n - 1].1 {
            verts[n] = reflected;
            continue;
        }
        if evaluations >= budget {
            break;
        }
        // Contract outside (towards the reflection) or inside (towards the worst vertex).
        let (contracted, accept) = if reflected.1 < worst {
            let c = score(&towards(-0.5, &verts[n].0), &mut evaluations);
            let ok = c.1 <= reflected.1;
            (c, ok)
        } else {
            let c = score(&towards(0.5, &verts[n].0), &mut evaluations);
            let ok = c.1 < worst;
            (c, ok)
        };
        if accept {
            verts[n] = contracted;
            continue;
        }
        // Shrink every vertex halfway towards the best.
        for i in 1..=n {
            if evaluations >= budget {
                break;
            }
            let y: Vec<f64> = verts[0]
                .0
                .iter()
                .zip(&verts[i].0)
                .map(|(b, x)| b + 0.5 * (x - b))
                .collect();
            verts[i] = score(&y, &mut evaluations);
        }
    }
    let best = verts
        .iter()
        .enumerate()
        .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1).then(a.0.cmp(&b.0)))
        .map(|(_, v)| v.clone())
        .unwrap_or_else(|| (y0.clone(), f64::INFINITY));
    SwarmResult {
        best: place(&best.0),
        cost: best.1,
        evaluations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::search::test_functions::{boxes, rastrigin, sphere};
    use proptest::prelude::*;

    fn run(bounds: &[DofRange], start: &[f64], budget: usize, f: fn(&[f64]) -> f64) -> SwarmResult {
        let cfg = SimplexConfig {
            max_evaluations: budget,
            ..SimplexConfig::default()
        };
        minimise(bounds, start, &cfg, || (), |_, x| f(x))
    }

    #[test]
    fn finds_the_sphere_minimum_in_4_and_13_dimensions() {
        for (d, budget) in [(4, 2000), (13, 20000)] {
            let res = run(&boxes(d, -5.12, 5.12), &vec![-2.0; d], budget, sphere);
            assert!(res.cost < 1e-6, "d={d}: {}", res.cost);
            assert!(res.evaluations <= budget);
        }
    }

    #[test]
    fn rastrigin_from_its_basin_reaches_the_global_minimum() {
        // A local method: it finds the minimum of the cell it starts in (the global one here)
        // and, started elsewhere, ends in some other local minimum.
        let b = boxes(5, -5.12, 5.12);
        let res = run(&b, &[0.3, -0.2, 0.1, 0.25, -0.3], 5000, rastrigin);
        assert!(res.cost < 1e-6, "{}", res.cost);
        let far = run(&b, &[3.1; 5], 5000, rastrigin);
        assert!(far.cost > 1.0 && far.cost.is_finite(), "{}", far.cost);
    }

    #[test]
    fn a_single_valued_range_is_held_fixed() {
        let mut b = boxes(3, -1.0, 1.0);
        b[1] = DofRange::new(0.0, 0.0).unwrap();
        let res = run(&b, &[0.9, 0.0, -0.9], 2000, sphere);
        assert_eq!(res.best[1], 0.0);
        assert!((res.best[0] - 0.3).abs() < 1e-3 && (res.best[2] - 0.3).abs() < 1e-3);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, failure_persistence: None, ..ProptestConfig::default() })]
        #[test]
        fn every_scored_point_respects_the_constraints(
            start in proptest::collection::vec(-4.0..4.0f64, 3),
            target in proptest::collection::vec(-4.0..4.0f64, 3),
            budget in 1usize..300,
        ) {
            let b = vec![
                DofRange::union(&[(-3.0, -1.0), (1.0, 3.0)]).unwrap(),
                DofRange::new(-0.5, 2.0).unwrap(),
                DofRange::new(0.0, 0.0).unwrap(),
            ];
            let seen = std::cell::RefCell::new(Vec::new());
            let res = minimise(&b, &start, &SimplexConfig { max_evaluations: budget, ..SimplexConfig::default() }, || (), |_, x| {
                seen.borrow_mut().push(x.to_vec());
                x.iter().zip(&target).map(|(a, t)| (a - t).abs()).sum()
            });
            let seen = seen.into_inner();
            prop_assert!(seen.len() <= budget && res.evaluations == seen.len());
            for x in seen.iter().chain(std::iter::once(&res.best)) {
                prop_assert!(x.iter().zip(&b).all(|(v, r)| r.contains(*v)), "{:?}", x);
            }
        }
    }
}
