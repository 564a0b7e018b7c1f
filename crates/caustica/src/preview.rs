//! A live preview of a render while it runs: the running image sent to a tev viewer
//! ([`tev`]) and/or rewritten to an image file, at an interval, from a thread of its own so
//! that a slow viewer or disk never holds the render up.
//!
//! The render feeds it two ways: the course model's Whitted tiles as they finish, through
//! [`Preview::progress`] (a [`Progress`] that also keeps the tiles), and the physical
//! integrators' mean after each pass, through [`Preview::offer`]. Only what changed since the
//! last update is sent to the viewer, in blocks of 128×128 pixels.

pub mod tev;

use crate::error::Result;
use crate::film::{Film, ToneMap};
use crate::math::Vec3;
use crate::progress::{PixelBlock, Progress};
use std::path::PathBuf;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Side of the blocks sent to the viewer: 128×128 RGB floats are 192 KiB a packet.
const BLOCK: usize = 128;

/// Where the preview goes.
#[derive(Clone, Debug, PartialEq)]
pub struct PreviewSettings {
    /// A tev viewer's `host:port` ([`tev::parse_address`]).
    pub display: Option<String>,
    /// An image file rewritten (atomically) with the running image, and its tone map.
    pub file: Option<(PathBuf, ToneMap)>,
    /// The name of the image in the viewer.
    pub name: String,
    /// Time between updates of the viewer.
    pub display_every: Duration,
    /// Time between writes of the file (encoding an image costs more than sending it).
    pub file_every: Duration,
}

impl PreviewSettings {
    /// How often the preview thread looks for changes: as often as its most frequent output.
    fn interval(&self) -> Duration {
        let display = self.display.as_ref().map(|_| self.display_every);
        let file = self.file.as_ref().map(|_| self.file_every);
        display.into_iter().chain(file).min().unwrap_or(self.file_every)
    }
}

/// What a preview did, for the front end's summary.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PreviewReport {
    /// Updates made (each sends the changed blocks and/or writes the file).
    pub updates: u64,
    /// Seconds the preview thread spent copying, encoding, sending and writing.
    pub busy_seconds: f64,
    /// Bytes sent to the viewer.
    pub bytes_sent: u64,
}

/// The image as the render last showed it, and which blocks changed since the preview thread
/// last looked.
struct Latest {
    film: Film,
    dirty: Vec<bool>,
    any_dirty: bool,
    last_offer: Option<Instant>,
    done: bool,
}

