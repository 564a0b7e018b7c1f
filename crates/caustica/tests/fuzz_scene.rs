//! A bounded, deterministic fuzz of the scene reader: real scenes are mutated and every mutant must
//! parse or fail cleanly (no panic, no hang, no unbounded allocation); mutants that build are also
//! rendered tiny to check that shading survives odd geometry.
//!
//! `CAUSTICA_FUZZ_CASES=N` runs N cases instead of the default time-boxed run;
//! `CAUSTICA_FUZZ_SEED=S` changes the seed. A failure names the case number, the mutation and
//! writes the mutant to the temp folder.

mod common;

use caustica::format::ray_file::{self, ast::Dialect, ParseOptions};
use caustica::integrator::path::{PathSettings, PathTracer};
use caustica::integrator::ppm::{Ppm, PpmSettings};
use caustica::integrator::whitted::{render, WhittedSettings};
use caustica::integrator::ImageSettings;
use caustica::integrator::Progressive;
use caustica::loader::{from_text, LoadSettings};
use caustica::photon::{PhotonMap, PhotonSettings};
use std::alloc::{GlobalAlloc, Layout, System};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Cases of the default run; it also stops after `DEFAULT_BUDGET` (CI's ten minutes on two
/// cores hold the whole suite: a longer run takes `CAUSTICA_FUZZ_CASES`).
const DEFAULT_CASES: u64 = 40_000;
const DEFAULT_BUDGET: Duration = Duration::from_secs(8);
/// Files larger than this are left out of the pool: one case must stay well under a second.
const MAX_SOURCE_BYTES: usize = 160_000;
/// A case slower than this is reported; one this slow fails the run.
const SLOW: Duration = Duration::from_secs(1);
const TOO_SLOW: Duration = Duration::from_secs(5);
/// A case still running after this is a hang: the watchdog names it and aborts.
const HANG: Duration = Duration::from_secs(60);

/// Extreme numbers the reader accepts, then ones it must refuse.
const NUMBERS: &[&str] = &[
    "1e38",
    "-1e38",
    "0",
    "-0",
    "3.4e38",
    "-3.4e38",
    "1e-45",
    "1e-38",
    "1e30",
    "-1e30",
    "4294967296",
    "99999999999999999999",
    "-1",
    "0.0000001",
    "1e-999",
];
const BAD_NUMBERS: &[&str] = &["1e999", "nan", "inf", ".", "-", "1e", "1e+5", "1E5"];
const GARBAGE: &[&str] = &[
    "(",
    ")",
    "{",
    "}",
    ",",
    "=",
    ";",
    "\"",
    "/",
    "/*",
    "*/",
    "//",
    "+",
    "-",
    ".",
    "e",
    "E",
    "\0",
    "\u{feff}",
    "é",
    "\u{1F600}",
    "\r",
    "\t",
    "\n",
    "#",
    "map(",
    "material",
    "name",
    "SBT-raytracer",
    "polymesh",
    "gennormals",
];

/// Live heap bytes and their peak, so a case that allocates from a count in the file is caught.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded unchanged to the system allocator; only counters are added.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let ptr = System.alloc(layout);
        if !ptr.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        ptr
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout);
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Heap a case may use beyond its input: a fixed allowance plus a multiple of the text's size.
fn memory_limit(text_len: usize) -> usize {
    (256 << 20) + 400 * text_len
}

/// SplitMix64: small, fast and good enough to pick mutations.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        if n == 0 {
            0
        } else {
            (self.next() % n as u64) as usize
        }
    }
    fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// Pieces of scene text: words/numbers, single punctuation, whitespace runs.
fn pieces(text: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let mut start = 0;
    let kind = |c: char| {
        if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') {
            0
        } else if c.is_whitespace() {
            1
        } else {
            2
        }
    };
    let mut prev: Option<u8> = None;
    for (i, c) in text.char_indices() {
        let k = kind(c);
        if prev.is_some_and(|p| p != k || k == 2) {
            out.push(&text[start..i]);
            start = i;
        }
        prev = Some(k);
    }
    if start < text.len() {
        out.push(&text[start..]);
    }
    out
}

