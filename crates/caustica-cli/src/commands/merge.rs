//! `caustica merge`: the partial files of a split progressive run, combined into one image.

use crate::cli::MergeArgs;
use caustica::film::ToneMap;
use caustica::image_io::ImageFormat;
use caustica::integrator::partial::Accumulator;
use caustica::{Error, Result};

/// Runs the command; returns the exit code.
pub fn run(args: MergeArgs) -> Result<u8> {
    ImageFormat::from_path(&args.output)?;
    if !args.exposure.is_finite() || args.exposure.abs() > 64.0 {
        return Err(Error::InvalidSettings(
            "--exposure must be a number of stops between -64 and 64".into(),
        ));
    }
    let mut parts = args.parts.iter();
    let first = parts
        .next()
        .ok_or_else(|| Error::InvalidSettings("no partial files given".into()))?;
    let mut merged = Accumulator::load(first)?;
    for path in parts {
        let part = Accumulator::load(path)?;
        merged.merge(&part).map_err(|e| match e {
            Error::InvalidSettings(m) => Error::InvalidSettings(format!("{}: {m}", path.display())),
            other => other,
        })?;
    }
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
