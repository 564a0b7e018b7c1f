//! The sums of a run's passes, kept, saved, loaded and merged.
//!
//! Every pass is a complete, independent estimate of the image, and pass `i` depends on (seed,
//! i) alone (and, for a pass resized to a time limit, its size), so passes can run in any order,
//! on any machine: the weighted mean of the passes of several partial runs equals that of one
//! run over all of them.
//!
//! Passes may differ in size (a vcm pass under a time limit is cut or stretched to end at it):
//! each is added with its weight, its share of a full pass's light paths, and the image is the
//! weighted mean, so a small pass moves it no more than its paths deserve.
//!
//! A partial file (`.part`) holds the sums of a run's passes: a short text header (format, image
//! size, the run's settings fingerprint, the passes it holds, their total weight) and then the
//! weighted sums as little-endian f64 triples, rows from the top.

use crate::error::{Error, Result};
use crate::film::Film;
use crate::math::Vec3;
use std::path::Path;

/// The sums of a set of passes.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulator {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Everything that must agree for two accumulations to be merged (scene, settings, size).
    pub fingerprint: String,
    /// The passes held, as half-open ranges, sorted and disjoint.
    pub passes: Vec<(u64, u64)>,
    /// The passes' total weight (their count when all are full).
    pub weight: f64,
    sum: Vec<[f64; 3]>,
}

const MAGIC: &str = "caustica-partial 1";

impl Accumulator {
    /// No passes yet.
    pub fn new(width: usize, height: usize, fingerprint: impl Into<String>) -> Accumulator {
        Accumulator {
            width,
            height,
            fingerprint: fingerprint.into(),
            passes: Vec::new(),
            weight: 0.0,
            sum: vec![[0.0; 3]; width * height],
        }
    }

    /// Only the size and fingerprint, for a run that keeps no sums; adding to it or saving it is
    /// refused.
    pub fn without_sums(width: usize, height: usize, fingerprint: impl Into<String>) -> Accumulator {
        Accumulator {
            width,
            height,
            fingerprint: fingerprint.into(),
            passes: Vec::new(),
            weight: 0.0,
            sum: Vec::new(),
        }
    }

    /// Whether pass `pass` is among those held.
    pub fn holds(&self, pass: u64) -> bool {
        self.passes.iter().any(|&(a, b)| a <= pass && pass < b)
    }

    /// Number of passes held.
    pub fn pass_count(&self) -> u64 {
        self.passes.iter().map(|(a, b)| b - a).sum()
    }

    /// Adds the pixels of pass `pass`, of weight `weight` (1 for a full pass).
    pub fn add(&mut self, pass: u64, pixels: &[Vec3], weight: f64) {
        assert_eq!(pixels.len(), self.sum.len(), "pass image size");
        for (s, p) in self.sum.iter_mut().zip(pixels) {
            s[0] += weight * p.x as f64;
            s[1] += weight * p.y as f64;
            s[2] += weight * p.z as f64;
        }
        self.weight += weight;
        self.insert_range(pass, pass + 1);
    }

    fn insert_range(&mut self, a: u64, b: u64) {
        self.passes.push((a, b));
        self.passes.sort_unstable();
        let mut merged: Vec<(u64, u64)> = Vec::with_capacity(self.passes.len());
        for &(a, b) in &self.passes {
            match merged.last_mut() {
                Some(last) if last.1 == a => last.1 = b,
                _ => merged.push((a, b)),
            }
        }
        self.passes = merged;
    }

    /// The weighted mean of the passes.
    pub fn film(&self) -> Film {
        let mut film = Film::new(self.width, self.height);
        let n = if self.weight > 0.0 { self.weight } else { 1.0 };
        for (p, s) in film.pixels.iter_mut().zip(&self.sum) {
            *p = Vec3::new((s[0] / n) as f32, (s[1] / n) as f32, (s[2] / n) as f32);
        }
        film
    }

