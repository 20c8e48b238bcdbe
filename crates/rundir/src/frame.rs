//! The frames of a run, `frames/frame_STEP.npz`, and reading `.npz` archives back.
//!
//! Frames are NumPy `.npz` archives (zip of `.npy` arrays, deflate-compressed), readable with
//! `numpy.load` and no custom code. Arrays in a frame:
//!
//! | name | shape | meaning |
//! |---|---|---|
//! | `format` | `()` int64 | [`FRAME_FORMAT`], the version of this layout |
//! | `step`, `time`, `zeta` | `()` | clock and activity |
//! | `lattice` | `(2,)` int64 | `[lx, ly]` |
//! | `id` | `(N,)` int64 | each row's cell identity, increasing (`0..N` unless cells divided or were removed; then the ids of `lineage.csv`) |
//! | `centre` | `(N, 2)` | centre of mass `[x, y]` |
//! | `velocity` | `(N, 2)` | `v_i` |
//! | `force` | `(N, 2)` | `F_i` |
//! | `area` | `(N,)` | `Σ φ_i²` |
//! | `shape_tensor` | `(N, 2)` | `[S_xx, S_xy]` (`S_yy = −S_xx`) |
//! | `origin` | `(N, 2)` int64 | lattice node of each patch's element `[0, 0]` |
//! | `phi` | `(N, nx, ny)`, float32 or float64: the run's storage precision (`[integrator] precision`) | `phi[i, u, v]` is `φ_i` at node `((origin_x+u) % lx, (origin_y+v) % ly)` |
//!
//! Arrays without a type in the table are float64. Rows are in increasing identity (`phi[i]`
//! is the cell `id[i]`: cell `i` of the scene while the number of cells has not changed),
//! whatever their order in memory. `format` 2 is the same layout without `id` (cell `i` is
//! row `i`), and `format` 1 (before issue 12) has `phi` always float64; [`read_npz`] reads
//! them all.

use std::fs::File;
use std::io::{BufReader, Read, Write};
use std::path::{Path, PathBuf};

use mechanics::{Tissue, Workspace};

use crate::{Result, RunDirError};
use npyz::WriterBuilder;
use phasefield::Real;

/// Version of the frame layout; `monolayer analyze` refuses frames of another version.
/// Format 3 adds `id`, the identity of each row; format 2 stores `phi` in the run's
/// precision; format 1 stored it as float64.
pub const FRAME_FORMAT: i64 = 3;

/// The frame formats this version reads.
pub const FRAME_FORMATS_READ: std::ops::RangeInclusive<i64> = 1..=FRAME_FORMAT;

/// One `.npy` array in memory.
pub fn npy<T: npyz::Serialize + npyz::AutoSerialize + Copy>(
    shape: &[u64],
    data: impl IntoIterator<Item = T>,
) -> std::io::Result<Vec<u8>> {
    let mut buf = Vec::new();
    {
        let mut w = npyz::WriteOptions::new()
            .default_dtype()
            .shape(shape)
            .writer(&mut buf)
            .begin_nd()?;
        w.extend(data)?;
        w.finish()?;
    }
    Ok(buf)
}

/// Writes one frame (see the module docs); `ws` must hold the derived quantities of the
/// current state (call [`Tissue::observe`] or [`Tissue::refresh`] first).
pub fn write_frame<T: Real>(dir: &Path, tissue: &Tissue<T>, ws: &Workspace<T>) -> Result<PathBuf> {
    write_frame_with(dir, tissue, ws, None)
}

