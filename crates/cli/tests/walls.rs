//! Scenes with walls end to end: a wound opens after the relaxation and closes, `analyze`
//! measures its gap, `render` draws the wall in grey while it stands, and `export vtk`
//! writes the wall field of each frame; a mask file is read from the scene's directory.

use crate::common::{bin, scene_path, stderr};

/// The wound scene, shrunk (80 × 50, 15 cells), relaxed 50 TU and run 200 TU, on two
/// threads, is the same run on one thread to the byte; its gap is 1 while the band stands
/// and falls after it opens; render and VTK show the wall during the relaxation only.
#[test]
fn a_wound_opens_closes_and_is_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let run = |out: &std::path::Path, threads: &str| {
        bin()
            .arg("run")
            .arg(scene_path("wound.toml"))
            .arg("--out")
            .arg(out)
            .args(["--quiet", "--threads", threads])
            .args([
                "--set",
                "domain.lx=80",
                "--set",
                "domain.ly=50",
                "--set",
                "cells.count=15",
            ])
            .args(["--set", "run.relax_time=50", "--set", "run.time=200"])
            .args([
                "--set",
                "run.output_every=25",
                "--set",
                "run.series_every=25",
            ])
            .output()
            .unwrap()
    };
    let out = dir.path().join("wound");
    let o = run(&out, "2");
    assert!(o.status.success(), "{}", stderr(&o));
    let one = dir.path().join("one");
    assert!(run(&one, "1").status.success());
    assert!(
        crate::common::run_files(&out) == crate::common::run_files(&one),
        "one thread differs from two"
    );
    let o = bin()
        .arg("analyze")
        .arg(&out)
        .args(["--from", "0"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let table = std::fs::read_to_string(out.join("analysis/observables.csv")).unwrap();
    let header: Vec<&str> = table.lines().next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|&h| h == "gap")
        .expect("a gap column");
    let gaps: Vec<(f64, f64)> = table
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<&str> = l.split(',').collect();
            (v[1].parse().unwrap(), v[col].parse().unwrap())
        })
        .collect();
    for &(t, g) in &gaps {
        if t < 50.0 {
            assert_eq!(g, 1.0, "the band is open before it opens: {gaps:?}");
        }
    }
    let last = gaps.last().unwrap().1;
    assert!(last < 0.75, "the gap does not close: {gaps:?}");

    // VTK: the wall field while the band stands, none after.
    let vtk = dir.path().join("vtk");
    let o = bin()
        .args(["export", "vtk"])
        .arg(&out)
        .args(["--frames", "50,300", "--out"])
        .arg(&vtk)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let before = rundir::vtk::read_vti(&vtk.join("fields_00000050.vti")).unwrap();
    let array = |f: &rundir::vtk::VtiFile, name: &str| {
        f.arrays.iter().find(|a| a.0 == name).map(|a| a.2.clone())
    };
    let wall = array(&before, "wall").expect("a wall field during the relaxation");
    // Node (40, 25) is in the middle of the band (20 nodes wide): solid.
    assert_eq!(wall[40 * 50 + 25], 1.0);
    assert_eq!(wall[5 * 50 + 25], 0.0);
    let after = rundir::vtk::read_vti(&vtk.join("fields_00000300.vti")).unwrap();
    assert!(array(&after, "wall").is_none(), "the wound has opened");

    // Render: the band's middle is the wall's grey during the relaxation.
    let png_dir = dir.path().join("png");
    let o = bin()
        .arg("render")
        .arg(&out)
        .args(["--frames", "50", "--quiet", "--out"])
        .arg(&png_dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let file = std::fs::File::open(png_dir.join("frame_00000050.png")).unwrap();
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let (w, h) = (info.width as usize, info.height as usize);
    let grey = (0..h)
        .filter(|&row| {
            let p = &buf[row * info.line_size + (w / 2) * channels..];
            p[0] == 140 && p[1] == 140 && p[2] == 140
        })
        .count();
    assert!(grey > h / 2, "{grey} of {h} rows grey in the middle column");
}

/// A mask given relative to the scene file is found from another directory, and a run
/// between its walls keeps the cells out of them.
#[test]
fn a_mask_is_read_from_the_scene_directory() {
    let dir = tempfile::tempdir().unwrap();
    let (lx, ly) = (60usize, 40usize);
    // Solid: a square block of 12 nodes in the middle, stored [x, y].
    let values: Vec<u8> = (0..lx * ly)
        .map(|k| {
            let (x, y) = (k / ly, k % ly);
            u8::from((24..36).contains(&x) && (14..26).contains(&y))
        })
        .collect();
    let npy = rundir::npy(&[lx as u64, ly as u64], values).unwrap();
    std::fs::create_dir(dir.path().join("scene")).unwrap();
    std::fs::write(dir.path().join("scene/block.npy"), npy).unwrap();
    let scene = "[domain]\nlx = 60\nly = 40\n[cells]\ncount = 6\nradius = 6.0\n[walls]\nkind = \"mask\"\nmask = \"block.npy\"\n[integrator]\nmargin = 12\n[run]\nrelax_time = 0\ntime = 50\noutput_every = 50\n";
    std::fs::write(dir.path().join("scene/s.toml"), scene).unwrap();
    let out = dir.path().join("out");
    let o = bin()
        .current_dir(dir.path())
        .args(["run", "scene/s.toml", "--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let a = rundir::read_npz(&out.join("frames/frame_00000100.npz"), &["centre"]).unwrap();
    for c in a[0].data.chunks_exact(2) {
        let inside = (24.0..36.0).contains(&c[0]) && (14.0..26.0).contains(&c[1]);
        assert!(!inside, "a cell in the block: {c:?}");
    }
}
