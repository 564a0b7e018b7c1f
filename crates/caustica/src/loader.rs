//! From a scene file to a renderable scene: [`format`](crate::format) reads it into a
//! description, [`scene::build`](crate::scene::build) builds that.

use crate::error::{ParseError, Result};
use crate::format::{self, ReadOptions, SceneSource};
use crate::integrator::darkness;
use crate::presets;
use crate::progress::{NoProgress, Progress};
use crate::scene::{BuildSettings, Scene};
use std::path::Path;
use std::time::Instant;

/// How a scene file is read and built.
#[derive(Clone, Debug, Default)]
pub struct LoadSettings {
    /// How the file is read.
    pub read: ReadOptions,
    /// How the scene is built.
    pub build: BuildSettings,
}

impl LoadSettings {
    /// The settings of the command line's `--cone-quirks` and `--dialect` (`tokenizer`,
    /// `dictionary` or `hkust`; `None` detects it).
    pub fn new(cone_quirks: bool, dialect: Option<&str>) -> Result<LoadSettings> {
        let mut settings = LoadSettings::default();
        settings.build.shapes.cone_quirks = cone_quirks;
        settings.read.ray.dialect = dialect.map(str::parse).transpose()?;
        Ok(settings)
    }
}

/// A built scene, what identifies it, and the seconds its two phases took.
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// What identifies it in a render's fingerprint ([`scene_id`]).
    pub scene_id: String,
    /// Reading and parsing the file.
    pub parse_seconds: f64,
    /// Building shapes, meshes, textures and the BVHs.
    pub build_seconds: f64,
}

/// Reads and builds the scene file at `path`, or the built-in ring scene when there is none,
/// reporting a "parse" and a "build" phase and timing each.
pub fn load_timed(path: Option<&Path>, settings: &LoadSettings, progress: &dyn Progress) -> Result<Loaded> {
    let start = Instant::now();
    let source = match path {
        Some(path) => format::read_file(path, &settings.read, progress),
        None => format::read_text(
            Path::new("<built-in ring scene>"),
            presets::RING.to_string(),
            Path::new("."),
            &settings.read,
            progress,
        ),
    };
    let parse_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let source = source?;
    let scene_id = scene_id(&source, settings);
    let (_, scene) = build_detected(source, settings, progress)?;
    Ok(Loaded {
        scene,
        scene_id,
        parse_seconds,
        build_seconds: start.elapsed().as_secs_f64(),
    })
}

/// Reads and builds the scene file at `path`.
pub fn load(path: &Path, settings: &LoadSettings) -> Result<Scene> {
    let source = format::read_file(path, &settings.read, &NoProgress)?;
    build_detected(source, settings, &NoProgress).map(|(_, scene)| scene)
}

/// Builds a scene read with `settings`; when the dialect was detected rather than forced and
/// the course render would come out black or nearly black (no probe reaches 5 % of white,
/// [`darkness::NEARLY_BLACK`]) because point or spot lights fall off as 1/d² (the UT reading),
/// the file is read again with the HKUST COMP 4411 defaults (no falloff), and that reading is
/// kept if the file is valid there and it is not nearly black. The same file can be a UT or an
/// HKUST scene (stock samples are shared), so this is the one case where the text cannot
/// choose; a warning says which reading was taken. Returns the source the scene was built from.
pub fn build_detected(
    source: SceneSource,
    settings: &LoadSettings,
    progress: &dyn Progress,
) -> Result<(SceneSource, Scene)> {
    let mut source = source;
    locate_warnings(&mut source);
    let scene = build_source_ref(&source, &settings.build, progress)?;
    // The second reading is the .ray format's own question.
    if settings.read.ray.dialect.is_some() || settings.read.format_of(&source.path) != format::Format::Ray {
        return Ok((source, scene));
    }
    if !darkness::dimmed_by_falloff(&scene) {
        return Ok((source, scene));
    }
    let mut options = settings.read.clone();
    options.ray.dialect = Some(crate::format::ray_file::ast::Dialect::Hkust);
    let dir = source
        .path
        .parent()
        .map_or_else(|| Path::new(".").to_path_buf(), Path::to_path_buf);
    let Ok(mut again) = format::read_text(&source.path, source.text.clone(), &dir, &options, &NoProgress) else {
        return Ok((source, scene));
    };
    again.description.warnings.push((
        "read with the HKUST COMP 4411 defaults (point lights without attenuation coefficients do not fall off): with the UT falloff 1/d² the image would be black or nearly so; --dialect tokenizer or dictionary keeps that reading".into(),
        0..0,
    ));
    locate_warnings(&mut again);
    match build_source_ref(&again, &settings.build, &NoProgress) {
        Ok(hkust) if !darkness::nearly_black(&hkust) => Ok((again, hkust)),
        _ => Ok((source, scene)),
    }
}