/// [`write_frame`], with each cell's force by origin (`parts`, by slot, from
/// [`Tissue::forces_by_origin`] of the same state) as arrays `force.ORIGIN` `(N, 2)`.
///
/// # Errors
/// As [`write_frame`].
pub fn write_frame_with<T: Real>(
    dir: &Path,
    tissue: &Tissue<T>,
    ws: &Workspace<T>,
    parts: Option<&mechanics::ForcesByOrigin>,
) -> Result<PathBuf> {
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).map_err(|e| RunDirError::io("create", &frames, e))?;
    let path = frames.join(format!("frame_{:08}.npz", tissue.iteration()));
    let n = tissue.n_cells();
    let shape = tissue.cells().shape();
    let (nx, ny) = (shape.nx, shape.ny);
    let cs = ws.cell_states();
    let lattice = tissue.lattice();
    // Cells are written in increasing identity, whatever their storage order.
    let slots = tissue.slots();
    let ids: Vec<usize> = slots.iter().map(|&s| tissue.cell_ids()[s]).collect();
    let cs: Vec<_> = slots.iter().map(|&s| cs[s]).collect();
    let centre: Vec<[f64; 2]> = slots.iter().map(|&s| ws.centres()[s]).collect();
    let origin = &tissue.cells().map().origin;
    let mut phi = vec![0.0; n * nx * ny];
    for (chunk, &slot) in phi.chunks_exact_mut(nx * ny).zip(&slots) {
        tissue.cells().unrolled_into(slot, chunk);
    }
    let n64 = n as u64;
    let arrays = || -> std::io::Result<Vec<(&str, Vec<u8>)>> {
        Ok(vec![
            ("format", npy(&[], [FRAME_FORMAT])?),
            ("step", npy(&[], [tissue.iteration() as i64])?),
            ("time", npy(&[], [tissue.time()])?),
            ("zeta", npy(&[], [tissue.params().zeta])?),
            (
                "lattice",
                npy(&[2], [lattice.lx as i64, lattice.ly as i64])?,
            ),
            ("id", npy(&[n64], ids.iter().map(|&i| i as i64))?),
            ("centre", npy(&[n64, 2], centre.iter().flatten().copied())?),
            (
                "velocity",
                npy(
                    &[n64, 2],
                    cs.iter().flat_map(|c| [c.velocity.x, c.velocity.y]),
                )?,
            ),
            (
                "force",
                npy(&[n64, 2], cs.iter().flat_map(|c| [c.force.x, c.force.y]))?,
            ),
            ("area", npy(&[n64], cs.iter().map(|c| c.area))?),
            (
                "shape_tensor",
                npy(&[n64, 2], cs.iter().flat_map(|c| c.shape.components()))?,
            ),
            (
                "origin",
                npy(
                    &[n64, 2],
                    slots
                        .iter()
                        .flat_map(|&s| [origin[s][0] as i64, origin[s][1] as i64]),
                )?,
            ),
            (
                "phi",
                if T::NAME == "f32" {
                    // Exact: the values were f32 before they were widened.
                    npy(&[n64, nx as u64, ny as u64], phi.iter().map(|&v| v as f32))?
                } else {
                    npy(&[n64, nx as u64, ny as u64], phi.iter().copied())?
                },
            ),
        ])
    };
    let mut arrays: Vec<(String, Vec<u8>)> = arrays()
        .map_err(|e| RunDirError::io("encode", &path, e))?
        .into_iter()
        .map(|(name, a)| (name.to_string(), a))
        .collect();
    let mut extra = Vec::new();
    if !tissue.terms().is_empty() {
        extra.push((
            "cell_force".to_string(),
            npy(
                &[n64, 2],
                cs.iter().flat_map(|c| [c.cell_force.x, c.cell_force.y]),
            ),
        ));
    }
    // The extensions' per-cell arrays are by identity: one row per living cell.
    for array in tissue.extensions().frame_arrays() {
        let w = array.columns;
        let rows = ids.iter().flat_map(|&i| &array.values[i * w..(i + 1) * w]);
        let shape = if w == 1 {
            vec![n64]
        } else {
            vec![n64, w as u64]
        };
        let a = if array.integer {
            npy(&shape, rows.map(|&v| v as i64))
        } else {
            npy(&shape, rows.copied())
        };
        extra.push((array.name, a));
    }
    if let Some(p) = parts {
        for (name, forces) in p.names.iter().zip(&p.parts) {
            extra.push((
                format!("force.{name}"),
                npy(&[n64, 2], slots.iter().flat_map(|&s| forces[s])),
            ));
        }
    }
    for (name, a) in extra {
        let a = a.map_err(|e| RunDirError::io("encode", &path, e))?;
        arrays.push((name, a));
    }
    write_npz(&path, arrays)?;
    Ok(path)
}

