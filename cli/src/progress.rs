//! Progress on stderr, shared by `lodkit demo` and `lodkit lod` over a folder.

/// Progress of a run on stderr: a bar on a terminal; elsewhere (a CI log, a pipe, where a bar
/// is not drawn) a line per part with the seconds since the start, so a log shows where the
/// time goes.
pub struct Progress {
    bar: indicatif::ProgressBar,
    lines: bool,
    start: std::time::Instant,
}

impl Progress {
    /// Progress over `steps` steps; nothing shown unless `enabled`.
    pub fn new(enabled: bool, steps: usize) -> Self {
        use std::io::IsTerminal;
        let terminal = std::io::stderr().is_terminal();
        let bar = if enabled && terminal {
            indicatif::ProgressBar::new(steps as u64)
        } else {
            indicatif::ProgressBar::hidden()
        };
        if let Ok(style) = indicatif::ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:32} {pos}/{len} {msg}",
        ) {
            bar.set_style(style);
        }
        Self {
            bar,
            lines: enabled && !terminal,
            start: std::time::Instant::now(),
        }
    }

    /// The part that starts now.
    pub fn set_message(&self, message: impl Into<String>) {
        let message = message.into();
        if self.lines {
            let seconds = self.start.elapsed().as_secs_f64();
            eprintln!("[{seconds:7.1} s] {message}");
        }
        self.bar.set_message(message);
    }

    /// `n` steps more done.
    pub fn inc(&self, n: u64) {
        self.bar.inc(n);
    }

    /// A step that has just ended.
    pub fn done(&self, message: String) {
        if self.lines {
            let seconds = self.start.elapsed().as_secs_f64();
            eprintln!("[{seconds:7.1} s] {message}: done");
        }
        self.bar.set_message(message);
        self.bar.inc(1);
    }

    /// Prints `line` on stderr without tearing the bar.
    pub fn println(&self, line: &str) {
        self.bar.suspend(|| eprintln!("{line}"));
    }

    /// The run has ended.
    pub fn finish(&self) {
        if self.lines {
            let seconds = self.start.elapsed().as_secs_f64();
            eprintln!("[{seconds:7.1} s] done");
        }
        self.bar.finish_and_clear();
    }
}