fn build_source_ref(source: &SceneSource, settings: &BuildSettings, progress: &dyn Progress) -> Result<Scene> {
    crate::scene::build::build_reporting(&source.description, settings, progress).map_err(|e| source.error(e))
}

/// Builds a scene read from a file (reporting a "build" phase); errors point into its text and
/// the reader's warnings start with their `file:line:col`, as errors do.
pub fn build_source(mut source: SceneSource, settings: &BuildSettings, progress: &dyn Progress) -> Result<Scene> {
    locate_warnings(&mut source);
    build_source_ref(&source, settings, progress)
}

/// Prefixes each of the reader's warnings with the `file:line:col` its span starts at (once per
/// source read).
fn locate_warnings(source: &mut SceneSource) {
    let files = &source.files;
    for (message, span) in &mut source.description.warnings {
        // An empty span at 0 is a remark about the whole scene, not a place in it.
        if *span == (0..0) {
            continue;
        }
        if let Some((file, at)) = files.locate(span) {
            let (line, col) = crate::error::line_col(&file.text, at.start);
            *message = format!("{}:{line}:{col}: {message}", file.path.display());
        }
    }
}

/// What identifies a scene in a render's fingerprint, so that only parts of one run merge: a
/// hash of its text (the same on every machine) and how it was read and built.
pub fn scene_id(source: &SceneSource, settings: &LoadSettings) -> String {
    // One file: the hash of its text alone, as before scenes could span several files.
    let hash = if source.files.files().len() == 1 {
        source.text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
        })
    } else {
        source.files.hash()
    };
    format!(
        "{hash:016x} cone-quirks {} dialect {:?}",
        settings.build.shapes.cone_quirks, settings.read.ray.dialect
    )
}

