//! A stopwatch for the stages of a conversion, printed only when asked
//! for (benchmarks set `CIRRUS_TIMING`).

/// Stage times on stderr when `CIRRUS_TIMING` is set (for benchmarks):
/// wall time, and the process's CPU time where /proc says it.
pub(crate) struct Stages(Option<std::cell::Cell<(std::time::Instant, f64)>>);

fn cpu_seconds() -> f64 {
    // utime and stime, fields 14 and 15 of /proc/self/stat, in 1/100 s.
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            let rest = &s[s.rfind(')')? + 2..];
            let f: Vec<&str> = rest.split(' ').collect();
            Some((f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?) / 100.0)
        })
        .unwrap_or(0.0)
}

impl Stages {
    /// A stopwatch that prints nothing.
    pub fn silent() -> Self {
        Stages(None)
    }

    pub fn start() -> Self {
        Stages(
            std::env::var_os("CIRRUS_TIMING")
                .map(|_| std::cell::Cell::new((std::time::Instant::now(), cpu_seconds()))),
        )
    }
    pub fn lap(&self, what: &str) {
        if let Some(t) = &self.0 {
            let (wall, cpu) = t.get();
            let now = cpu_seconds();
            eprintln!(
                "  {what}: {:.3} s ({:.2} s CPU)",
                wall.elapsed().as_secs_f64(),
                now - cpu
            );
            t.set((std::time::Instant::now(), now));
        }
    }
}