    /// Adds another accumulation of the same run; refuses a different run or shared passes.
    pub fn merge(&mut self, other: &Accumulator) -> Result<()> {
        if other.width != self.width || other.height != self.height {
            return Err(Error::InvalidSettings(format!(
                "the parts differ in size: {}×{} and {}×{}",
                self.width, self.height, other.width, other.height
            )));
        }
        if other.fingerprint != self.fingerprint {
            return Err(Error::InvalidSettings(format!(
                "the parts come from different runs (scene or settings differ):\n  {}\n  {}",
                self.fingerprint, other.fingerprint
            )));
        }
        for &(a, b) in &other.passes {
            if let Some(&(c, d)) = self.passes.iter().find(|&&(c, d)| a < d && c < b) {
                return Err(Error::InvalidSettings(format!(
                    "passes {}..{} are in two parts (ranges {a}..{b} and {c}..{d}): merging them would count them twice",
                    a.max(c),
                    b.min(d)
                )));
            }
        }
        for (s, o) in self.sum.iter_mut().zip(&other.sum) {
            for c in 0..3 {
                s[c] += o[c];
            }
        }
        self.weight += other.weight;
        for &(a, b) in &other.passes {
            self.insert_range(a, b);
        }
        Ok(())
    }

    /// Writes the accumulation atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let ranges: Vec<String> = self.passes.iter().map(|(a, b)| format!("{a}..{b}")).collect();
        let mut bytes = format!(
            "{MAGIC}\nwidth {}\nheight {}\nfingerprint {}\npasses {}\nweight {}\n\n",
            self.width,
            self.height,
            self.fingerprint.replace('\n', " "),
            ranges.join(","),
            self.weight
        )
        .into_bytes();
        bytes.reserve(self.sum.len() * 24);
        for s in &self.sum {
            for c in s {
                bytes.extend_from_slice(&c.to_le_bytes());
            }
        }
        crate::image_io::write_atomically(path, |tmp| std::fs::write(tmp, &bytes).map_err(|e| e.to_string()))
    }

    /// Reads a partial file written by [`Accumulator::save`].
    pub fn load(path: &Path) -> Result<Accumulator> {
        let bytes = std::fs::read(path).map_err(|source| Error::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let bad = |why: &str| Error::Image {
            path: path.to_path_buf(),
            message: format!("not a caustica partial file: {why}"),
        };
        let end = bytes
            .windows(2)
            .position(|w| w == b"\n\n")
            .ok_or_else(|| bad("no header"))?;
        let header = std::str::from_utf8(&bytes[..end]).map_err(|_| bad("the header is not text"))?;
        let mut lines = header.lines();
        if lines.next() != Some(MAGIC) {
            return Err(bad("wrong first line"));
        }
        let (mut width, mut height, mut fingerprint, mut passes, mut weight) = (None, None, None, None, None);
        for line in lines {
            let (key, value) = line.split_once(' ').unwrap_or((line, ""));
            match key {
                "width" => width = value.parse::<usize>().ok(),
                "height" => height = value.parse::<usize>().ok(),
                "fingerprint" => fingerprint = Some(value.to_string()),
                "passes" => passes = Some(parse_ranges(value).ok_or_else(|| bad("bad pass ranges"))?),
                "weight" => {
                    let w = value.parse::<f64>().ok().filter(|w| w.is_finite() && *w >= 0.0);
                    weight = Some(w.ok_or_else(|| bad("bad weight"))?);
                }
                _ => return Err(bad(&format!("unknown header line `{line}`"))),
            }
        }
        let (width, height) = (
            width.ok_or_else(|| bad("no width"))?,
            height.ok_or_else(|| bad("no height"))?,
        );
        let body = &bytes[end + 2..];
        let expected = width
            .checked_mul(height)
            .and_then(|n| n.checked_mul(24))
            .ok_or_else(|| bad("absurd size"))?;
        if body.len() != expected {
            return Err(bad(&format!(
                "{} bytes of sums for {width}×{height} pixels (expected {expected}): the file is truncated or damaged",
                body.len()
            )));
        }
        let sum = body
            .chunks_exact(24)
            .map(|c| {
                let f = |i: usize| f64::from_le_bytes(c[i * 8..i * 8 + 8].try_into().unwrap_or([0; 8]));
                [f(0), f(1), f(2)]
            })
            .collect();
        let mut acc = Accumulator {
            width,
            height,
            fingerprint: fingerprint.ok_or_else(|| bad("no fingerprint"))?,
            passes: Vec::new(),
            weight: 0.0,
            sum,
        };
        for (a, b) in passes.ok_or_else(|| bad("no passes"))? {
            acc.insert_range(a, b);
        }
        // Files written before passes had weights hold full passes only.
        acc.weight = weight.unwrap_or(acc.pass_count() as f64);
        Ok(acc)
    }
}