fn floor_boundary(text: &str, mut i: usize) -> usize {
    i = i.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// One mutant of `source` and a description of what was done.
fn mutate(source: &str, rng: &mut Rng) -> (String, String) {
    let p = pieces(source);
    match rng.below(10) {
        0 => {
            // Truncation at every k-th byte, k chosen per case.
            let step = 1 + rng.below(source.len().max(1));
            let at = floor_boundary(source, rng.below(source.len() / step + 1) * step);
            (source[..at].to_string(), format!("truncated at byte {at}"))
        }
        1 => {
            let mut p = p;
            let n = 1 + rng.below(3);
            for _ in 0..n {
                if !p.is_empty() {
                    let i = rng.below(p.len());
                    p.remove(i);
                }
            }
            (p.concat(), format!("{n} piece(s) deleted"))
        }
        2 => {
            let mut p = p;
            let i = rng.below(p.len());
            let len = 1 + rng.below(8);
            let copy: Vec<&str> = p[i..(i + len).min(p.len())].to_vec();
            let times = 1 + rng.below(3);
            for _ in 0..times {
                let at = rng.below(p.len() + 1);
                p.splice(at..at, copy.iter().copied());
            }
            (p.concat(), format!("{len} piece(s) from {i} duplicated {times}×"))
        }
        3 => {
            let mut p = p;
            let (a, b) = (rng.below(p.len()), rng.below(p.len()));
            if !p.is_empty() {
                p.swap(a, b);
            }
            (p.concat(), format!("pieces {a} and {b} swapped"))
        }
        4 => {
            let mut text = source.to_string();
            let n = 1 + rng.below(4);
            for _ in 0..n {
                let at = floor_boundary(&text, rng.below(text.len() + 1));
                let junk = if rng.below(2) == 0 {
                    rng.pick(GARBAGE).to_string()
                } else {
                    // Random bytes, made valid text the way `load` would not: the parser takes `&str`.
                    let bytes: Vec<u8> = (0..1 + rng.below(6)).map(|_| rng.next() as u8).collect();
                    String::from_utf8_lossy(&bytes).into_owned()
                };
                text.insert_str(at, &junk);
            }
            (text, format!("{n} garbage insertion(s)"))
        }
        5 | 6 => {
            // Replace numbers with extreme ones.
            let mut p = p;
            let numeric: Vec<usize> = (0..p.len())
                .filter(|&i| p[i].starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '.'))
                .collect();
            let n = 1 + rng.below(4);
            let mut done = Vec::new();
            for _ in 0..n {
                if numeric.is_empty() {
                    break;
                }
                let i = *rng.pick(&numeric);
                let value = if rng.below(6) == 0 {
                    *rng.pick(BAD_NUMBERS)
                } else {
                    *rng.pick(NUMBERS)
                };
                p[i] = value;
                done.push(format!("#{i}={value}"));
            }
            (p.concat(), format!("numbers replaced: {}", done.join(" ")))
        }
        7 => {
            // Wrap one piece position in deep nesting.
            let depth = [100, 1000, 10_000][rng.below(3)];
            let (open, close) = match rng.below(4) {
                0 => ("translate(1, 0, 0, ", ")"),
                1 => ("scale(1.001, ", ")"),
                2 => ("rotate(1, 1, 0, 0.1, ", ")"),
                _ => ("{ ", "}"),
            };
            let at = floor_boundary(source, rng.below(source.len() + 1));
            let closed = rng.below(3) > 0;
            let text = format!(
                "{}{}sphere {{}}{}{}",
                &source[..at],
                open.repeat(depth),
                if closed { close.repeat(depth) } else { String::new() },
                &source[at..]
            );
            (text, format!("{depth}× `{open}` at byte {at}, closed: {closed}"))
        }
        8 => {
            // Very long words, numbers and lines.
            let at = floor_boundary(source, rng.below(source.len() + 1));
            let len = [1000, 100_000, 1_000_000][rng.below(3)];
            let (what, filler) = match rng.below(4) {
                0 => ("identifier", "a".repeat(len)),
                1 => ("number", "1".repeat(len)),
                2 => ("quoted string", format!("\"{}\"", "x".repeat(len))),
                _ => ("line of `;`", ";".repeat(len)),
            };
            (
                format!("{} {filler} {}", &source[..at], &source[at..]),
                format!("{len}-byte {what} at byte {at}"),
            )
        }
        _ => {
            // A second mutation on top of a first.
            let (once, first) = mutate(source, rng);
            if once.len() > 4 * source.len() + 100_000 {
                return (once, first);
            }
            let (twice, second) = mutate(&once, rng);
            (twice, format!("{first}, then {second}"))
        }
    }
}

