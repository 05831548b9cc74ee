//! Everything `lodkit` prints on stdout goes through [`Output`]. A reader that stops early
//! (`lodkit check --stats shaders/*.wgsl | head -1`) is no error: what is left to print is
//! dropped and the command exits as it would have. Any other failure to write is an I/O error
//! (exit 2).

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
                eprintln!("error: cannot write to stdout: {e}");
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
