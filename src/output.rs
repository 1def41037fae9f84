//! What rslf says on standard output, and what happens when nobody reads it any more.

use std::io::{ErrorKind, Write};

/// The exit status when standard output's reader has gone: 128 + `SIGPIPE`, the status a shell
/// reports for a Unix tool that signal ended (`yes | head`).
pub const BROKEN_PIPE_EXIT: i32 = 128 + 13;

/// Writes `text` to standard output (the `out!` and `outln!` macros). When the reader has
/// gone (`rslf generate --suite --list | head`) the program ends at once, silently, with
/// `BROKEN_PIPE_EXIT`, as a Unix tool ends on `SIGPIPE`: what it had to say was read as far as
/// it was wanted, and every file rslf writes is written whole or not at all. Any other failure
/// to write panics, as `print!` does.
pub(crate) fn write_out(text: std::fmt::Arguments) {
    let mut stdout = std::io::stdout().lock();
    match stdout.write_fmt(text).and_then(|()| stdout.flush()) {
        Ok(()) => {}
        Err(err) if err.kind() == ErrorKind::BrokenPipe => std::process::exit(BROKEN_PIPE_EXIT),
        Err(err) => panic!("failed printing to stdout: {err}"),
    }
}
