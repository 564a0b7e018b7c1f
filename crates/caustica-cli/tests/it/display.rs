//! The live preview: `--display` against a stand-in tev viewer that decodes every packet the way
//! tev's protocol lays them out, and `--preview` watched from outside while a render runs.

use assert_cmd::Command;
use caustica::image_io::read_exr;
use caustica::math::Vec3;
use std::io::Read;
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

fn caustica() -> Command {
    Command::cargo_bin("caustica").expect("the binary is built")
}

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-display-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A rectangle of RGB values the viewer was sent.
#[derive(Debug)]
struct Update {
    x: usize,
    y: usize,
    width: usize,
    height: usize,
    rgb: Vec<Vec3>,
}

/// Everything the viewer received.
#[derive(Debug, Default)]
struct Received {
    /// CreateImage packets: name, width, height, channel names, grab focus.
    creates: Vec<(String, usize, usize, Vec<String>, bool)>,
    updates: Vec<Update>,
    /// The image as tev would show it after the last packet.
    image: Vec<Vec3>,
}

/// Reads the fields of one packet, refusing to run past its end.
struct Cursor<'a>(&'a [u8]);

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if self.0.len() < n {
            return Err(format!("the packet ends {n} bytes early"));
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }
    fn byte(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn i32(&mut self) -> Result<i32, String> {
        Ok(i32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    fn i64(&mut self) -> Result<i64, String> {
        Ok(i64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    fn f32(&mut self) -> Result<f32, String> {
        Ok(f32::from_le_bytes(self.take(4)?.try_into().unwrap()))
    }
    fn string(&mut self) -> Result<String, String> {
        let end = self.0.iter().position(|&b| b == 0).ok_or("a string without its NUL")?;
        let s = String::from_utf8(self.take(end)?.to_vec()).map_err(|e| e.to_string())?;
        self.take(1)?;
        Ok(s)
    }
    fn size(&mut self) -> Result<usize, String> {
        usize::try_from(self.i32()?).map_err(|_| "a negative size".to_string())
    }
}

/// Decodes one packet (its length already stripped) into `received`.
fn decode(packet: &[u8], received: &mut Received) -> Result<(), String> {
    let mut c = Cursor(packet);
    match c.byte()? {
        4 => {
            let focus = c.byte()? == 1;
            let name = c.string()?;
            let (w, h, n) = (c.size()?, c.size()?, c.size()?);
            let channels = (0..n).map(|_| c.string()).collect::<Result<Vec<_>, _>>()?;
            received.image = vec![Vec3::ZERO; w * h];
            received.creates.push((name, w, h, channels, focus));
        }
        6 => {
            let (_, width, height, _, _) = received.creates.last().ok_or("an update before CreateImage")?.clone();
            c.byte()?;
            let name = c.string()?;
            if name != received.creates.last().unwrap().0 {
                return Err(format!("an update of another image, {name}"));
            }
            let n = c.size()?;
            let channels = (0..n).map(|_| c.string()).collect::<Result<Vec<_>, _>>()?;
            let (x, y, w, h) = (c.size()?, c.size()?, c.size()?, c.size()?);
            let offsets = (0..n).map(|_| c.i64()).collect::<Result<Vec<_>, _>>()?;
            let strides = (0..n).map(|_| c.i64()).collect::<Result<Vec<_>, _>>()?;
            let mut data = Vec::new();
            while !c.0.is_empty() {
                data.push(c.f32()?);
            }
            let pixels = w * h;
            // tev's own check: every channel's last value lies within the data.
            for (o, s) in offsets.iter().zip(&strides) {
                let last = o + (pixels as i64 - 1) * s;
                if *o < 0 || last >= data.len() as i64 {
                    return Err("insufficient image data".into());
                }
            }
            if x + w > width || y + h > height {
                return Err(format!(
                    "a rectangle {x},{y} {w}×{h} outside the {width}×{height} image"
                ));
            }
            let mut rgb = vec![Vec3::ZERO; pixels];
            for (ci, name) in channels.iter().enumerate() {
                let slot = ["R", "G", "B"]
                    .iter()
                    .position(|c| c == name)
                    .ok_or(format!("channel {name}"))?;
                for (p, value) in rgb.iter_mut().enumerate() {
                    value[slot] = data[(offsets[ci] + p as i64 * strides[ci]) as usize];
                }
            }
            for (p, value) in rgb.iter().enumerate() {
                received.image[(y + p / w) * width + x + p % w] = *value;
            }
            received.updates.push(Update {
                x,
                y,
                width: w,
                height: h,
                rgb,
            });
        }
        other => return Err(format!("unexpected packet type {other}")),
    }
    Ok(())
}

/// A viewer on an ephemeral port: it takes one connection and decodes it until it closes.
fn viewer() -> (u16, JoinHandle<Result<Received, String>>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    listener.set_nonblocking(true).unwrap();
    let server = std::thread::spawn(move || {
        let deadline = Instant::now() + Duration::from_secs(120);
        let mut stream: TcpStream = loop {
            match listener.accept() {
                Ok((stream, _)) => break stream,
                Err(_) if Instant::now() < deadline => std::thread::sleep(Duration::from_millis(5)),
                Err(e) => return Err(format!("no connection: {e}")),
            }
        };
        stream.set_nonblocking(false).unwrap();
        stream.set_read_timeout(Some(Duration::from_secs(120))).unwrap();
        let mut received = Received::default();
        loop {
            let mut len = [0u8; 4];
            match stream.read(&mut len[..1]) {
                Ok(0) => return Ok(received),
                Ok(_) => stream.read_exact(&mut len[1..]).map_err(|e| e.to_string())?,
                Err(e) => return Err(e.to_string()),
            }
            let len = u32::from_le_bytes(len) as usize;
            if !(5..=64 << 20).contains(&len) {
                return Err(format!("a packet length of {len}"));
            }
            let mut packet = vec![0; len - 4];
            stream.read_exact(&mut packet).map_err(|e| e.to_string())?;
            decode(&packet, &mut received)?;
        }
    });
    (port, server)
}

fn render_with_viewer(out: &Path, args: &[&str]) -> Received {
    let (port, server) = viewer();
    caustica()
        .arg("render")
        .args(args)
        .arg("-o")
        .arg(out)
        .args(["--quiet", "--display", &format!("127.0.0.1:{port}")])
        .assert()
        .success();
    server.join().unwrap().unwrap()
}

#[test]
fn the_viewer_gets_a_colour_image_and_ends_with_the_exr() {
    let dir = temp_dir("whitted");
    let out = dir.join("ring.exr");
    let scene = scenes().join("ring.ray");
    let received = render_with_viewer(&out, &[scene.to_str().unwrap(), "--width", "150", "--photons", "5000"]);
    let (w, h, pixels) = read_exr(&out).unwrap();
    assert_eq!(received.creates.len(), 1);
    let (name, cw, ch, channels, focus) = &received.creates[0];
    assert_eq!((name.as_str(), *cw, *ch, focus), ("ring.exr", w, h, &true));
    assert_eq!(channels, &["R", "G", "B"]);
    // 150 wide is two blocks across; the image is bit for bit the file's.
    assert!(received.updates.iter().all(|u| u.width <= 128 && u.height <= 128));
    assert_eq!(received.image, pixels);
}

#[test]
fn the_viewer_follows_the_passes_of_a_physical_render() {
    let dir = temp_dir("passes");
    let out = dir.join("sphere.exr");
    let scene = scenes().join("glass_sphere.ray");
    let args = [
        scene.to_str().unwrap(),
        "--model",
        "physical",
        "--passes",
        "4",
        "--width",
        "40",
    ];
    let received = render_with_viewer(&out, &args);
    let (_, _, pixels) = read_exr(&out).unwrap();
    assert_eq!(received.image, pixels);
    assert!(!received.updates.is_empty());
}

#[test]
fn whitted_tiles_are_shown_before_the_image_is_done() {
    let dir = temp_dir("tiles");
    let out = dir.join("ring.exr");
    let scene = scenes().join("ring.ray");
    // About a second of rendering, shown every 20 ms.
    let args = [
        scene.to_str().unwrap(),
        "--width",
        "320",
        "--aa",
        "3",
        "--photons",
        "50000",
        "--preview-every",
        "0.02",
    ];
    let received = render_with_viewer(&out, &args);
    let (w, _, pixels) = read_exr(&out).unwrap();
    assert_eq!(received.image, pixels);
    // Some rectangle was sent while its tiles were still being rendered: it differs from the
    // finished image there.
    let unfinished = received.updates.iter().any(|u| {
        u.rgb
            .iter()
            .enumerate()
            .any(|(p, v)| *v != pixels[(u.y + p / u.width) * w + u.x + p % u.width])
    });
    assert!(unfinished, "{} updates, all of finished pixels", received.updates.len());
}

#[test]
fn a_missing_viewer_costs_a_warning_not_the_render() {
    let dir = temp_dir("missing");
    let out = dir.join("ring.png");
    // A port nothing listens on: bound, then closed.
    let port = TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let assert = caustica()
        .args(["render", "--width", "32", "--photons", "2000", "--display"])
        .arg(format!("127.0.0.1:{port}"))
        .arg("-o")
        .arg(&out)
        .assert()
        .success();
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
    assert!(
        stderr.contains("warning: preview: cannot reach a tev viewer"),
        "{stderr}"
    );
    assert!(out.is_file());
}

#[test]
fn bad_preview_options_are_refused_before_any_work() {
    for (args, words) in [
        (vec!["--display", "viewer:"], "expected [HOST:]PORT"),
        (vec!["--display", "99999"], "expected [HOST:]PORT"),
        (
            vec!["--preview-every", "0"],
            "--preview-every must be a positive number",
        ),
        (
            vec!["--preview", "--model", "physical", "--partial", "x.part"],
            "--preview rewrites the output image",
        ),
    ] {
        let assert = caustica().arg("render").args(&args).assert().code(2);
        let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
        assert!(stderr.contains(words), "{args:?}: {stderr}");
    }
}

#[test]
fn preview_rewrites_the_output_while_the_render_runs() {
    let dir = temp_dir("file");
    let out = dir.join("sphere.exr");
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("caustica"))
        .arg("render")
        .arg(scenes().join("glass_sphere.ray"))
        .args([
            "--model",
            "physical",
            "--width",
            "96",
            "--photons",
            "100000",
            "--passes",
            "40",
        ])
        .args(["--preview", "--preview-every", "0.05", "--quiet", "-o"])
        .arg(&out)
        .spawn()
        .unwrap();
    let (mut seen, mut distinct, mut last) = (0, 0, None);
    let deadline = Instant::now() + Duration::from_secs(120);
    while child.try_wait().unwrap().is_none() {
        assert!(Instant::now() < deadline, "the render did not end");
        if out.exists() {
            // Written atomically: whenever the file is there, it is a whole image.
            let (_, _, pixels) = read_exr(&out).expect("a complete image");
            seen += 1;
            if last.as_ref() != Some(&pixels) {
                distinct += 1;
                last = Some(pixels);
            }
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(child.wait().unwrap().success());
    assert!(
        seen > 0 && distinct >= 2,
        "{seen} reads during the render, {distinct} different images"
    );
    assert!(read_exr(&out).is_ok());
}