/// The step of a frame file named `frame_STEP.npz`.
pub(crate) fn frame_step(name: &str) -> Option<u64> {
    name.strip_prefix("frame_")?
        .strip_suffix(".npz")?
        .parse()
        .ok()
}

/// The step of the last whole frame in `dir/frames/` (by name; a `.partial` file is not a
/// frame), if any.
pub fn last_frame(dir: &Path) -> Option<u64> {
    std::fs::read_dir(dir.join("frames"))
        .ok()?
        .filter_map(|e| frame_step(e.ok()?.file_name().to_str()?))
        .max()
}

/// Writes named `.npy` arrays (from [`npy`]) as a deflated `.npz` archive, through a
/// temporary name so that a reader never sees a half-written file.
///
/// # Errors
/// I/O errors (a full disk among them), naming the file; the temporary file is removed.
pub fn write_npz<S: AsRef<str>>(path: &Path, arrays: Vec<(S, Vec<u8>)>) -> Result<()> {
    write_zip(path, arrays, zip::CompressionMethod::Deflated, false)
}

/// Writes an `.npz` archive of `arrays` under `PATH.partial`, with `method` (deflate at
/// level 1, or stored), flushed to disk first when `sync`, then renames it to `path` (and
/// syncs the directory). On an error the partial file is removed.
///
/// The archive is built in memory (each array is freed once it is in), then written in one
/// go: a write error (a full disk) then reaches the caller alone, where a zip writer on the
/// file would meet it again in its `Drop` and print it, or trip an assertion.
pub(crate) fn write_zip<S: AsRef<str>>(
    path: &Path,
    arrays: Vec<(S, Vec<u8>)>,
    method: zip::CompressionMethod,
    sync: bool,
) -> Result<()> {
    let tmp = path.with_extension("npz.partial");
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let level = (method == zip::CompressionMethod::Deflated).then_some(1);
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(method)
        .compression_level(level)
        .large_file(true);
    let encode = || -> std::io::Result<()> {
        for (name, bytes) in arrays {
            zip.start_file(format!("{}.npy", name.as_ref()), opts)
                .map_err(std::io::Error::other)?;
            zip.write_all(&bytes)?;
        }
        Ok(())
    };
    encode().map_err(|e| RunDirError::io("encode", path, e))?;
    let bytes = zip
        .finish()
        .map_err(|e| RunDirError::io("encode", path, std::io::Error::other(e)))?
        .into_inner();
    let write = || -> std::io::Result<()> {
        let mut f = File::create(&tmp)?;
        f.write_all(&bytes)?;
        if sync {
            f.sync_all()?;
        }
        Ok(())
    };
    if let Err(e) = write() {
        let _ = std::fs::remove_file(&tmp);
        return Err(RunDirError::io("write", &tmp, e));
    }
    std::fs::rename(&tmp, path).map_err(|e| RunDirError::io("rename", &tmp, e))?;
    if sync {
        if let Some(d) = path.parent().and_then(|p| File::open(p).ok()) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

/// An array read from an `.npz` archive: its shape and its values as `f64`.
#[derive(Debug, Clone, PartialEq)]
pub struct Array {
    /// The shape.
    pub shape: Vec<u64>,
    /// The values in C order.
    pub data: Vec<f64>,
}

impl Array {
    /// The value of an array that holds exactly one, as a scalar (`()`) array does.
    pub fn scalar(&self) -> Option<f64> {
        match self.data[..] {
            [v] => Some(v),
            _ => None,
        }
    }
}

/// Reads the arrays `names` (and only those) from an `.npz` archive. Integer and float32
/// arrays are converted to `f64` (exactly).
///
/// # Errors
/// When the file is not a readable archive or lacks one of the arrays.
pub fn read_npz(path: &Path, names: &[&str]) -> Result<Vec<Array>> {
    let f = File::open(path).map_err(|e| RunDirError::io("open", path, e))?;
    let mut zip = zip::ZipArchive::new(BufReader::new(f)).map_err(|e| RunDirError::Archive {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    let mut out = Vec::with_capacity(names.len());
    for name in names {
        let bad = |reason: String| RunDirError::BadArray {
            path: path.to_path_buf(),
            name: name.to_string(),
            reason,
        };
        let mut entry =
            zip.by_name(&format!("{name}.npy"))
                .map_err(|_| RunDirError::MissingArray {
                    path: path.to_path_buf(),
                    name: name.to_string(),
                })?;
        let mut bytes = Vec::with_capacity(entry.size() as usize);
        entry
            .read_to_end(&mut bytes)
            .map_err(|e| bad(e.to_string()))?;
        let npy = npyz::NpyFile::new(&bytes[..]).map_err(|e| bad(e.to_string()))?;
        let shape = npy.shape().to_vec();
        let data = match npy.dtype() {
            npyz::DType::Plain(t) if t.type_char() == npyz::TypeChar::Int => npy
                .into_vec::<i64>()
                .map_err(|e| bad(e.to_string()))?
                .into_iter()
                .map(|v| v as f64)
                .collect(),
            npyz::DType::Plain(t)
                if t.type_char() == npyz::TypeChar::Float && t.size_field() == 4 =>
            {
                npy.into_vec::<f32>()
                    .map_err(|e| bad(e.to_string()))?
                    .into_iter()
                    .map(f64::from)
                    .collect()
            }
            _ => npy.into_vec::<f64>().map_err(|e| bad(e.to_string()))?,
        };
        out.push(Array { shape, data });
    }
    Ok(out)
}

/// The names of the arrays of the NumPy archive `path`, in archive order.
///
/// # Errors
/// A file that cannot be opened or is not a zip archive, naming it.
pub fn npz_names(path: &Path) -> Result<Vec<String>> {
    let f = File::open(path).map_err(|e| RunDirError::io("open", path, e))?;
    let zip = zip::ZipArchive::new(BufReader::new(f)).map_err(|e| RunDirError::Archive {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    Ok(zip
        .file_names()
        .filter_map(|n| n.strip_suffix(".npy"))
        .map(str::to_string)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame stores φ in the run's precision, and reads back exactly: an f32 run writes a
    /// float32 `phi` (half the bytes) whose values widen to the tissue's own; an f64 run
    /// writes float64.
    #[test]
    fn phi_is_stored_in_the_runs_precision_and_reads_back_exactly() {
        let text =
            "[domain]\nlx = 48\nly = 48\n[cells]\ncount = 3\nradius = 6.0\n[run]\ntime = 1\n";
        let scene = scene::Scene::parse(text, &[]).unwrap();
        let dir = tempfile::tempdir().unwrap();
        fn check<T: Real>(scene: &scene::Scene, dir: &Path, dtype: &str) {
            let tissue = scene.tissue::<T>().expect("a scene of discs builds");
            let mut ws = Workspace::new(tissue.cells());
            tissue.observe(&mut ws);
            let path = write_frame(dir, &tissue, &ws).unwrap();
            let a = read_npz(&path, &["format", "phi"]).unwrap();
            assert_eq!(a[0].data, [FRAME_FORMAT as f64]);
            let shape = tissue.cells().shape();
            let mut want = vec![0.0; shape.nx * shape.ny];
            tissue.cells().unrolled_into(0, &mut want);
            assert_eq!(&a[1].data[..want.len()], &want[..]);
            // The .npy header names the dtype.
            let f = File::open(&path).unwrap();
            let mut zip = zip::ZipArchive::new(BufReader::new(f)).unwrap();
            let mut bytes = Vec::new();
            zip.by_name("phi.npy")
                .unwrap()
                .read_to_end(&mut bytes)
                .unwrap();
            let header = String::from_utf8_lossy(&bytes[..128.min(bytes.len())]).to_string();
            assert!(header.contains(dtype), "{header}");
        }
        check::<f32>(&scene, &dir.path().join("a"), "'<f4'");
        check::<f64>(&scene, &dir.path().join("b"), "'<f8'");
    }
}
