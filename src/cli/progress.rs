//! Progress on standard error while a build runs.

use std::cell::RefCell;
use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

use brickwright::pipeline::Progress;

/// Spinners on standard error, one per stage; hidden when not a terminal.
#[derive(Default)]
pub struct Spinners {
    bar: RefCell<Option<ProgressBar>>,
}

impl Progress for Spinners {
    fn stage(&self, name: &str) {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("valid template"),
        );
        bar.set_message(name.to_string());
        bar.enable_steady_tick(Duration::from_millis(120));
        *self.bar.borrow_mut() = Some(bar);
    }
    fn done(&self) {
        if let Some(b) = self.bar.borrow_mut().take() {
            b.finish_and_clear();
        }
    }
    fn advance(&self, done: u64, total: u64) {
        if let Some(b) = self.bar.borrow().as_ref() {
            if b.length() != Some(total) {
                // From a spinner to a bar with counts and time left.
                b.set_style(
                    ProgressStyle::with_template(
                        "{spinner} {msg} [{bar:30}] {pos}/{len}, {eta} left",
                    )
                    .expect("valid template")
                    .progress_chars("=> "),
                );
                b.set_length(total);
            }
            b.set_position(done);
        }
    }
}
