//! Which method searches a stage: our APSO or one of the baselines the thesis compares with
//! (§4.2-4.3; SPEC 7; docs/baselines.md). All share the body model, the features, the
//! constraints, the boxes and the output; they differ in the search and, for the baselines,
//! in what their sources fix: [1] keeps the elbows straight, [2] scores silhouette and edge only.

use std::borrow::Cow;

use super::apso::{self, SwarmConfig, SwarmResult};
use super::rng::Rng;
use super::simplex::{self, SimplexConfig};
use super::{apsopf, SearchConfig};
use crate::pose::{Dof, DofRange, JointLimits};
use rayon::ThreadPool;

/// The search method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Optimizer {
    /// Annealed particle swarm (thesis §3.1.2): ours.
    #[default]
    Apso,
    /// The same swarm without annealing (coefficients held at their mid value).
    Pso,
    /// Downhill simplex with straight arms, as in [1].
    Simplex,
    /// Annealed swarm inside a particle filter, Gaussian redistribution, silhouette and edge
    /// only, as in [2].
    Apsopf,
}

impl Optimizer {
    pub const ALL: [Optimizer; 4] = [
        Optimizer::Apso,
        Optimizer::Pso,
        Optimizer::Simplex,
        Optimizer::Apsopf,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Optimizer::Apso => "apso",
            Optimizer::Pso => "pso",
            Optimizer::Simplex => "simplex",
            Optimizer::Apsopf => "apsopf",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|o| o.name() == name)
    }
}

/// The limits with both elbows held straight (x_down = 0), as [1] assumes.
fn straight_arms(limits: &JointLimits) -> JointLimits {
    let ranges = Dof::ALL
        .iter()
        .map(|&d| match d {
            Dof::RightXDown | Dof::LeftXDown => {
                DofRange::new(0.0, 0.0).unwrap_or_else(|_| limits.range(d).clone())
            }
            _ => limits.range(d).clone(),
        })
        .collect();
    JointLimits::new(ranges).unwrap_or_else(|_| limits.clone())
}

/// The settings the method really runs with: [1] with straight elbows, [2] with the
/// silhouette and edge terms only (and none of our priors). APSO and PSO run `config` as it is.
pub fn effective(config: &SearchConfig) -> Cow<'_, SearchConfig> {
    match config.optimizer {
        Optimizer::Apso | Optimizer::Pso => Cow::Borrowed(config),
        Optimizer::Simplex => Cow::Owned(SearchConfig {
            limits: straight_arms(&config.limits),
            ..config.clone()
        }),
        Optimizer::Apsopf => {
            let w = config.weights;
            let mut c = config.clone();
            c.weights = super::cost::CostWeights {
                sil: w.sil,
                edge: w.edge,
                motion: 0.0,
                skin: 0.0,
                arm: 0.0,
                ratio: 0.0,
                cover: 0.0,
            };
            c.behind_weight = 0.0;
            c.turn_weight = 0.0;
            c.lean_weight = 0.0;
            c.rotation_weight = 0.0;
            Cow::Owned(c)
        }
    }
}

/// Minimises one stage's cost over `bounds` with the configured method. `start` is the
/// prediction; every method gets the budget of the swarm, `particles x (iterations + 1)`
/// evaluations (the simplex may stop earlier).
#[allow(clippy::too_many_arguments)] // the swarm's own arguments
pub fn minimise<F, S, I>(
    config: &SearchConfig,
    bounds: &[DofRange],
    start: &[f64],
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
    let swarm = &config.swarm;
    let seeds = [start.to_vec()];
    match config.optimizer {
        Optimizer::Apso => apso::minimise(bounds, swarm, &seeds, rng, pool, init, cost),
        Optimizer::Pso => {
            let plain = SwarmConfig {
                annealing: false,
                ..*swarm
            };
            apso::minimise(bounds, &plain, &seeds, rng, pool, init, cost)
        }
        Optimizer::Simplex => {
            let sc = SimplexConfig {
                max_evaluations: swarm.particles.max(1) * (swarm.iterations + 1),
                ..SimplexConfig::default()
            };
            simplex::minimise(bounds, start, &sc, init, cost)
        }
        Optimizer::Apsopf => {
            apsopf::minimise(bounds, swarm, config.sigma, start, rng, pool, init, cost)
        }
    }
}