struct Shared {
    latest: Mutex<Latest>,
    wake: Condvar,
    blocks_x: usize,
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, Latest> {
        // A panic elsewhere while holding the lock leaves an image that is still worth showing.
        self.latest.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A running preview; [`Preview::finish`] ends it.
pub struct Preview {
    shared: Arc<Shared>,
    interval: Duration,
    thread: Option<JoinHandle<PreviewReport>>,
}

impl Preview {
    /// Starts the preview thread for an image of `width × height`. `warn` receives a message
    /// when the viewer cannot be reached or is lost (once each time; the preview keeps trying
    /// to reconnect) or the file cannot be written.
    pub fn start(
        width: usize,
        height: usize,
        settings: PreviewSettings,
        warn: impl Fn(String) + Send + 'static,
    ) -> Result<Preview> {
        let blocks_x = width.div_ceil(BLOCK);
        let blocks = blocks_x * height.div_ceil(BLOCK);
        let shared = Arc::new(Shared {
            latest: Mutex::new(Latest {
                film: Film::new(width, height),
                dirty: vec![false; blocks],
                any_dirty: false,
                last_offer: None,
                done: false,
            }),
            wake: Condvar::new(),
            blocks_x,
        });
        let interval = settings.interval();
        let thread = {
            let shared = Arc::clone(&shared);
            std::thread::Builder::new()
                .name("caustica-preview".into())
                .spawn(move || Updater::new(shared, settings, Box::new(warn)).run())
                .map_err(|e| crate::Error::InvalidSettings(format!("cannot start the preview thread: {e}")))?
        };
        Ok(Preview {
            shared,
            interval,
            thread: Some(thread),
        })
    }

    /// A progress that reports to `inner` and keeps the pixel blocks the render finishes.
    pub fn progress<'a>(&'a self, inner: &'a dyn Progress) -> PreviewProgress<'a> {
        PreviewProgress { inner, preview: self }
    }

    /// Offers a whole new image (a pass's mean); `image` is called only when an update is due,
    /// so offering after every pass costs nothing in between.
    pub fn offer(&self, image: impl FnOnce() -> Film) {
        {
            let latest = self.shared.lock();
            if latest.last_offer.is_some_and(|t| t.elapsed() < self.interval) {
                return;
            }
        }
        // Made outside the lock: the preview thread may be copying meanwhile.
        let film = image();
        let mut latest = self.shared.lock();
        if film.width == latest.film.width && film.height == latest.film.height {
            latest.film = film;
            latest.dirty.iter_mut().for_each(|d| *d = true);
            latest.any_dirty = true;
        }
        latest.last_offer = Some(Instant::now());
    }

    fn take_block(&self, block: &PixelBlock) {
        let mut latest = self.shared.lock();
        let latest = &mut *latest;
        let width = latest.film.width;
        if block.x + block.width > width || block.y + block.height > latest.film.height {
            return;
        }
        for (row, values) in block.pixels.chunks_exact(block.width).enumerate() {
            let start = (block.y + row) * width + block.x;
            latest.film.pixels[start..start + block.width].copy_from_slice(values);
        }
        // Render tiles lie within one preview block or straddle a few.
        for by in block.y / BLOCK..=(block.y + block.height - 1) / BLOCK {
            for bx in block.x / BLOCK..=(block.x + block.width - 1) / BLOCK {
                latest.dirty[by * self.shared.blocks_x + bx] = true;
            }
        }
        latest.any_dirty = true;
    }

    /// Shows `last` (the finished image) in the viewer and stops the thread. The file is left
    /// to the front end, which writes the final image itself.
    pub fn finish(mut self, last: &Film) -> PreviewReport {
        {
            let mut latest = self.shared.lock();
            if last.width == latest.film.width && last.height == latest.film.height {
                latest.film.pixels.copy_from_slice(&last.pixels);
                latest.dirty.iter_mut().for_each(|d| *d = true);
                latest.any_dirty = true;
            }
            latest.done = true;
        }
        self.shared.wake.notify_all();
        self.thread.take().and_then(|t| t.join().ok()).unwrap_or_default()
    }
}

impl Drop for Preview {
    fn drop(&mut self) {
        // Without finish (an error ended the render): stop the thread, sending nothing more.
        self.shared.lock().done = true;
        self.shared.wake.notify_all();
    }
}

/// The progress of a render with a preview: reports go on to the front end's progress, pixel
/// blocks into the preview.
pub struct PreviewProgress<'a> {
    inner: &'a dyn Progress,
    preview: &'a Preview,
}

impl Progress for PreviewProgress<'_> {
    fn start(&self, phase: &str, total: u64) {
        self.inner.start(phase, total);
    }

    fn advance(&self, n: u64) {
        self.inner.advance(n);
    }

    fn finish(&self) {
        self.inner.finish();
    }

    fn pixels(&self, block: &PixelBlock) {
        self.preview.take_block(block);
        self.inner.pixels(block);
    }
}

/// The preview thread's side: its own copy of the image, and the viewer and file it updates.
struct Updater {
    shared: Arc<Shared>,
    settings: PreviewSettings,
    warn: Box<dyn Fn(String) + Send>,
    image: Film,
    /// Blocks changed since the viewer was last sent them.
    unsent: Vec<bool>,
    /// Blocks the render has shown at all (the rest are still black).
    touched: Vec<bool>,
    /// Whether the file is behind the image, and when it may next be written.
    file_stale: bool,
    file_due: Option<Instant>,
    /// When the viewer may next be updated.
    viewer_due: Option<Instant>,
    viewer: Option<tev::TevClient>,
    /// When a connection was last tried, and whether the viewer was missing then.
    last_attempt: Option<Instant>,
    viewer_missing: bool,
    file_failed: bool,
    report: PreviewReport,
}

/// The preview may keep one core busy for at most this fraction of the time: after an update
/// that took t, the next waits at least t / SHARE (however short the interval), so a large
/// image or a slow disk slows the preview, not the render.
const SHARE: f64 = 0.02;

