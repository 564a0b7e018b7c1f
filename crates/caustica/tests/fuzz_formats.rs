//! A bounded, deterministic fuzz of the pbrt-v4, glTF, OBJ/MTL and PLY readers, as
//! `fuzz_scene.rs` fuzzes the `.ray` reader: seed files of each format are mutated (bytes and
//! tokens deleted, duplicated, swapped, replaced by extreme numbers or syntax, truncated) and
//! every mutant must read or fail with a located error — no panic, no hang, no unbounded
//! allocation. Mutants that read are built and rendered tiny in both models.
//!
//! Each format runs a fixed number of cases (no clock decides anything, so a run is the same on
//! a busy machine); `CAUSTICA_FUZZ_CASES=N` runs N instead and `CAUSTICA_FUZZ_SEED=S` changes
//! the seed. A failure names the case and writes the mutant to the temp folder.

mod common;

use caustica::error::Error;
use caustica::format::{self, ply, ReadOptions, SourceFiles};
use caustica::integrator::path::{PathSettings, PathTracer};
use caustica::integrator::whitted::{render, WhittedSettings};
use caustica::integrator::{ImageSettings, Progressive};
use caustica::progress::NoProgress;
use caustica::scene::build;
use std::alloc::{GlobalAlloc, Layout, System};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Cases per format by default.
const DEFAULT_CASES: u64 = 10_000;

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
}

const REPLACEMENTS: &[&[u8]] = &[
    b"1e38",
    b"-1e38",
    b"0",
    b"-0",
    b"1e-45",
    b"nan",
    b"inf",
    b"4294967296",
    b"-1",
    b"99999999999",
    b"[",
    b"]",
    b"\"",
    b"{",
    b"}",
    b",",
    b":",
    b"#",
    b"\n",
    b"\0",
    b"\xff",
    b"\xc3",
    b"/",
    b"//",
    b"-1/-1/-1",
    b"null",
    b"true",
    b"[]",
    b"{}",
    b"\"\"",
    b"AttributeBegin",
    b"WorldBegin",
    b"Include \"x.pbrt\"",
    b"element vertex 9999999999",
];

/// One mutant of `source`: byte-level edits at token-ish places.
fn mutate(source: &[u8], rng: &mut Rng) -> (Vec<u8>, String) {
    let n = source.len().max(1);
    let at = rng.below(n);
    let len = 1 + rng.below(16.min(n));
    let end = (at + len).min(source.len());
    let mut out = source.to_vec();
    match rng.below(7) {
        0 => {
            out.truncate(at);
            (out, format!("truncated at {at}"))
        }
        1 => {
            out.drain(at.min(out.len())..end);
            (out, format!("deleted {at}..{end}"))
        }
        2 => {
            let piece = source[at.min(source.len())..end].to_vec();
            let to = rng.below(out.len() + 1);
            out.splice(to..to, piece);
            (out, format!("copied {at}..{end} to {to}"))
        }
        3 | 4 => {
            let r = REPLACEMENTS[rng.below(REPLACEMENTS.len())];
            out.splice(at.min(out.len())..end, r.iter().copied());
            (out, format!("{at}..{end} replaced by {:?}", String::from_utf8_lossy(r)))
        }
        5 => {
            // Replace a run of digits (a number) by an extreme.
            let digits = (at..source.len()).find(|&i| source[i].is_ascii_digit());
            match digits {
                Some(s) => {
                    let e = (s..source.len())
                        .find(|&i| !source[i].is_ascii_digit() && source[i] != b'.')
                        .unwrap_or(source.len());
                    let r = REPLACEMENTS[rng.below(10)];
                    out.splice(s..e, r.iter().copied());
                    (
                        out,
                        format!("number at {s} replaced by {:?}", String::from_utf8_lossy(r)),
                    )
                }
                None => (out, "unchanged".into()),
            }
        }
        _ => {
            if !out.is_empty() {
                let (a, b) = (rng.below(out.len()), rng.below(out.len()));
                out.swap(a, b);
            }
            (out, "two bytes swapped".into())
        }
    }
}

