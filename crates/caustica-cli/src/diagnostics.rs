//! How the command reports a failure: the library's diagnostic (a window of the line, never the
//! whole of it), as text on standard error or as JSON; and a panic, which is a bug, as one line.

use caustica::diagnostic::Diagnostic;
use caustica::Error;
use std::io::Write;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Prints `error` on standard error; with `json`, as one JSON object `{"error": {…}}` on
/// standard output as well, so a script reading `--json` sees why there is no result.
pub fn print(error: &Error, json: bool) {
    // Rendering is plain string work bounded by its window; should it fail all the same, the
    // fallback is the error's own `file:line:col: message`, not a second crash.
    let rendered = catch_unwind(AssertUnwindSafe(|| {
        let diagnostic = Diagnostic::new(error);
        let json = json.then(|| serde_json::json!({ "error": &diagnostic }).to_string());
        (diagnostic.render(), json)
    }));
    match rendered {
        Ok((text, json)) => {
            eprintln!("{text}");
            if let Some(json) = json {
                // A closed pipe is no reason for a second error.
                let _ = writeln!(std::io::stdout(), "{json}");
            }
        }
        Err(_) => eprintln!("error: {}", caustica::diagnostic::shorten(&error.to_string())),
    }
}

/// Makes any panic end the process with exit code 1 and one line saying it is a bug, instead
/// of a backtrace; a panic on a worker thread ends the process too, not just that thread.
pub fn on_panic_exit(code: u8) {
    std::panic::set_hook(Box::new(move |info| {
        let message = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".into());
        let place = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        let message = caustica::diagnostic::shorten(&message).replace('\n', " ");
        eprintln!(
            "caustica: internal error (a bug in caustica, not in your input): {message}{place}; \
             please report it to caustica's developers with the command and the scene"
        );
        std::process::exit(i32::from(code));
    }));
}