/// The sums of several partial files of one run, merged in the order given (`caustica merge`);
/// a part that does not fit the others is named in the error.
pub fn merge_files(paths: &[impl AsRef<Path>]) -> Result<Accumulator> {
    let mut paths = paths.iter().map(AsRef::as_ref);
    let first = paths
        .next()
        .ok_or_else(|| Error::InvalidSettings("no partial files given".into()))?;
    let mut merged = Accumulator::load(first)?;
    for path in paths {
        let part = Accumulator::load(path)?;
        merged.merge(&part).map_err(|e| match e {
            Error::InvalidSettings(m) => Error::InvalidSettings(format!("{}: {m}", path.display())),
            other => other,
        })?;
    }
    Ok(merged)
}

/// `a..b` ranges separated by commas (empty for none).
fn parse_ranges(text: &str) -> Option<Vec<(u64, u64)>> {
    if text.trim().is_empty() {
        return Some(Vec::new());
    }
    text.split(',')
        .map(|r| {
            let (a, b) = r.trim().split_once("..")?;
            let (a, b) = (a.parse::<u64>().ok()?, b.parse::<u64>().ok()?);
            (a < b).then_some((a, b))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accumulations_merge_save_and_load() {
        let dir = std::env::temp_dir().join(format!("caustica-part-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let pass = |i: u64| vec![Vec3::new(i as f32, 1.0, 0.5); 6];
        let mut whole = Accumulator::new(3, 2, "run");
        let mut first = Accumulator::new(3, 2, "run");
        let mut second = Accumulator::new(3, 2, "run");
        // Pass 5 is a half pass: it weighs half as much in the mean.
        let weight = |i: u64| if i == 5 { 0.5 } else { 1.0 };
        for i in 0..6 {
            whole.add(i, &pass(i), weight(i));
            if i < 3 { &mut first } else { &mut second }.add(i, &pass(i), weight(i));
        }
        let path = dir.join("b.part");
        second.save(&path).unwrap();
        let loaded = Accumulator::load(&path).unwrap();
        assert_eq!(loaded, second);
        first.merge(&loaded).unwrap();
        assert_eq!(first.passes, vec![(0, 6)]);
        assert_eq!(first.film(), whole.film());
        // (0 + 1 + 2 + 3 + 4 + 5/2) / 5.5
        assert!((whole.film().pixels[0].x - 12.5 / 5.5).abs() < 1e-6);
        assert_eq!(first.weight, 5.5);
        // Counting passes twice, or mixing runs, is refused.
        assert!(first.merge(&loaded).is_err());
        assert!(Accumulator::new(3, 2, "other").merge(&second).is_err());
        // A truncated file is refused with a reason.
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 5]).unwrap();
        let err = Accumulator::load(&path).unwrap_err().to_string();
        assert!(err.contains("truncated"), "{err}");
        // A file from before passes had weights: its passes are full ones.
        let mut old = Accumulator::new(3, 2, "run");
        old.add(0, &pass(1), 1.0);
        old.add(1, &pass(2), 1.0);
        old.save(&path).unwrap();
        let text = std::fs::read(&path).unwrap();
        let cut = text.windows(9).position(|w| w == b"weight 2\n").unwrap();
        std::fs::write(&path, [&text[..cut], &text[cut + 9..]].concat()).unwrap();
        assert_eq!(Accumulator::load(&path).unwrap(), old);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