/// Builds a scene that read and renders it 6×6 in both models.
fn exercise_scene(source: format::SceneSource) {
    let Ok(scene) = build(&source.description, &Default::default()) else {
        return;
    };
    let image = ImageSettings {
        width: 6,
        height: 6,
        aa: 1,
        seed: 0,
    };
    let _ = render(&scene, None, &WhittedSettings::default(), &image, common::control());
    let path = PathTracer::new(
        &scene,
        PathSettings {
            max_depth: 8,
            ..PathSettings::default()
        },
        6,
        6,
        0,
    );
    let _ = path.render_pass(0, common::control());
}

/// A reader's result must be a scene or a located error: a `Scene` error whose span lies in
/// its file's text.
fn check_error(result: &Result<format::SceneSource, Error>) -> Result<(), String> {
    match result {
        Ok(_) => Ok(()),
        Err(Error::Scene { text, error, .. }) if error.span.start > text.len() => Err(format!(
            "an error span {:?} outside its file of {} bytes",
            error.span,
            text.len()
        )),
        Err(Error::Scene { .. }) => Ok(()),
        Err(other) => Err(format!("an error without a location: {other}")),
    }
}

fn run(name: &str, seeds: &[Vec<u8>], dir: &Path, mut one: impl FnMut(&[u8]) -> Result<(), String>) {
    let cases: Option<u64> = std::env::var("CAUSTICA_FUZZ_CASES").ok().and_then(|v| v.parse().ok());
    let seed: u64 = std::env::var("CAUSTICA_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(16);
    let mut rng = Rng(seed ^ name.len() as u64);
    let limit = cases.unwrap_or(DEFAULT_CASES);
    for case in 0..limit {
        let source = &seeds[rng.below(seeds.len())];
        let (mut mutant, mut what) = mutate(source, &mut rng);
        // Sometimes a second mutation on top.
        if rng.below(3) == 0 {
            let (m, w) = mutate(&mutant, &mut rng);
            mutant = m;
            what = format!("{what}; {w}");
        }
        let baseline = LIVE.load(Ordering::Relaxed);
        PEAK.store(baseline, Ordering::Relaxed);
        let outcome = catch_unwind(AssertUnwindSafe(|| one(&mutant)));
        let used = PEAK.load(Ordering::Relaxed).saturating_sub(baseline);
        let failure = match outcome {
            Err(_) => Some("panicked".to_string()),
            Ok(Err(e)) => Some(e),
            Ok(Ok(())) if used > (512 << 20) + 400 * mutant.len() => Some(format!("used {} MB", used >> 20)),
            Ok(Ok(())) => None,
        };
        if let Some(failure) = failure {
            let path = dir.join(format!("fuzz-{name}-case-{case}"));
            std::fs::write(&path, &mutant).ok();
            panic!(
                "{name} case {case} ({what}): {failure}; the mutant is in {}",
                path.display()
            );
        }
    }
    println!("{name}: {limit} cases");
}

fn temp_dir() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-fuzz-formats-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

const PBRT: &str = r#"LookAt 0 1 4  0 0 0  0 1 0
Camera "perspective" "float fov" [40] "float screenwindow" [-1 1 -1 1]
Film "rgb" "integer xresolution" [8] "integer yresolution" 8
Sampler "halton" "integer pixelsamples" 4
Integrator "sppm" "integer maxdepth" 5
WorldBegin
LightSource "spot" "point3 from" [1 3 1] "point3 to" [0 0 0] "float coneangle" 30 "rgb I" [5 5 5]
LightSource "distant" "blackbody L" 6500 "float illuminance" 2
LightSource "infinite" "rgb L" [0.1 0.1 0.1]
Texture "check" "spectrum" "checkerboard" "float uscale" 4 "rgb tex1" [1 1 1] "rgb tex2" [0 0 0]
MakeNamedMaterial "gold" "string type" "conductor" "spectrum eta" "metal-Au-eta" "spectrum k" "metal-Au-k" "float roughness" 0.1
AttributeBegin
  Material "diffuse" "texture reflectance" "check"
  Shape "bilinearmesh" "point3 P" [-3 0 -3 3 0 -3 -3 0 3 3 0 3] "point2 uv" [0 0 1 0 0 1 1 1]
AttributeEnd
AttributeBegin
  Material "dielectric" "spectrum eta" "glass-BK7"
  Translate 0 0.5 0
  Shape "sphere" "float radius" 0.5
AttributeEnd
AttributeBegin
  NamedMaterial "gold"
  Translate 1 0.3 0
  Rotate 30 0 1 0
  Shape "cylinder" "float radius" 0.2 "float zmin" 0 "float zmax" 0.5
  Shape "disk" "float radius" 0.2 "float height" 0.5
AttributeEnd
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [2 2 2]
  Material "coateddiffuse" "rgb reflectance" [0.2 0.3 0.4] "float roughness" 0.2
  Translate -1 2 0
  Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2] "normal N" [0 0 1 0 0 1 0 0 1]
