//! Progress bars on stderr for the phases (parse, build, photons, render).

use caustica::progress::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// A phase draws only once it has lasted this long, so quick phases do not flicker.
const SHOW_AFTER: Duration = Duration::from_millis(500);

/// The phase being shown, numbered so a late reveal cannot show a finished phase's bar.
#[derive(Default)]
struct Current {
    phase: u64,
    bar: Option<ProgressBar>,
}

/// One indicatif bar per phase on stderr (drawn only on a terminal), none when quiet.
pub struct Bars {
    quiet: bool,
    current: Arc<Mutex<Current>>,
}

impl Bars {
    /// Bars that draw unless `quiet`.
    pub fn new(quiet: bool) -> Bars {
        Bars {
            quiet,
            current: Arc::default(),
        }
    }

    /// Starts `bar` hidden; a timer thread draws it if the phase is still running later.
    fn begin(&self, phase: &str, bar: ProgressBar) {
        bar.set_prefix(phase.to_string());
        let id = {
            let Ok(mut current) = self.current.lock() else { return };
            if let Some(old) = current.bar.take() {
                old.finish_and_clear();
            }
            current.phase += 1;
            current.bar = Some(bar);
            current.phase
        };
        let current = Arc::clone(&self.current);
        std::thread::spawn(move || {
            std::thread::sleep(SHOW_AFTER);
            let Ok(current) = current.lock() else { return };
            if let (true, Some(bar)) = (current.phase == id, current.bar.as_ref()) {
                bar.set_draw_target(ProgressDrawTarget::stderr());
                // Ticks keep the elapsed time and ETA moving between reports.
                bar.enable_steady_tick(Duration::from_millis(200));
            }
        });
    }
}

impl Progress for Bars {
    fn start(&self, phase: &str, total: u64) {
        if self.quiet {
            return;
        }
        let bar = ProgressBar::hidden();
        bar.set_length(total);
        bar.set_style(
            ProgressStyle::with_template("{prefix:>8} [{bar:40}] {percent:>3}%  {elapsed_precise} (ETA {eta})")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        self.begin(phase, bar);
    }

    fn advance(&self, n: u64) {
        if let Ok(current) = self.current.lock() {
            if let Some(bar) = current.bar.as_ref() {
                bar.inc(n);
            }
        }
    }

    fn finish(&self) {
        if let Ok(mut current) = self.current.lock() {
            if let Some(bar) = current.bar.take() {
                bar.finish_and_clear();
            }
        }
    }
}
