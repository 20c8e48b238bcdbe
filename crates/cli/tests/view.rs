//! `monolayer render` and `monolayer export vtk` end to end, on a short run of the paper
//! scene: the files exist, decode, hold every frame, and carry the frame's values, checked
//! by our own reader and by VTK's.

use crate::common::{bin, python_has, run_python, stderr};
use std::path::{Path, PathBuf};
use std::process::Command;

/// A short run of the paper scene (4 TU relaxation, 6 TU activity at ζ = 0.01, a frame every
/// 2 TU: 6 frames), into `dir/run`.
fn short_run(dir: &Path) -> PathBuf {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/paper.toml");
    let out = dir.join("run");
    let o = bin()
        .arg("run")
        .arg(scene)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .args(["--set", "run.relax_time=4", "--set", "run.time=6"])
        .args(["--set", "run.output_every=2", "--set", "model.zeta=0.01"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    out
}

fn files(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    v.sort();
    v
}

/// One PNG per frame, all of one size and decodable, and movies (GIF, APNG) with as many
/// frames as the run; bad options are refused by name before anything is written.
#[test]
fn render_draws_every_frame_and_movies_with_as_many_frames() {
    let dir = tempfile::tempdir().unwrap();
    let run = short_run(dir.path());
    let n_frames = files(&run.join("frames"), "npz").len();
    assert_eq!(n_frames, 6);
    let out = dir.path().join("png");
    let o = bin()
        .arg("render")
        .arg(&run)
        .arg("--out")
        .arg(&out)
        .args([
            "--colour",
            "velocity",
            "--director",
            "--defects",
            "--flow",
            "--axes",
        ])
        .args(["--size", "300", "-q", "--movie"])
        .arg(dir.path().join("m.gif"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let pngs = files(&out, "png");
    assert_eq!(pngs.len(), n_frames);
    let mut sizes = Vec::new();
    for p in &pngs {
        let d = png::Decoder::new(std::fs::File::open(p).unwrap());
        let r = d.read_info().unwrap();
        sizes.push((r.info().width, r.info().height));
    }
    assert!(sizes.iter().all(|s| *s == sizes[0]) && sizes[0].0 > 300);
    let mut gif = gif::DecodeOptions::new()
        .read_info(std::fs::File::open(dir.path().join("m.gif")).unwrap())
        .unwrap();
    let mut n = 0;
    while gif.read_next_frame().unwrap().is_some() {
        n += 1;
    }
    assert_eq!(n, n_frames, "GIF frames");
    // APNG only, no PNGs, two frames picked by step.
    let o = bin()
        .arg("render")
        .arg(&run)
        .arg("--out")
        .arg(dir.path().join("none"))
        .args([
            "--frames",
            "0,50",
            "--colour",
            "pressure",
            "--no-pngs",
            "-q",
            "--movie",
        ])
        .arg(dir.path().join("m.apng"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let d = png::Decoder::new(std::fs::File::open(dir.path().join("m.apng")).unwrap());
    let r = d.read_info().unwrap();
    assert_eq!(r.info().animation_control().unwrap().num_frames, 2);
    assert!(files(&dir.path().join("none"), "png").is_empty());

    let refuse = |args: &[&str], want: &str| {
        let o = bin()
            .arg("render")
            .arg(&run)
            .arg("--out")
            .arg(dir.path().join("bad"))
            .args(args)
            .output()
            .unwrap();
        let e = stderr(&o);
        assert!(!o.status.success() && e.contains(want), "{args:?}: {e}");
        assert!(!dir.path().join("bad").join("frame_00000000.png").exists());
    };
    refuse(
        &["--frames", "7"],
        "no frame at step 7; it has 6 frames, steps 0 to 50",
    );
    refuse(&["--frames", "x"], "'x' is not a step");
    refuse(&["--colour", "blue"], "use none, velocity, pressure");
    refuse(&["--range", "1"], "give two numbers LOW,HIGH");
    refuse(&["--range", "2,1"], "the low one first");
    refuse(&["--size", "0"], "from 16 to 8000");
    refuse(&["--movie", "m.avi"], ".gif, .apng or .mp4");
    if Command::new("ffmpeg").arg("-version").output().is_err() {
        refuse(&["--movie", "m.mp4"], "ffmpeg on the PATH");
    }
}

/// The frame's own φ, pasted into the lattice: `Σ_i φ_i` and the owner (−1 below ½).
fn phi_sum_and_owner(frame: &Path, lx: usize, ly: usize) -> (Vec<f64>, Vec<f64>) {
    let a = rundir::read_npz(frame, &["origin", "phi"]).unwrap();
    let (n, nx, ny) = (
        a[1].shape[0] as usize,
        a[1].shape[1] as usize,
        a[1].shape[2] as usize,
    );
    let (mut sum, mut best, mut owner) =
        (vec![0.0; lx * ly], vec![0.5; lx * ly], vec![-1.0; lx * ly]);
    for i in 0..n {
        let (ox, oy) = (a[0].data[2 * i] as usize, a[0].data[2 * i + 1] as usize);
        for u in 0..nx {
            for v in 0..ny {
                let k = ((ox + u) % lx) * ly + (oy + v) % ly;
                let f = a[1].data[(i * nx + u) * ny + v];
                sum[k] += f;
                if f > best[k] {
                    best[k] = f;
                    owner[k] = i as f64;
                }
            }
        }
    }
    (sum, owner)
}

/// `export vtk` writes a .vti and a .vtp per frame and the two .pvd series. Our reader finds
/// the lattice's dimensions, every array, `phi_sum` equal to the frame's Σφ_i to float32
/// rounding and `cell_id` equal to its owner map; VTK's own XML readers (the `vtk` Python
/// package, which CI installs) agree on dimensions, components, values and times.
#[test]
fn export_vtk_round_trips_through_our_reader_and_vtks() {
    let dir = tempfile::tempdir().unwrap();
    let run = short_run(dir.path());
    let o = bin()
        .args(["export", "vtk"])
        .arg(&run)
        .arg("-q")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let out = run.join("vtk");
    let frames = files(&run.join("frames"), "npz");
    assert_eq!(files(&out, "vti").len(), frames.len());
    assert_eq!(files(&out, "vtp").len(), frames.len());
    let last = frames.last().unwrap();
    let step = last
        .file_stem()
        .unwrap()
        .to_str()
        .unwrap()
        .trim_start_matches("frame_");
    let vti = rundir::vtk::read_vti(&out.join(format!("fields_{step}.vti"))).unwrap();
    assert_eq!((vti.lx, vti.ly), (100, 100));
    let time = rundir::read_npz(last, &["time"]).unwrap()[0].data[0];
    assert_eq!(vti.time, time);
    let names: Vec<(&str, usize)> = vti.arrays.iter().map(|a| (a.0.as_str(), a.1)).collect();
    assert_eq!(
        names,
        [
            ("phi_sum", 1),
            ("cell_id", 1),
            ("velocity", 3),
            ("Q", 2),
            ("director", 3),
            ("pressure", 1),
            ("sigma_xx", 1),
            ("sigma_yy", 1),
            ("sigma_xy", 1)
        ]
    );
    let (sum, owner) = phi_sum_and_owner(last, 100, 100);
    for (k, (&got, &want)) in vti.arrays[0].2.iter().zip(&sum).enumerate() {
        assert!(
            (got - want).abs() <= 1e-6 * want.abs().max(1.0),
            "phi_sum at {k}: {got} vs {want}"
        );
    }
    assert_eq!(vti.arrays[1].2, owner);
    assert!(owner.iter().any(|&o| o < 0.0) && owner.iter().any(|&o| o >= 59.0));

    if !python_has("vtkmodules.vtkIOXML, numpy", "vtk") {
        return;
    }
    let script = format!(
        r#"
import glob, os, xml.etree.ElementTree as ET
import numpy as np
from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLPolyDataReader
from vtkmodules.util.numpy_support import vtk_to_numpy
run, out = "{run}", "{out}"
frames = sorted(glob.glob(os.path.join(run, "frames", "frame_*.npz")))
for pvd, kind in (("fields.pvd", "vti"), ("cells.pvd", "vtp")):
    sets = ET.parse(os.path.join(out, pvd)).getroot().find("Collection").findall("DataSet")
    assert len(sets) == len(frames), (pvd, len(sets))
    for ds, f in zip(sets, frames):
        z = np.load(f)
        assert abs(float(ds.get("timestep")) - float(z["time"])) < 1e-9 * max(1.0, float(z["time"]))
        path = os.path.join(out, ds.get("file"))
        if kind == "vti":
            r = vtkXMLImageDataReader(); r.SetFileName(path); r.Update()
            img = r.GetOutput()
            assert img.GetDimensions() == (100, 100, 1), img.GetDimensions()
            pd = img.GetPointData()
            comps = {{pd.GetArrayName(i): pd.GetArray(i).GetNumberOfComponents() for i in range(pd.GetNumberOfArrays())}}
            assert comps == {{"phi_sum": 1, "cell_id": 1, "velocity": 3, "Q": 2, "director": 3, "pressure": 1, "sigma_xx": 1, "sigma_yy": 1, "sigma_xy": 1}}, comps
            lx, ly = z["lattice"]
            phi, origin = z["phi"].astype(np.float64), z["origin"]
            n, nx, ny = phi.shape
            total = np.zeros((lx, ly))
            for i in range(n):
                xs = (origin[i, 0] + np.arange(nx)) % lx
                ys = (origin[i, 1] + np.arange(ny)) % ly
                total[np.ix_(xs, ys)] += phi[i]
            # VTK's point order is x fastest: reshape to (y, x).
            got = vtk_to_numpy(pd.GetArray("phi_sum")).reshape(ly, lx).T
            assert np.allclose(got, total, rtol=1e-6, atol=1e-6), np.abs(got - total).max()
            # The node the picture's cell 0 owns most holds phi_0 > 1/2 there.
            ids = vtk_to_numpy(pd.GetArray("cell_id")).reshape(ly, lx).T
            assert ids.min() == -1 and ids.max() == n - 1
            s = vtk_to_numpy(pd.GetArray("sigma_xx")).reshape(ly, lx).T
            p = vtk_to_numpy(pd.GetArray("pressure")).reshape(ly, lx).T
            q = vtk_to_numpy(pd.GetArray("Q")).reshape(ly, lx, 2).transpose(1, 0, 2)
            zeta = float(z["zeta"])
            # sigma_xx = -P - zeta Q_xx, to float32 rounding.
            assert np.allclose(s, -p - zeta * q[:, :, 0], atol=1e-6 * max(1.0, np.abs(s).max()))
        else:
            r = vtkXMLPolyDataReader(); r.SetFileName(path); r.Update()
            poly = r.GetOutput()
            pts = vtk_to_numpy(poly.GetPoints().GetData())
            assert pts.shape == (len(z["centre"]), 3)
            assert np.array_equal(pts[:, :2], z["centre"])
            v = vtk_to_numpy(poly.GetPointData().GetArray("velocity"))
            assert np.array_equal(v[:, :2], z["velocity"])
            assert poly.GetNumberOfVerts() == len(z["centre"])
print("ok")
"#,
        run = run.display(),
        out = out.display()
    );
    run_python(&script);
}

/// The cells' ParaView file holds every per-cell array the frame has for the scene's parts,
/// from the one table the render arrows and Python's cell table read (issue 48): with
/// `[polarity]` and two populations, `polarity.theta`, the vector `polarity` `(p_x, p_y, 0)`
/// and `population` (int32), each equal to the frame's own array row by row, as VTK's own
/// reader reads them.
#[test]
fn the_cells_file_holds_every_part_array_of_the_frame() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        &scene,
        "[domain]\nlx = 60\nly = 60\n[cells]\ncount = 8\nradius = 6.0\n\
         [[population]]\nname = \"a\"\ncount = 5\n[[population]]\nname = \"b\"\ncount = 3\n\
         [polarity]\nalpha = 0.04\nrotational_diffusion = 1e-3\n\
         [run]\nrelax_time = 2.0\ntime = 4.0\noutput_every = 2.0\n",
    )
    .unwrap();
    let run = dir.path().join("run");
    let o = bin()
        .arg("run")
        .arg(&scene)
        .arg("--out")
        .arg(&run)
        .arg("--quiet")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let o = bin()
        .args(["export", "vtk"])
        .arg(&run)
        .arg("-q")
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    if !python_has("vtkmodules.vtkIOXML, numpy", "vtk") {
        return;
    }
    let script = format!(
        r#"
import glob, os
import numpy as np
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
from vtkmodules.util.numpy_support import vtk_to_numpy
run = "{run}"
frames = sorted(glob.glob(os.path.join(run, "frames", "frame_*.npz")))
assert len(frames) >= 2
for f in frames:
    z = np.load(f)
    step = os.path.basename(f)[len("frame_"):-len(".npz")]
    r = vtkXMLPolyDataReader(); r.SetFileName(os.path.join(run, "vtk", f"cells_{{step}}.vtp")); r.Update()
    pd = r.GetOutput().GetPointData()
    names = [pd.GetArrayName(i) for i in range(pd.GetNumberOfArrays())]
    for name in ("polarity.theta", "polarity", "population"):
        assert name in names, (name, names)
    theta = vtk_to_numpy(pd.GetArray("polarity.theta"))
    assert np.array_equal(theta, z["polarity.theta"]), (theta, z["polarity.theta"])
    p = vtk_to_numpy(pd.GetArray("polarity"))
    assert p.shape == (8, 3) and np.array_equal(p[:, :2], z["polarity"]) and not p[:, 2].any()
    pop = vtk_to_numpy(pd.GetArray("population"))
    assert pop.dtype == np.int32 and np.array_equal(pop, z["population"]), (pop, z["population"])
    assert sorted(set(pop.tolist())) == [0, 1]
print("ok")
"#,
        run = run.display()
    );
    run_python(&script);
}