AttributeEnd
ObjectBegin "leaf"
  Material "diffusetransmission"
  Shape "trianglemesh" "point3 P" [0 0 0 0.3 0 0 0 0.3 0]
ObjectEnd
Translate -1 0.2 1
ObjectInstance "leaf"
"#;

const OBJ: &str =
    "mtllib fuzz.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\n\
usemtl glass\nf 1/1/1 2/2/1 3/3/1 4/3/1\nf -5 -4 -1\nusemtl red\nf 2//1 3//1 5//1\ng rest\nf 3 4 5\nl 1 2\n";
const MTL: &str = "newmtl glass\nNi 1.5\nillum 7\nTf 1 1 1\nnewmtl red\nKd 0.8 0.1 0.1\nKs 0.2 0.2 0.2\nNs 50\nKe 0 0 0\nd 0.9\nnewmtl gold\nKd 1 0.8 0.3\nPm 1\nPr 0.3\n";

#[test]
fn pbrt_reader_survives_mutants() {
    let dir = temp_dir();
    std::fs::write(dir.join("x.pbrt"), "Shape \"sphere\"\n").unwrap();
    let mut seeds = vec![PBRT.as_bytes().to_vec()];
    if let Ok(text) = std::fs::read(root().join("scenes/glass_caustic.pbrt")) {
        seeds.push(text);
    }
    run("pbrt", &seeds, &dir, |bytes| {
        let text = String::from_utf8_lossy(bytes).into_owned();
        let result = format::read_text(&dir.join("fuzz.pbrt"), text, &dir, &ReadOptions::default(), &NoProgress);
        check_error(&result)?;
        if let Ok(source) = result {
            exercise_scene(source);
        }
        Ok(())
    });
}

#[test]
fn obj_and_mtl_readers_survive_mutants() {
    let dir = temp_dir();
    std::fs::write(dir.join("fuzz.mtl"), MTL).unwrap();
    run("obj", &[OBJ.as_bytes().to_vec()], &dir, |bytes| {
        let text = String::from_utf8_lossy(bytes).into_owned();
        let result = format::read_text(&dir.join("fuzz.obj"), text, &dir, &ReadOptions::default(), &NoProgress);
        check_error(&result)?;
        if let Ok(source) = result {
            exercise_scene(source);
        }
        Ok(())
    });
    run("mtl", &[MTL.as_bytes().to_vec()], &dir, |bytes| {
        let mut warnings = Vec::new();
        let text = String::from_utf8_lossy(bytes);
        let _ = format::obj::parse_mtl(&text, 0, &dir, &mut warnings);
        Ok(())
    });
}