/// Reads and builds scene text; files it refers to resolve against `scene_dir`.
pub fn from_text(text: &str, scene_dir: &Path, settings: &LoadSettings) -> Result<Scene, ParseError> {
    let scene = format::ray_file::parse(text, scene_dir, &settings.read.ray)?;
    let mut files = format::SourceFiles::new(Path::new("<text>"), text.to_string());
    crate::scene::build::build(&scene.into_description(&mut files, scene_dir)?, &settings.build)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;
    use crate::format::ray_file::{ast::Dialect, ParseOptions};
    use std::path::Path;
    use std::sync::Mutex;

    /// Records the phases and the units reported.
    #[derive(Default)]
    struct Record(Mutex<Vec<(String, u64, u64, bool)>>);

    impl Progress for Record {
        fn start(&self, phase: &str, total: u64) {
            self.0.lock().unwrap().push((phase.into(), total, 0, false));
        }
        fn advance(&self, n: u64) {
            self.0.lock().unwrap().last_mut().unwrap().2 += n;
        }
        fn finish(&self) {
            self.0.lock().unwrap().last_mut().unwrap().3 = true;
        }
    }

    const SCENE: &str = "SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); }
point_light { position = (0, 5, 5); color = (1, 1, 1); }
sphere { material = { diffuse = (1, 0, 0); } }
polymesh { points = ((0,0,0), (1,0,0), (0,1,0), (2,0,0)); faces = ((0,1,2), (0,1,3)); }
";

    #[test]
    fn parse_then_build_reports_one_build_phase_that_ends_at_its_total() {
        let settings = LoadSettings::default();
        let record = Record::default();
        let parsed = format::read_text(
            Path::new("t.ray"),
            SCENE.into(),
            Path::new("."),
            &settings.read,
            &record,
        )
        .unwrap();
        let scene = build_source(parsed, &settings.build, &record).unwrap();
        // The collinear face is dropped by the parser; placing and the BVH count 2 units each.
        assert_eq!(scene.triangles().len(), 1);
        let phases = record.0.into_inner().unwrap();
        let bytes = SCENE.len() as u64;
        assert_eq!(
            phases,
            [
                ("parse".to_string(), bytes, bytes, true),
                ("build".to_string(), 4, 4, true)
            ]
        );
    }

    #[test]
    fn a_large_file_reports_each_byte_once() {
        let points: Vec<String> = (0..20_000).map(|i| format!("({i}, 0, 1)")).collect();
        let text = format!(
            "SBT-raytracer 1.0\npolymesh {{ points = ({}); faces = ((0, 1, 2)); }}\n",
            points.join(", ")
        );
        let settings = LoadSettings::default();
        for dialect in [None, Some(Dialect::Tokenizer), Some(Dialect::Dictionary)] {
            let settings = LoadSettings {
                read: ReadOptions {
                    ray: ParseOptions { dialect },
                    ..ReadOptions::default()
                },
                ..settings.clone()
            };
            let record = Record::default();
            let parsed = format::read_text(
                Path::new("big.ray"),
                text.clone(),
                Path::new("."),
                &settings.read,
                &record,
            );
            assert!(parsed.is_ok(), "{dialect:?}");
            let phases = record.0.into_inner().unwrap();
            let total = text.len() as u64;
            assert_eq!(phases, [("parse".to_string(), total, total, true)], "{dialect:?}");
        }
    }

    /// A file both readers accept, its floor lit by a light 5 units above it: with the UT
    /// falloff it keeps 1/25 of the light's colour there.
    fn ambiguous(color: f32) -> String {
        format!(
            "SBT-raytracer 1.0
camera {{ position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); }}
point_light {{ position = (0, 0, 3); color = ({color}, {color}, {color}); }}
translate(0, 0, -2, scale(20, square {{ material = {{ diffuse = (0.8, 0.8, 0.8); }} }}))
"
        )
    }

    fn load_ambiguous(color: f32) -> (SceneSource, Scene) {
        let settings = LoadSettings::default();
        let source = format::read_text(
            Path::new("a.ray"),
            ambiguous(color),
            Path::new("."),
            &settings.read,
            &NoProgress,
        )
        .unwrap();
        build_detected(source, &settings, &NoProgress).unwrap()
    }

    fn point_falloff(scene: &Scene) -> [f32; 3] {
        match scene.lights().course_lights().next() {
            Some(crate::light::Light::Point { attenuation, .. }) => *attenuation,
            other => panic!("{other:?}"),
        }
    }

    /// UT reading: 0.8/25 = 3.2 % of white at best, nearly black: read the HKUST way instead.
    #[test]
    fn a_nearly_black_ut_reading_is_read_the_hkust_way() {
        let (source, scene) = load_ambiguous(1.0);
        assert_eq!(point_falloff(&scene), [1.0, 0.0, 0.0]);
        assert!(
            source
                .description
                .warnings
                .iter()
                .any(|(w, _)| w.starts_with("read with the HKUST")),
            "{:?}",
            source.description.warnings
        );
    }

    /// UT reading: 2 × 0.8/25 = 6.4 % of white, dim but above the threshold: kept.
    #[test]
    fn a_dim_ut_reading_above_the_threshold_is_kept() {
        let (source, scene) = load_ambiguous(2.0);
        assert_eq!(point_falloff(&scene), [0.0, 0.0, 1.0]);
        assert!(source.description.warnings.iter().all(|(w, _)| !w.contains("HKUST")));
    }

    #[test]
    fn errors_of_either_half_name_the_file() {
        let settings = LoadSettings::default();
        let bad_syntax = format::read_text(
            Path::new("a.ray"),
            "SBT-raytracer 1.0\nsphere {".into(),
            Path::new("."),
            &settings.read,
            &NoProgress,
        );
        assert!(matches!(bad_syntax, Err(Error::Scene { path, .. }) if path == Path::new("a.ray")));
        // Textures are read while building: one that is there but is no image is refused then.
        let garbage = std::env::temp_dir().join(format!("caustica-loader-garbage-{}.png", std::process::id()));
        std::fs::write(&garbage, b"not an image").unwrap();
        let no_texture = format!(
            "SBT-raytracer 1.0\nsphere {{ material = {{ diffuse = map(\"{}\"); }} }}\n",
            garbage.display()
        );
        let parsed = format::read_text(
            Path::new("b.ray"),
            no_texture.clone(),
            Path::new("."),
            &settings.read,
            &NoProgress,
        )
        .unwrap();
        let built = build_source(parsed, &settings.build, &NoProgress);
        assert!(
            matches!(built, Err(Error::Scene { path, text, .. }) if path == Path::new("b.ray") && text == no_texture)
        );
    }
}
