//! Everything `lodkit` prints on stdout goes through [`Output`]. A reader that stops early
//! (`lodkit check --stats shaders/*.wgsl | head -1`) is no error: what is left to print is
//! dropped and the command exits as it would have. Any other failure to write is an I/O error
//! (exit 2). Diagnostics on stderr go through [`eprint`], which drops what a closed stderr
//! cannot take instead of panicking as `eprintln!` does.

use std::io::{ErrorKind, Write as _};
use std::process::ExitCode;

/// Stdout for one command's output.
#[derive(Default)]
pub struct Output {
    /// The reader has gone: nothing more is written.
    closed: bool,
    /// A write failed for another reason.
    failed: Option<std::io::Error>,
}

impl Output {
    /// Writes `bytes` and flushes them (so they come before what follows on stderr).
    pub fn write(&mut self, bytes: &[u8]) {
        if self.closed || self.failed.is_some() {
            return;
        }
        let mut stdout = std::io::stdout().lock();
        match stdout.write_all(bytes).and_then(|()| stdout.flush()) {
            Ok(()) => {}
            Err(e) if e.kind() == ErrorKind::BrokenPipe => self.closed = true,
            Err(e) => self.failed = Some(e),
        }
    }

    /// Writes `text`.
    pub fn print(&mut self, text: &str) {
        self.write(text.as_bytes());
    }

    /// Writes `line` and a newline.
    pub fn println(&mut self, line: &str) {
        self.print(&format!("{line}\n"));
    }

    /// The command's exit code: `code`, or 2 when a write failed (said on stderr) other than
    /// to a reader that stopped early.
    pub fn finish(self, code: ExitCode) -> ExitCode {
        match self.failed {
            Some(e) => {
                eprint(&format!("error: cannot write to stdout: {e}\n"));
                ExitCode::from(2)
            }
            None => code,
        }
    }
}

/// Writes a command's whole output to stdout: exit 0, or 2 when writing failed.
pub fn emit(text: &str) -> ExitCode {
    let mut out = Output::default();
    out.print(text);
    out.finish(ExitCode::SUCCESS)
}

/// Writes `text` to stderr; a stderr that is closed or fails takes nothing, and the command
/// goes on (its exit code says what happened).
pub fn eprint(text: &str) {
    let mut stderr = std::io::stderr().lock();
    let _ = stderr
        .write_all(text.as_bytes())
        .and_then(|()| stderr.flush());
}

/// Writes `line` and a newline to stderr, as [`eprint`].
pub fn eprintln(line: &str) {
    eprint(&format!("{line}\n"));
}
