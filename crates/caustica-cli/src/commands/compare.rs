//! `caustica compare`: region means of an image against a reference, with relative errors.

use crate::cli::CompareArgs;
use caustica::film::Film;
use caustica::{Error, Result};

/// One region: a name and inclusive row and column ranges.
struct Region {
    name: String,
    rows: (usize, usize),
    cols: (usize, usize),
}

fn parse_region(text: &str, width: usize, height: usize) -> Result<Region> {
    let bad = || {
        Error::InvalidSettings(format!(
            "--region {text}: expected [NAME=]R0..R1,C0..C1 inside the {width}×{height} image"
        ))
    };
    let (name, spec) = match text.split_once('=') {
        Some((n, s)) => (n.to_string(), s),
        None => (text.to_string(), text),
    };
    let (rows, cols) = spec.split_once(',').ok_or_else(bad)?;
    let range = |r: &str| -> Option<(usize, usize)> {
        let (a, b) = r.trim().split_once("..")?;
        Some((a.trim().parse().ok()?, b.trim().parse().ok()?))
    };
    let (rows, cols) = (range(rows).ok_or_else(bad)?, range(cols).ok_or_else(bad)?);
    if rows.0 > rows.1 || cols.0 > cols.1 || rows.1 >= height || cols.1 >= width {
        return Err(bad());
    }
    Ok(Region { name, rows, cols })
}

fn load(path: &std::path::Path) -> Result<Film> {
    let (width, height, pixels) = caustica::image_io::read_exr(path)?;
    Ok(Film { width, height, pixels })
}

/// Runs the command; returns the exit code.
pub fn run(args: CompareArgs) -> Result<u8> {
    let image = load(&args.image)?;
    let reference = load(&args.reference)?;
    if (image.width, image.height) != (reference.width, reference.height) {
        return Err(Error::InvalidSettings(format!(
            "the images differ in size: {}×{} and {}×{}",
            image.width, image.height, reference.width, reference.height
        )));
    }
    let mut regions = args
        .region
        .iter()
        .map(|r| parse_region(r, image.width, image.height))
        .collect::<Result<Vec<_>>>()?;
    if regions.is_empty() {
        regions.push(Region {
            name: "whole image".into(),
            rows: (0, image.height - 1),
            cols: (0, image.width - 1),
        });
    }
    let mut rows = Vec::new();
    for region in &regions {
        let got = image.region_mean(region.rows, region.cols);
        let want = reference.region_mean(region.rows, region.cols);
        let error = (0..3)
            .map(|c| (got[c] - want[c]).abs() / want[c].abs().max(1e-12))
            .fold(0.0f32, f32::max);
        rows.push((region, got, want, error));
    }
    if args.json {
        let items: Vec<serde_json::Value> = rows
            .iter()
            .map(|(r, g, w, e)| {
                serde_json::json!({
                    "name": r.name,
                    "mean": g.to_array(),
                    "reference": w.to_array(),
                    "relative_error": e,
                })
            })
            .collect();
        crate::stdout::println(&serde_json::Value::Array(items).to_string())?;
    } else {
        let mut table = String::from(
            "| region | mean R, G, B | reference R, G, B | largest relative error |\n|---|---|---|---:|\n",
        );
        for (r, g, w, e) in &rows {
            table += &format!(
                "| {} | {:.4}, {:.4}, {:.4} | {:.4}, {:.4}, {:.4} | {:.2}% |\n",
                r.name,
                g.x,
                g.y,
                g.z,
                w.x,
                w.y,
                w.z,
                100.0 * e
            );
        }
        crate::stdout::print(&table)?;
    }
    Ok(0)
}
