//! Thread pools for the parallel evaluation of particles. One named pool per thread count,
//! built on first use and kept: building a pool every frame would cost more than a search.

use crate::error::{CoreError, Result};
use rayon::{ThreadPool, ThreadPoolBuilder};
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Environment variable giving the default thread count.
pub const THREADS_ENV: &str = "UPPERPOSE_NUM_THREADS";

/// The thread count to use: `requested`, else `UPPERPOSE_NUM_THREADS`, else the number of cores.
pub fn resolve_threads(requested: Option<usize>) -> Result<usize> {
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
            _ => Err(CoreError::InvalidShape {
                name: THREADS_ENV,
                expected: "a positive whole number".into(),
                got: format!("{text:?}"),
            }),
        };
    }
    Ok(std::thread::available_parallelism()
        .map(usize::from)
        .unwrap_or(1))
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
        .map_err(|e| CoreError::InvalidShape {
            name: "thread pool",
            expected: "a pool that starts".into(),
            got: e.to_string(),
        })?;
    let p = Arc::new(built);
    map.insert(threads, Arc::clone(&p));
    Ok(p)
}