fn gltf_seed() -> Vec<u8> {
    // Two triangles, a camera, a light, a textured-looking material and a glass one, with its
    // buffer in a data URI.
    let mut buffer = Vec::new();
    for v in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0] {
        buffer.extend(v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 1, 3, 2] {
        buffer.extend(i.to_le_bytes());
    }
    let b64 = {
        const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut out = String::new();
        for chunk in buffer.chunks(3) {
            let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
            let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
            for k in 0..4 {
                out.push(if k <= chunk.len() {
                    A[(n >> (18 - 6 * k) & 63) as usize] as char
                } else {
                    '='
                });
            }
        }
        out
    };
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1,2]}}],
"nodes":[{{"mesh":0,"children":[3]}},{{"camera":0,"translation":[0.5,0.5,3]}},{{"translation":[0,2,2],"rotation":[-0.38,0,0,0.92],"extensions":{{"KHR_lights_punctual":{{"light":0}}}}}},{{"mesh":0,"scale":[0.5,0.5,0.5],"translation":[0,0,0.5]}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"material":0}},{{"attributes":{{"POSITION":0}},"indices":1,"material":1,"mode":5}}]}}],
"materials":[{{"pbrMetallicRoughness":{{"baseColorFactor":[0.8,0.2,0.2,1],"metallicFactor":0,"roughnessFactor":0.5}},"emissiveFactor":[0.1,0.1,0.1]}},
{{"pbrMetallicRoughness":{{"metallicFactor":0,"roughnessFactor":0}},"extensions":{{"KHR_materials_transmission":{{"transmissionFactor":1}},"KHR_materials_ior":{{"ior":1.5}},"KHR_materials_dispersion":{{"dispersion":0.3}}}}}}],
"cameras":[{{"type":"perspective","perspective":{{"yfov":0.7,"aspectRatio":1.5,"znear":0.1}}}}],
"extensionsUsed":["KHR_lights_punctual","KHR_materials_transmission","KHR_materials_ior","KHR_materials_dispersion"],
"extensions":{{"KHR_lights_punctual":{{"lights":[{{"type":"spot","intensity":2000,"spot":{{"outerConeAngle":0.6}}}}]}}}},
"accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},{{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":12}}],
"buffers":[{{"byteLength":60,"uri":"data:application/octet-stream;base64,{b64}"}}]}}"#
    )
    .into_bytes()
}

/// The same document as a GLB: its buffer moved into the binary chunk.
fn glb_seed() -> Vec<u8> {
    let json = String::from_utf8(gltf_seed()).unwrap();
    let start = json.find("\"uri\":\"data:").unwrap();
    let end = json[start..].find("\"}]").unwrap() + start + 1;
    let data_start = json[start..].find("base64,").unwrap() + start + 7;
    let encoded = &json[data_start..end - 1];
    let mut bin = Vec::new();
    {
        let value = |c: u8| match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            _ => 63,
        } as u32;
        let digits: Vec<u8> = encoded.bytes().filter(|&c| c != b'=').collect();
        for chunk in digits.chunks(4) {
            let mut acc = 0u32;
            for (k, &c) in chunk.iter().enumerate() {
                acc |= value(c) << (18 - 6 * k);
            }
            bin.extend(&acc.to_be_bytes()[1..chunk.len()]);
        }
    }
    let mut json = format!("{}{}", &json[..start - 1], &json[end..]).into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(0x4E4F_534Au32.to_le_bytes());
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(0x004E_4942u32.to_le_bytes());
    out.extend(bin);
    out
}

#[test]
fn gltf_reader_survives_mutants() {
    let dir = temp_dir();
    let seeds = [gltf_seed(), glb_seed()];
    // Both seeds read cleanly before they are mutated.
    for (seed, name) in seeds.iter().zip(["fuzz.gltf", "fuzz.glb"]) {
        let source = format::gltf::read(&dir.join(name), seed.clone(), &dir, &NoProgress)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(source.description.objects.len(), 4, "{name}");
    }
    run("gltf", &seeds, &dir, |bytes| {
        let result = format::gltf::read(&dir.join("fuzz.gltf"), bytes.to_vec(), &dir, &NoProgress);
        check_error(&result)?;
        if let Ok(source) = result {
            exercise_scene(source);
        }
        Ok(())
    });
}

