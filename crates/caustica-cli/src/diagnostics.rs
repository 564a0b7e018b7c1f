//! Library errors as miette reports: scene errors point at the offending text.

use caustica::error::line_col;
use caustica::Error;
use miette::{LabeledSpan, MietteDiagnostic, NamedSource, Report};

/// A printable report for an error.
pub fn report(error: Error) -> Report {
    match error {
        Error::Scene { path, text, error } => {
            let (line, col) = line_col(&text, error.span.start);
            let len = error.span.end.saturating_sub(error.span.start).max(1);
            let start = error.span.start.min(text.len());
            let len = len
                .min(text.len().saturating_sub(start))
                .max(usize::from(start < text.len()));
            let mut diagnostic = MietteDiagnostic::new(format!("{}:{line}:{col}: {}", path.display(), error.message))
                .with_code("caustica::scene")
                .with_label(LabeledSpan::at(start..start + len, "here"));
            if let Some(help) = error.help {
                diagnostic = diagnostic.with_help(help);
            }
            Report::new(diagnostic).with_source_code(NamedSource::new(path.display().to_string(), text))
        }
        other => miette::miette!("{other}"),
    }
}
