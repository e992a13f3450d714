//! Two pieces of a model's preparation at once (the analyses of `envelope` and `units`, each
//! up to a second on large models).

use std::sync::Mutex;

/// Runs `background` on a thread of its own and `here` on the calling one, and returns both
/// results. Where the system gives no thread, `background` runs here after `here`; a panic in
/// it is passed on.
pub(crate) fn join<A: Send, B>(
    background: impl FnOnce() -> A + Send,
    here: impl FnOnce() -> B,
) -> (A, B) {
    // The job stays reachable when a refused spawn drops the thread's closure.
    let job = Mutex::new(Some(background));
    let run = || {
        let job = job.lock().unwrap_or_else(|e| e.into_inner()).take();
        job.map(|f| f())
    };
    std::thread::scope(|s| {
        let thread = std::thread::Builder::new()
            .name("ressort-prepare".into())
            .spawn_scoped(s, run)
            .ok();
        let b = here();
        let a = match thread.map(|t| t.join()) {
            Some(Ok(Some(a))) => a,
            Some(Err(panic)) => std::panic::resume_unwind(panic),
            Some(Ok(None)) | None => run().expect("the job ran nowhere else"),
        };
        (a, b)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn both_results_come_back_in_order() {
        let data = [1u64, 2, 3];
        let (a, b) = join(|| data.iter().sum::<u64>(), || data.len());
        assert_eq!((a, b), (6, 3));
        let ((x, y), z) = join(|| join(|| "x", || "y"), || "z");
        assert_eq!((x, y, z), ("x", "y", "z"));
    }
}
