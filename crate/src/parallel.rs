//! Independent jobs shared between this thread and one helper.

/// Runs the jobs `order` (indices, in the order to start them) from one
/// queue: natively this thread and one helper thread take the next job in
/// turn, the helper with `quiet`, this thread with `reporting` (which may
/// report progress); in wasm32 this thread alone. Once a result satisfies
/// `stop`, no job is started any more. Returns `(job, result)` pairs, this
/// thread's first, each thread's in the order it took them.
pub fn share_jobs<T: Send>(
    order: &[usize],
    quiet: impl Fn(usize) -> T + Sync,
    mut reporting: impl FnMut(usize) -> T,
    stop: impl Fn(&T) -> bool + Sync,
) -> Vec<(usize, T)> {
    #[cfg(not(target_arch = "wasm32"))]
    if order.len() > 1 {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let next = AtomicUsize::new(0);
        let drain = |job: &mut dyn FnMut(usize) -> T| {
            let mut out = Vec::new();
            while let Some(&i) = order.get(next.fetch_add(1, Ordering::Relaxed)) {
                let result = job(i);
                if stop(&result) {
                    next.store(order.len(), Ordering::Relaxed); // the other thread stops too
                }
                out.push((i, result));
            }
            out
        };
        return std::thread::scope(|scope| {
            let helper = scope.spawn(|| drain(&mut |i| quiet(i)));
            let mut mine = drain(&mut reporting);
            mine.extend(helper.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)));
            mine
        });
    }
    let _ = &quiet; // (the helper's, natively)
    let mut out = Vec::new();
    for &i in order {
        let result = reporting(i);
        let done = stop(&result);
        out.push((i, result));
        if done {
            break;
        }
    }
    out
}
