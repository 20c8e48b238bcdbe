//! Helpers shared by the binary's test files.

use std::path::Path;

/// `series.csv` and every frame of a run directory, by name, in name order: what must be
/// byte-identical between two runs that should agree.
pub fn run_files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v = vec![(
        "series.csv".to_string(),
        std::fs::read(dir.join("series.csv")).unwrap(),
    )];
    let mut frames: Vec<_> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    frames.sort();
    for f in frames {
        v.push((
            f.file_name().unwrap().to_string_lossy().into_owned(),
            std::fs::read(&f).unwrap(),
        ));
    }
    v
}
