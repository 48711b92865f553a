//! Wall-clock timing that works natively and in wasm32 (where
//! `std::time::Instant` panics).

/// Seconds since an arbitrary origin.
pub fn now_seconds() -> f64 {
    #[cfg(target_arch = "wasm32")]
    {
        js_sys::Date::now() / 1000.0
    }
    #[cfg(not(target_arch = "wasm32"))]
    {
        use std::sync::OnceLock;
        use std::time::Instant;
        static ORIGIN: OnceLock<Instant> = OnceLock::new();
        ORIGIN.get_or_init(Instant::now).elapsed().as_secs_f64()
    }
}

/// Measures consecutive stages: each [`Stopwatch::lap`] returns the seconds
/// since the previous lap (or since creation).
#[derive(Clone, Debug)]
pub struct Stopwatch {
    last: f64,
}

impl Stopwatch {
    /// Starts timing now.
    pub fn start() -> Stopwatch {
        Stopwatch { last: now_seconds() }
    }
    /// Seconds since the previous lap; restarts the lap.
    pub fn lap(&mut self) -> f64 {
        let t = now_seconds();
        let d = t - self.last;
        self.last = t;
        d
    }
}