#[test]
fn ply_reader_survives_mutants() {
    let dir = temp_dir();
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
property float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n"
        .to_vec();
    let mut binary = b"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
element face 1\nproperty list uchar uint vertex_indices\nend_header\n"
        .to_vec();
    for v in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        binary.extend(v.to_le_bytes());
    }
    binary.push(3);
    for i in [0u32, 1, 2] {
        binary.extend(i.to_le_bytes());
    }
    run("ply", &[ascii, binary], &dir, |bytes| {
        let mut files = SourceFiles::new(Path::new("main.pbrt"), String::new());
        if let Err(e) = ply::parse(&mut files, Path::new("m.ply"), bytes) {
            // The error lies in the PLY file's registered text.
            if let Error::Scene { path, text, error } = files.error(e) {
                if path != Path::new("m.ply") || error.span.start > text.len() {
                    return Err(format!("a PLY error placed at {} {:?}", path.display(), error.span));
                }
            }
        }
        Ok(())
    });
}

// ---- long lines ------------------------------------------------------------------------------
// Real glTF is written on one line, and pbrt and `.ray` files carry parameter lists of megabytes:
// an error far along such a line must be located and reported in a few short lines.

/// Columns past this are out of reach of a report that pads a line to its column (a format
/// width is a `u16`).
const FAR: usize = 70_000;

/// Every refusal of a long-line case: a located scene error whose report is short.
fn check_long(name: &str, result: &Result<format::SceneSource, Error>) -> Result<Option<usize>, String> {
    check_error(result).map_err(|e| format!("{name}: {e}"))?;
    let Err(error) = result else {
        return Ok(None);
    };
    let diagnostic = caustica::diagnostic::Diagnostic::new(error);
    let report = diagnostic.render();
    let Some(at) = &diagnostic.excerpt else {
        return Err(format!("{name}: no excerpt"));
    };
    let located = format!(":{}:{}: ", at.line, at.column);
    if !report.lines().next().is_some_and(|l| l.contains(&located)) {
        return Err(format!("{name}: the report's first line lacks `{located}`"));
    }
    if let Some(long) = report.lines().find(|l| l.chars().count() > 1000) {
        return Err(format!("{name}: a report line of {} characters", long.chars().count()));
    }
    Ok(Some(at.column))
}

fn read(dir: &Path, name: &str, text: String) -> Result<format::SceneSource, Error> {
    format::read_text(&dir.join(name), text, dir, &ReadOptions::default(), &NoProgress)
}

#[test]
fn one_line_gltf_cut_at_many_points_is_refused_with_a_short_located_report() {
    let dir = temp_dir();
    // The seed glTF with a long `extras` string, then squeezed onto one line.
    let seed = String::from_utf8(gltf_seed()).unwrap();
    let padded = seed.replacen('{', &format!("{{\"extras\":{{\"note\":\"{}\"}},", "n".repeat(FAR)), 1);
    let one_line: String = padded.chars().filter(|&c| c != '\n' && c != '\r').collect();
    format::gltf::read(&dir.join("one.gltf"), one_line.clone().into_bytes(), &dir, &NoProgress)
        .expect("the whole one-line file reads");
    // Cuts inside the long string, and many after it, where every error lies far along the line.
    let after = one_line.find(&"n".repeat(FAR)).unwrap() + FAR;
    let cuts = (1..20)
        .map(|i| after * i / 20)
        .chain((0..200).map(|i| after + (one_line.len() - after) * i / 200));
    for cut in cuts {
        let bytes = one_line.as_bytes()[..cut].to_vec();
        let result = format::gltf::read(&dir.join("cut.gltf"), bytes, &dir, &NoProgress);
        assert!(result.is_err(), "cut at {cut} read as a scene");
        let column = check_long(&format!("cut at {cut}"), &result).unwrap().unwrap();
        assert!(cut < after || column > FAR, "cut at {cut} located at column {column}");
    }
}