/// Hand-written extremes that random mutation rarely reaches.
fn fixed_cases() -> Vec<(String, String)> {
    let stage = "SBT-raytracer 1.0\ncamera { position = (0, 0, 4); }\npoint_light { position = (1, 1, 4); color = (1, 1, 1); }\n";
    let mut cases = vec![
        (
            format!("{stage}{}sphere {{}}{}", "translate(0, 0, 0, ".repeat(10_000), ")".repeat(10_000)),
            "10,000 nested translates".to_string(),
        ),
        (
            format!("{stage}{}sphere {{}}{}", "{ ".repeat(10_000), "}".repeat(10_000)),
            "10,000 nested groups".to_string(),
        ),
        (
            format!("{stage}{}", "rotate(1, 0, 0, 1, {".repeat(10_000)),
            "10,000 unclosed rotate groups".to_string(),
        ),
        (
            format!("{stage}{}sphere {{}}{}", "scale(10, ".repeat(10_000), ")".repeat(10_000)),
            "10,000 nested scales (overflow)".to_string(),
        ),
        (
            format!("{stage}{}sphere {{}}{}", "scale(0.1, ".repeat(10_000), ")".repeat(10_000)),
            "10,000 nested scales (underflow)".to_string(),
        ),
        (
            format!("{stage}polymesh {{ points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0, 1, 4294967295)); }}"),
            "face index 2^32 - 1".to_string(),
        ),
        (
            format!("{stage}polymesh {{ points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0, 1, 1e30)); }}"),
            "face index 1e30".to_string(),
        ),
        (
            format!(
                "{stage}polymesh {{ points = ((0,0,0),(1,0,0),(0,1,0)); faces = (({})); }}",
                vec!["0, 1, 2"; 50_000].join(", ")
            ),
            "a 150,000-corner face".to_string(),
        ),
        (
            format!("{stage}polymesh {{ points = ((0,0,0),(1e38,0,0),(0,1e38,0)); faces = ((0, 1, 2)); gennormals; }}"),
            "a triangle whose area overflows".to_string(),
        ),
        (
            format!("{stage}polymesh {{ points = ((0,0,0),(1e-30,0,0),(0,1e-30,0)); faces = ((0, 1, 2)); gennormals; }}"),
            "a triangle whose area underflows".to_string(),
        ),
        (
            format!("{stage}scale(1e15, polymesh {{ points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0, 1, 2)); }})"),
            "a mesh under a giant scale".to_string(),
        ),
        (
            format!("{stage}scale(1e-15, sphere {{}})"),
            "a tiny sphere".to_string(),
        ),
        (
            format!("{stage}scale(1e12, 1e-12, 1, cylinder {{}}) scale(1e-12, 1e12, 1, cone {{ top_radius = 1e30; }})"),
            "extremely anisotropic shapes".to_string(),
        ),
        (
            format!("{stage}cone {{ height = 1e38; bottom_radius = 1e38; top_radius = 0; }}"),
            "a giant cone".to_string(),
        ),
        (
            "SBT-raytracer 1.0\ncamera { position = (1e38, 0, 0); viewdir = (1e-38, 0, 0); updir = (0, 1e38, 0); fov = 179.99; aspectratio = 1e-38; } sphere {}"
                .to_string(),
            "an extreme camera".to_string(),
        ),
        (
            "SBT-raytracer 1.0\ncamera { viewdir = (0, 0, 0); updir = (0, 0, 0); fov = 0; } point_light { position = (0,0,0); color = (1e38, 1e38, 1e38); constant_attenuation_coeff = 0; quadratic_attenuation_coeff = 0; } sphere { material = { diffuse = (1,1,1); specular = (1,1,1); shininess = 1e38; reflective = (1,1,1); transmissive = (1,1,1); index = 0; } }"
                .to_string(),
            "a degenerate camera and a light at a sphere's centre".to_string(),
        ),
        (
            "SBT-raytracer 1.0\ncamera { quaternian = (0, 0, 0, 0); } directional_light { direction = (0, 0, 0); color = (1, 1, 1); } box {}"
                .to_string(),
            "a zero quaternion and a zero light direction".to_string(),
        ),
        (
            "SBT-raytracer 1.0\ncamera { look_at = (0, 0, 0); } sphere { material = { index = -1; transmissive = (1,1,1); } }"
                .to_string(),
            "look_at the eye, negative index".to_string(),
        ),
        ("SBT-raytracer 1.0 material { name = m; diffuse = (1,1,1); } ".repeat(2000), "2000 dialect-O named materials".to_string()),
        (format!("SBT-raytracer 1.0 {}", "polymesh { points = (".repeat(5000)), "5000 unclosed meshes".to_string()),
        (format!("SBT-raytracer 1.0 {}", "/*".repeat(100_000)), "100,000 `/*`".to_string()),
        (format!("SBT-raytracer 1.0 {}", "\"".repeat(100_001)), "100,001 quotes".to_string()),
        (format!("SBT-raytracer 1.0 {}", "-".repeat(100_000)), "100,000 minus signs".to_string()),
    ];
    for n in NUMBERS.iter().chain(BAD_NUMBERS) {
        cases.push((
            format!("{stage}translate({n}, {n}, {n}, scale({n}, rotate({n}, 1, 0, {n}, sphere {{ material = {{ index = {n}; shininess = {n}; }} }})))"),
            format!("every number {n}"),
        ));
    }
    cases
}

