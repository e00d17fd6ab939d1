//! Thread pools for the parallel evaluation of particles. One named pool per thread count,
//! built on first use and kept: building a pool every frame would cost more than a search.

use crate::error::{CoreError, Result};
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Environment variable giving the default thread count.
pub const THREADS_ENV: &str = "UPPERPOSE_NUM_THREADS";

/// Particles per worker thread by default. Handing a swarm iteration to the pool and waiting
/// for it costs thread wake-ups, which outweigh the split below about this many particles
/// (measured in docs/search.md, "Parallel and deterministic").
pub const PARTICLES_PER_THREAD: usize = 64;

/// The thread count to use: `requested`, else `UPPERPOSE_NUM_THREADS`, else one thread per
/// [`PARTICLES_PER_THREAD`] particles, at most one per core.
pub fn resolve_threads(requested: Option<usize>, particles: usize) -> Result<usize> {
    if let Some(n) = requested {
        if n == 0 {
            return Err(CoreError::OutOfRange {
                name: "threads",
                expected: ">= 1",
                value: 0.0,
            });
        }
        return Ok(n);
    }
    if let Ok(text) = std::env::var(THREADS_ENV) {
        return match text.trim().parse::<usize>() {
            Ok(n) if n > 0 => Ok(n),
            _ => Err(CoreError::BadSetting {
                name: THREADS_ENV,
                expected: "a positive whole number",
                got: format!("{text:?}"),
            }),
        };
    }
    let cores = std::thread::available_parallelism()
        .map(usize::from)
        .unwrap_or(1);
    Ok(particles.div_ceil(PARTICLES_PER_THREAD).clamp(1, cores))
}

/// The shared pool with `threads` workers.
pub fn pool(threads: usize) -> Result<Arc<ThreadPool>> {
    static POOLS: OnceLock<Mutex<HashMap<usize, Arc<ThreadPool>>>> = OnceLock::new();
    let pools = POOLS.get_or_init(|| Mutex::new(HashMap::new()));
    // A poisoned lock only means another thread panicked while inserting; the map is intact.
    let mut map = pools.lock().unwrap_or_else(|e| e.into_inner());
    if let Some(p) = map.get(&threads) {
        return Ok(Arc::clone(p));
    }
    let built = ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("upperpose-{i}"))
        .build()
        .map_err(|e| CoreError::BadSetting {
            name: "thread pool",
            expected: "able to start",
            got: e.to_string(),
        })?;
    let p = Arc::new(built);
    map.insert(threads, Arc::clone(&p));
    Ok(p)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // test code may fail loudly
    use super::*;

    #[test]
    fn threads_follow_the_request_else_the_swarm_size_up_to_the_cores() {
        assert_eq!(resolve_threads(Some(3), 24).unwrap(), 3);
        assert!(resolve_threads(Some(0), 24).is_err());
        if std::env::var(THREADS_ENV).is_err() {
            let cores = std::thread::available_parallelism().unwrap().get();
            assert_eq!(resolve_threads(None, 24).unwrap(), 1);
            assert_eq!(resolve_threads(None, 64).unwrap(), 1);
            assert_eq!(resolve_threads(None, 65).unwrap(), 2.min(cores));
            assert_eq!(resolve_threads(None, 64 * 1000).unwrap(), cores);
        }
    }
}
