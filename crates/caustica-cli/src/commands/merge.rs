//! `caustica merge`: the partial files of a split progressive run, combined into one image.

use crate::cli::MergeArgs;
use caustica::film::ToneMap;
use caustica::image_io::{check_writable, ImageFormat};
use caustica::integrator::partial::merge_files;
use caustica::{Error, Result};

/// Runs the command; returns the exit code.
pub fn run(args: MergeArgs) -> Result<u8> {
    ImageFormat::from_path(&args.output)?;
    for path in std::iter::once(&args.output).chain(&args.partial) {
        check_writable(path)?;
    }
    if !args.exposure.is_finite() || args.exposure.abs() > 64.0 {
        return Err(Error::InvalidSettings(
            "--exposure must be a number of stops between -64 and 64".into(),
        ));
    }
    let merged = merge_files(&args.parts)?;
    merged.film().save(
        &args.output,
        ToneMap::Reinhard {
            exposure: args.exposure,
        },
    )?;
    if let Some(p) = &args.partial {
        merged.save(p)?;
    }
    if !args.quiet {
        let ranges: Vec<String> = merged.passes.iter().map(|(a, b)| format!("{a}..{b}")).collect();
        eprintln!(
            "{}: {} parts, {} passes ({}), {}×{}",
            args.output.display(),
            args.parts.len(),
            merged.pass_count(),
            ranges.join(","),
            merged.width,
            merged.height
        );
    }
    Ok(0)
}