fn sources() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut dirs = vec![root.join("scenes")];
    let corpus = root.join("../shared/scenes/sbt-corpus");
    if corpus.is_dir() {
        dirs.push(corpus);
    } else {
        println!(
            "note: the corpus at {} is absent; fuzzing the project's scenes only",
            corpus.display()
        );
    }
    let mut out = Vec::new();
    for dir in dirs {
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e == "ray"))
            .collect();
        files.sort();
        for file in files {
            let Ok(text) = std::fs::read_to_string(&file) else {
                continue;
            };
            if text.len() <= MAX_SOURCE_BYTES {
                out.push((file.file_name().unwrap().to_string_lossy().into_owned(), text));
            }
        }
    }
    out
}

/// Parses (auto and both forced dialects), builds, and renders a built scene 8×8; returns
/// whether it parsed and whether it was rendered.
fn exercise(text: &str, dir: &Path) -> (bool, bool) {
    let parsed = ray_file::parse(text, dir, &ParseOptions::default()).is_ok();
    for dialect in [Dialect::Tokenizer, Dialect::Dictionary] {
        let _ = ray_file::parse(text, dir, &ParseOptions { dialect: Some(dialect) });
    }
    if let Ok(scene) = from_text(text, dir, &LoadSettings::default()) {
        let image = ImageSettings {
            width: 8,
            height: 8,
            aa: 1,
            seed: 0,
        };
        let _ = render(&scene, None, &WhittedSettings::default(), &image, common::control());
        // A few photons too: emission and aiming meet the same odd geometry.
        let photons = PhotonSettings {
            target_stored: 50,
            max_emitted: 5_000,
            ..PhotonSettings::default()
        };
        let estimate = caustica::photon::EstimateSettings {
            k: 10,
            ..Default::default()
        };
        let _ = PhotonMap::trace(&scene, &photons, &estimate, common::control());
        // And one pass of the physical model: area lights, BSDF sampling, photon scattering.
        let ppm = Ppm::new(
            &scene,
            PpmSettings {
                photons_per_pass: 200,
                max_depth: 16,
                ..PpmSettings::default()
            },
            8,
            8,
            0,
        );
        let _ = ppm.render_pass(0, common::control());
        let path = PathTracer::new(
            &scene,
            PathSettings {
                max_depth: 16,
                ..PathSettings::default()
            },
            4,
            4,
            0,
        );
        let _ = path.render_pass(0, common::control());
        return (parsed, true);
    }
    (parsed, false)
}

fn env_u64(name: &str) -> Option<u64> {
    std::env::var(name)
        .ok()
        .map(|v| v.parse().unwrap_or_else(|_| panic!("{name} must be a number")))
}

