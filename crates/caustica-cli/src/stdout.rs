//! Everything the command prints on stdout goes through here: a reader that stops early
//! (`caustica info scene.ray | head`) closes the pipe, and that ends the command quietly
//! instead of panicking as `println!` does.

use caustica::{Error, Result};
use std::io::Write;

/// Writes `text` to stdout and flushes it.
pub fn print(text: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|source| Error::Io {
            path: STDOUT.into(),
            source,
        })
}

/// Writes `text` and a newline to stdout.
pub fn println(text: &str) -> Result<()> {
    print(&format!("{text}\n"))
}

/// The name stdout errors carry.
const STDOUT: &str = "<stdout>";

/// Whether `error` is stdout's reader having gone away: not a failure of the command.
pub fn is_closed_pipe(error: &Error) -> bool {
    matches!(error, Error::Io { path, source } if path.as_os_str() == STDOUT && source.kind() == std::io::ErrorKind::BrokenPipe)
}
