//! How many threads one comparison may use beside its caller's: FLIP's
//! strips and a failing case's report images. The check driver sets it
//! from the cores its jobs leave (`check --jobs 1` on two cores: 2); 1
//! (everything on the calling thread) until something sets it.

use std::sync::atomic::{AtomicUsize, Ordering};

static CASE_THREADS: AtomicUsize = AtomicUsize::new(1);

/// Lets each comparison use `n` threads (at least 1) from now on.
pub fn set_case_threads(n: usize) {
    CASE_THREADS.store(n.max(1), Ordering::Relaxed);
}

/// The threads one comparison may use.
pub fn case_threads() -> usize {
    CASE_THREADS.load(Ordering::Relaxed)
}

/// Images under this many pixels stay on one thread: starting threads
/// costs more than their work (a 32 x 32 case's whole check is ~1 ms).
const PARALLEL_FROM_PIXELS: usize = 1 << 18;

/// The threads one comparison of `pixels` pixels may use.
pub fn threads_for(pixels: usize) -> usize {
    if pixels < PARALLEL_FROM_PIXELS { 1 } else { case_threads() }
}

/// Runs `work` on every item, at most `threads` at once (on the calling
/// thread alone for one), and hands each result to `take` in item order:
/// FLIP's strips and SSIM's bands, whose sums must not depend on the
/// threads. A rayon pool of `threads`, not the global one: the check's
/// jobs share the cores ([`set_case_threads`]).
pub(crate) fn in_groups<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    work: impl Fn(&T) -> R + Sync,
    take: impl FnMut(R),
) {
    use rayon::prelude::*;
    if threads <= 1 || items.len() <= 1 {
        items.iter().map(work).for_each(take);
        return;
    }
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.min(items.len())).build();
    match pool {
        Ok(pool) => pool.install(|| items.par_iter().map(&work).collect::<Vec<R>>()).into_iter().for_each(take),
        // No thread to be had: the same work on this one.
        Err(_) => items.iter().map(work).for_each(take),
    }
}

/// Makes every thread of this process allocate from glibc's one main
/// arena; call it first in `main`. A helper thread otherwise gets an arena
/// of its own, and the freed top of one (a FLIP strip's 45 MB) is what
/// `malloc_trim` does not hand back: four failing 2048 x 2048 cases
/// peaked at 364 MB, not 308, since each case after the first started
/// with about 110 MB of such tops resident. The arena's lock
/// costs nothing measurable: a thread allocates a few large buffers per
/// band or strip.
pub fn one_arena() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets a tunable of the allocator.
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, 1);
    }
}

/// Hands what a case of `pixels` pixels freed back to the system, where
/// it is large enough to spread threads (see [`release_freed_memory`]).
pub fn release_after_case(pixels: u64) {
    if pixels >= PARALLEL_FROM_PIXELS as u64 {
        release_freed_memory();
    }
}

/// Hands the memory that helper threads freed back to the system (measured:
/// 78 MB more peak memory at 1920 x 1080 without this). Where each thread
/// has its own glibc arena (a process that did not call [`one_arena`]),
/// the freed top of a helper's arena stays resident even so.
pub(crate) fn release_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only returns free pages of the allocator's arenas.
    unsafe {
        libc::malloc_trim(0);
    }
}