#[test]
fn mutated_scenes_never_panic_or_hang() {
    let sources = sources();
    assert!(!sources.is_empty(), "no scenes to fuzz");
    let requested = env_u64("CAUSTICA_FUZZ_CASES");
    let (cases, budget) = match requested {
        Some(n) => (n, None),
        None => (DEFAULT_CASES, Some(DEFAULT_BUDGET)),
    };
    let seed = env_u64("CAUSTICA_FUZZ_SEED").unwrap_or(0x5eed);
    // Textures resolve against a folder that holds none: `map(…)` fails cleanly at build time.
    let dir = std::env::temp_dir().join(format!("caustica-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();

    // The panic message of the last panic, so the report can show it next to the input.
    let last_panic = Arc::new(Mutex::new(String::new()));
    let hook_slot = Arc::clone(&last_panic);
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        *hook_slot.lock().unwrap() = format!("{info}");
    }));

    // Watchdog: a case running longer than HANG is reported and the process ends.
    let started_ms = Arc::new(AtomicU64::new(u64::MAX));
    let current = Arc::new(Mutex::new(String::new()));
    let epoch = Instant::now();
    {
        let (started_ms, current) = (Arc::clone(&started_ms), Arc::clone(&current));
        std::thread::spawn(move || loop {
            std::thread::sleep(Duration::from_millis(500));
            let start = started_ms.load(Ordering::Relaxed);
            let now = epoch.elapsed().as_millis() as u64;
            if start != u64::MAX && now.saturating_sub(start) > HANG.as_millis() as u64 {
                eprintln!("HANG: {} has run for over {:?}", current.lock().unwrap(), HANG);
                std::process::exit(3);
            }
        });
    }

    let fixed = fixed_cases();
    let mut rng = Rng(seed);
    let mut failures = Vec::new();
    let mut slow = Vec::new();
    let run_start = Instant::now();
    let mut run = 0u64;
    let mut longest = (Duration::ZERO, String::new());
    let (mut parsed, mut rendered) = (0u64, 0u64);
    for case in 0..cases + fixed.len() as u64 {
        if budget.is_some_and(|b| run_start.elapsed() > b) {
            break;
        }
        let (text, what) = match fixed.get(case as usize) {
            Some((text, what)) => (text.clone(), format!("fixed: {what}")),
            None => {
                let (name, source) = rng.pick(&sources);
                let (text, what) = mutate(source, &mut rng);
                (text, format!("{name}: {what}"))
            }
        };
        let label = format!("case {case} (seed {seed:#x}) [{what}]");
        *current.lock().unwrap() = label.clone();
        let path = dir.join(format!("mutant-{case}.ray"));
        started_ms.store(epoch.elapsed().as_millis() as u64, Ordering::Relaxed);
        let base = LIVE.load(Ordering::Relaxed);
        PEAK.store(base, Ordering::Relaxed);
        let t = Instant::now();
        let result = catch_unwind(AssertUnwindSafe(|| exercise(&text, &dir)));
        let elapsed = t.elapsed();
        if let Ok((p, r)) = result {
            parsed += u64::from(p);
            rendered += u64::from(r);
        }
        started_ms.store(u64::MAX, Ordering::Relaxed);
        run += 1;
        let used = PEAK.load(Ordering::Relaxed).saturating_sub(base);
        if elapsed > longest.0 {
            longest = (elapsed, label.clone());
        }
        let greedy = used > memory_limit(text.len());
        if result.is_err() || elapsed > TOO_SLOW || greedy {
            std::fs::write(&path, &text).unwrap();
            let why = if result.is_err() {
                format!("panicked: {}", last_panic.lock().unwrap())
            } else if greedy {
                format!("allocated {} MB for a {}-byte input", used >> 20, text.len())
            } else {
                format!("took {elapsed:?}")
            };
            failures.push(format!("{label} {why}\n  input: {}", path.display()));
        } else if elapsed > SLOW {
            slow.push(format!("{label} took {elapsed:?}"));
        }
    }
    std::panic::set_hook(default_hook);
    println!(
        "fuzz: {run} cases ({} fixed; {parsed} parsed, {rendered} built and rendered) in {:.1} s from {} scenes, seed {seed:#x}; slowest {:?}: {}",
        fixed.len(),
        run_start.elapsed().as_secs_f64(),
        sources.len(),
        longest.0,
        longest.1
    );
    for s in &slow {
        println!("slow (over {SLOW:?}): {s}");
    }
    assert!(
        failures.is_empty(),
        "{} failing case(s):\n{}",
        failures.len(),
        failures.join("\n")
    );
}