/// The time to wait after work that took `busy`, at least `interval`.
fn pause_after(busy: Duration, interval: Duration) -> Duration {
    interval.max(busy.div_f64(SHARE))
}

/// Time between attempts to reach a viewer that is not there.
const RECONNECT: Duration = Duration::from_secs(2);

impl Updater {
    fn new(shared: Arc<Shared>, settings: PreviewSettings, warn: Box<dyn Fn(String) + Send>) -> Updater {
        let (width, height, blocks) = {
            let latest = shared.lock();
            (latest.film.width, latest.film.height, latest.dirty.len())
        };
        Updater {
            shared,
            settings,
            warn,
            image: Film::new(width, height),
            unsent: vec![false; blocks],
            touched: vec![false; blocks],
            file_stale: false,
            file_due: None,
            viewer_due: None,
            viewer: None,
            last_attempt: None,
            viewer_missing: false,
            file_failed: false,
            report: PreviewReport::default(),
        }
    }

    fn run(mut self) -> PreviewReport {
        // The viewer shows the (black) image from the start.
        self.update(false);
        loop {
            let done = {
                let latest = self.shared.lock();
                let (latest, _) = self
                    .shared
                    .wake
                    .wait_timeout_while(latest, self.settings.interval(), |l| !l.done)
                    .unwrap_or_else(|e| e.into_inner());
                latest.done
            };
            self.update(done);
            if done {
                return self.report;
            }
        }
    }

    /// Takes the changed blocks and sends them on.
    fn update(&mut self, last: bool) {
        let start = Instant::now();
        let changed = self.take_changes();
        if changed || last || self.viewer.is_none() {
            self.send_to_viewer(last);
        }
        if !last {
            self.write_file();
        }
        if changed {
            self.report.updates += 1;
        }
        self.report.busy_seconds += start.elapsed().as_secs_f64();
    }

    fn take_changes(&mut self) -> bool {
        let mut latest = self.shared.lock();
        if !latest.any_dirty {
            return false;
        }
        let latest = &mut *latest;
        let width = self.image.width;
        for (b, dirty) in latest.dirty.iter_mut().enumerate() {
            if !std::mem::take(dirty) {
                continue;
            }
            let (x0, y0, w, h) = self.block_rect(b);
            for y in y0..y0 + h {
                let row = y * width + x0;
                self.image.pixels[row..row + w].copy_from_slice(&latest.film.pixels[row..row + w]);
            }
            self.unsent[b] = true;
            self.touched[b] = true;
        }
        latest.any_dirty = false;
        self.file_stale = true;
        true
    }

    fn block_rect(&self, b: usize) -> (usize, usize, usize, usize) {
        let (x0, y0) = ((b % self.shared.blocks_x) * BLOCK, (b / self.shared.blocks_x) * BLOCK);
        let w = BLOCK.min(self.image.width - x0);
        let h = BLOCK.min(self.image.height - y0);
        (x0, y0, w, h)
    }

    fn send_to_viewer(&mut self, last: bool) {
        let Some(address) = self.settings.display.clone() else {
            return;
        };
        if !last && matches!(self.viewer_due, Some(t) if Instant::now() < t) {
            return;
        }
        let start = Instant::now();
        self.send_blocks(&address);
        self.viewer_due = Some(Instant::now() + pause_after(start.elapsed(), self.settings.display_every));
    }

    /// Connects if need be, then sends the blocks the viewer has not seen.
    fn send_blocks(&mut self, address: &str) {
        if self.viewer.is_none() {
            if self.last_attempt.is_some_and(|t| t.elapsed() < RECONNECT) {
                return;
            }
            self.last_attempt = Some(Instant::now());
            match tev::TevClient::connect(address) {
                Ok(client) => {
                    self.viewer = Some(client);
                    self.viewer_missing = false;
                    // A new connection (or a restarted viewer) starts from a black image.
                    self.unsent.copy_from_slice(&self.touched);
                    let create = tev::create_image(
                        &self.settings.name,
                        self.image.width,
                        self.image.height,
                        &tev::RGB,
                        true,
                    );
                    if !self.send(&create) {
                        return;
                    }
                }
                Err(e) => {
                    if !self.viewer_missing {
                        (self.warn)(format!(
                            "cannot reach a tev viewer at {address} ({e}); rendering on, trying again every {} s",
                            RECONNECT.as_secs()
                        ));
                        self.viewer_missing = true;
                    }
                    return;
                }
            }
        }
        let mut rgb = Vec::with_capacity(BLOCK * BLOCK * 3);
        for b in 0..self.unsent.len() {
            if !self.unsent[b] {
                continue;
            }
            let (x0, y0, w, h) = self.block_rect(b);
            rgb.clear();
            for y in y0..y0 + h {
                let row = y * self.image.width + x0;
                rgb.extend(self.image.pixels[row..row + w].iter().flat_map(|p: &Vec3| p.to_array()));
            }
            let packet = tev::update_rgb(&self.settings.name, x0, y0, w, h, &rgb);
            if !self.send(&packet) {
                return;
            }
            self.unsent[b] = false;
        }
    }

