//! APSOPF, the search of the thesis' baseline [2] (§4.3; SPEC 7; docs/baselines.md): an
//! annealed particle swarm inside a particle filter.
//!
//! The filter's step, as we read [2]: the particles of the new frame are the previous estimate
//! (here the prediction, i.e. resampling collapsed onto the best particle) redistributed by a
//! Gaussian, `x ~ N(prediction, (sigma * h)^2)` per dimension with `h` half the box's width,
//! then refined by the annealed swarm of [`super::apso`]. A draw outside the box is put on its
//! wall; that is the waste the thesis names as its reason to start uniformly instead. Which
//! features score the particles (silhouette and edge only) is set by the caller
//! (`super::optimizer::effective`).

use super::apso::{self, SwarmConfig, SwarmResult};
use super::rng::Rng;
use crate::pose::DofRange;
use rayon::ThreadPool;

/// The Gaussian redistribution: `particles` positions around `centre`, drawn serially.
pub fn redistribute(
    bounds: &[DofRange],
    centre: &[f64],
    sigma: f64,
    particles: usize,
    rng: &mut Rng,
) -> Vec<Vec<f64>> {
    (0..particles)
        .map(|_| {
            bounds
                .iter()
                .zip(centre)
                .map(|(b, &c)| b.clamp(c + sigma * 0.5 * (b.hi() - b.lo()) * rng.normal()))
                .collect()
        })
        .collect()
}

/// Minimises `cost` by the annealed swarm started from the Gaussian redistribution.
#[allow(clippy::too_many_arguments)] // the swarm's arguments plus sigma and the centre
pub fn minimise<F, S, I>(
    bounds: &[DofRange],
    config: &SwarmConfig,
    sigma: f64,
    centre: &[f64],
    rng: &mut Rng,
    pool: &ThreadPool,
    init: I,
    cost: F,
) -> SwarmResult
where
    S: Send,
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, &[f64]) -> f64 + Sync + Send,
{
    let seeds = redistribute(bounds, centre, sigma, config.particles.max(1), rng);
    apso::minimise(bounds, config, &seeds, rng, pool, init, cost)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::pool;
    use crate::search::test_functions::{boxes, sphere};

    fn run(seed: u64, threads: usize, sigma: f64) -> SwarmResult {
        let cfg = SwarmConfig {
            particles: 40,
            iterations: 200,
            ..SwarmConfig::default()
        };
        let mut rng = Rng::for_stage(seed, 0, 0);
        let p = pool(threads).unwrap();
        let centre = vec![-1.0; 5];
        minimise(
            &boxes(5, -5.12, 5.12),
            &cfg,
            sigma,
            &centre,
            &mut rng,
            &p,
            || (),
            |_, x| sphere(x),
        )
    }

    #[test]
    fn finds_the_sphere_minimum_for_small_and_large_sigma() {
        for sigma in [0.1, 1.0, 1.5] {
            for seed in 0..3 {
                let res = run(seed, 1, sigma);
                assert!(res.cost < 1e-3, "sigma {sigma}: {}", res.cost);
            }
        }
    }

    #[test]
    fn same_seed_same_result_whatever_the_thread_count() {
        let one = run(4, 1, 0.5);
        assert_eq!(run(4, 2, 0.5), one);
        assert_eq!(run(4, 4, 0.5), one);
        assert_ne!(run(5, 1, 0.5), one);
    }

    #[test]
    fn redistribution_spreads_with_sigma_and_stays_in_the_box() {
        let b = vec![DofRange::union(&[(0.0, 1.0), (2.0, 3.0)]).unwrap()];
        let spread = |sigma: f64| {
            let mut rng = Rng::for_stage(1, 0, 0);
            let xs = redistribute(&b, &[0.5], sigma, 2000, &mut rng);
            assert!(xs.iter().all(|x| b[0].contains(x[0])));
            xs.iter().map(|x| (x[0] - 0.5).abs()).sum::<f64>() / xs.len() as f64
        };
        // sigma 0.1 of a half-width of 1.5: mean |dx| = 0.15 sqrt(2/pi) = 0.12.
        assert!((spread(0.1) - 0.12).abs() < 0.01, "{}", spread(0.1));
        assert!(spread(1.0) > 3.0 * spread(0.1));
    }
}
