//! `monolayer render` and `monolayer export vtk`: a progress report around
//! `study::view::{render_run, export_vtk}`.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

/// A progress report of frames: a bar on a terminal, a line about every 10 % otherwise,
/// nothing when `quiet`. Call it with `(done, total)`.
pub fn frames_progress(what: &'static str, quiet: bool) -> impl FnMut(usize, usize) {
    let mut bar: Option<ProgressBar> = None;
    let mut lines = crate::lines::Lines::new();
    move |done, total| {
        if quiet {
            return;
        }
        if std::io::stderr().is_terminal() {
            let b = bar.get_or_insert_with(|| {
                let b = ProgressBar::new(total as u64);
                b.set_style(
                    ProgressStyle::with_template(&format!(
                        "{{bar:40}} {{pos}}/{{len}} frames {what}  [{{elapsed_precise}} < {{eta_precise}}]"
                    ))
                    .expect("valid template"),
                );
                b
            });
            b.set_position(done as u64);
            if done == total {
                b.finish();
            }
        } else if lines.due(done as f64, total as f64) {
            crate::say!("{done}/{total} frames {what}");
        }
    }
}