    /// Sends a packet; on failure drops the connection (it is tried again later).
    fn send(&mut self, packet: &[u8]) -> bool {
        let Some(viewer) = self.viewer.as_mut() else {
            return false;
        };
        match viewer.send(packet) {
            Ok(()) => {
                self.report.bytes_sent += packet.len() as u64;
                true
            }
            Err(e) => {
                (self.warn)(format!("lost the tev viewer ({e}); rendering on, trying to reconnect"));
                self.viewer = None;
                self.viewer_missing = true;
                self.last_attempt = Some(Instant::now());
                false
            }
        }
    }

    fn write_file(&mut self) {
        let Some((path, tone_map)) = &self.settings.file else {
            return;
        };
        let due = !matches!(self.file_due, Some(t) if Instant::now() < t);
        if !self.file_stale || !due {
            return;
        }
        self.file_stale = false;
        let start = Instant::now();
        let written = self.image.save(path, *tone_map);
        self.file_due = Some(Instant::now() + pause_after(start.elapsed(), self.settings.file_every));
        if let Err(e) = written {
            if !self.file_failed {
                (self.warn)(format!("cannot write the preview: {e}"));
                self.file_failed = true;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;

    #[test]
    fn slow_updates_wait_longer_than_the_interval() {
        let interval = Duration::from_millis(500);
        // Quick work keeps the interval; slow work waits fifty times as long as it took.
        assert_eq!(pause_after(Duration::from_millis(2), interval), interval);
        assert_eq!(pause_after(Duration::from_millis(40), interval), Duration::from_secs(2));
    }

    #[test]
    fn tiles_and_passes_reach_the_file() {
        let dir = std::env::temp_dir().join(format!("caustica-preview-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("p.exr");
        let settings = PreviewSettings {
            display: None,
            file: Some((path.clone(), ToneMap::Clamp { exposure: 0.0 })),
            name: "p".into(),
            display_every: Duration::from_secs(3600),
            file_every: Duration::from_millis(5),
        };
        let preview = Preview::start(200, 3, settings, |m| panic!("{m}")).unwrap();
        // A tile straddling two preview blocks.
        let pixels = vec![Vec3::new(1.0, 2.0, 3.0); 20 * 2];
        preview.progress(&NoProgress).pixels(&PixelBlock {
            x: 120,
            y: 1,
            width: 20,
            height: 2,
            pixels: &pixels,
        });
        let deadline = Instant::now() + Duration::from_secs(10);
        let read = || crate::image_io::read_exr(&path).ok();
        while !matches!(read(), Some((_, _, p)) if p[200 + 139] == Vec3::new(1.0, 2.0, 3.0)) {
            assert!(Instant::now() < deadline, "the tile never reached the file");
            std::thread::sleep(Duration::from_millis(5));
        }
        let (_, _, shown) = read().unwrap();
        assert_eq!(shown[200 + 119], Vec3::ZERO);
        assert_eq!(shown[0], Vec3::ZERO);
        // A whole image offered after a pass replaces it.
        let mut pass = Film::new(200, 3);
        pass.pixels.iter_mut().for_each(|p| *p = Vec3::splat(0.5));
        preview.offer(|| pass.clone());
        while !matches!(read(), Some((_, _, p)) if p[0] == Vec3::splat(0.5)) {
            assert!(Instant::now() < deadline, "the pass never reached the file");
            std::thread::sleep(Duration::from_millis(5));
        }
        let report = preview.finish(&pass);
        assert!(report.updates >= 2 && report.bytes_sent == 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