#[test]
fn huge_parameter_lists_with_a_bad_value_far_along_are_located() {
    let dir = temp_dir();
    let numbers = |n: usize| (0..n).map(|i| format!("{}", i % 7)).collect::<Vec<_>>().join(" ");
    let pbrt_bad = ["1.2.3", "\"text\"", "[", "nan", "\u{fffd}", "WorldEnd", "1e999"];
    let mut cases = Vec::new();
    for bad in pbrt_bad {
        cases.push((
            "bad.pbrt",
            format!(
                "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ {} {bad} 0 0 ] \"integer indices\" [0 1 2]\n",
                numbers(3 * 12_000)
            ),
        ));
    }
    for bad in ["1.2.3", "x", "(", ";", "\u{7}", "}"] {
        cases.push((
            "bad.ray",
            format!(
                "SBT-raytracer 1.0\ncamera {{ position = (0,0,4); }}\npolymesh {{ points = ({}({bad}, 0, 0)); faces = ((0,1,2)); }}\n",
                "(0, 0, 0), ".repeat(8_000)
            ),
        ));
    }
    // Deep nesting on one line, broken at its far end.
    cases.push((
        "nest.ray",
        format!(
            "SBT-raytracer 1.0\n{}sphere {{}} ]",
            "translate(0, 0, 0, ".repeat(5_000)
        ),
    ));
    cases.push((
        "face.obj",
        format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nf {}9999999\n", "1 2 3 ".repeat(12_000)),
    ));
    cases.push(("vertex.obj", format!("v {} x\n", "0.5 ".repeat(20_000))));
    let mut far = 0;
    for (name, text) in cases {
        let result = read(&dir, name, text);
        if let Some(column) = check_long(name, &result).unwrap() {
            far += usize::from(column > FAR);
        }
    }
    assert!(far >= 10, "only {far} errors past column {FAR}");
}

#[test]
fn bad_bytes_far_into_a_line_are_located_in_every_reader() {
    let dir = temp_dir();
    let junk = String::from_utf8_lossy(b"\xff\xfe\x00\x01\x80").into_owned();
    let cases = [
        (
            "b.ray",
            format!("SBT-raytracer 1.0\nsphere {{ {}{junk} }}\n", " ".repeat(FAR)),
        ),
        (
            "b.pbrt",
            format!("WorldBegin Shape \"sphere\" {}{junk}\n", " ".repeat(FAR)),
        ),
        ("b.obj", format!("v 0 0 0 {}{junk}\nf 1 1 1\n", " ".repeat(FAR))),
        (
            "b.gltf",
            format!("{{\"asset\":{{\"version\":\"2.0\"}},{}{junk}}}", " ".repeat(FAR)),
        ),
    ];
    for (name, text) in cases {
        check_long(name, &read(&dir, name, text)).unwrap();
    }
    // PLY: a header line and a data line of megabytes, then bad bytes.
    for ply in [
        format!(
            "ply\nformat ascii 1.0\ncomment {}\u{1}\nelement vertex 1\nend_header\n",
            "c".repeat(FAR)
        ),
        format!(
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n{}{junk}\n",
            "0 ".repeat(FAR)
        ),
    ] {
        let mut files = SourceFiles::new(Path::new("main.pbrt"), String::new());
        if let Err(e) = ply::parse(&mut files, Path::new("m.ply"), ply.as_bytes()) {
            let error = files.error(e);
            let report = caustica::diagnostic::Diagnostic::new(&error).render();
            assert!(report.lines().all(|l| l.chars().count() < 1000), "{report}");
        }
    }
    // MTL: warnings only, never a panic.
    let mut warnings = Vec::new();
    let _ = format::obj::parse_mtl(
        &format!("newmtl a\nKd {}{junk}\n", "1 ".repeat(FAR)),
        0,
        &dir,
        &mut warnings,
    );
}
