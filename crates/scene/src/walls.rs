//! `[walls]` into wall fields: the geometry's solid nodes, or a mask read from a PNG image or
//! a `.npy` array, checked key by key.

use std::path::Path;

use mechanics::walls::Walls;
use phasefield::{Lattice, WallField, WallShape};

use crate::error::{invalid, SceneError};
use crate::file::{WallKind, WallsSpec};

/// The walls of `[walls]`: their field during the relaxation and after it (none once a wound
/// has opened), with κ_w and ω_w. `reach` is how far from the solid the distances must be
/// exact (the initial placement's clearance).
///
/// # Errors
/// [`SceneError::Invalid`] naming the key, for a bad value, a key of another kind, or a mask
/// file that cannot be read or does not fit the lattice.
pub(crate) fn walls_of(
    spec: &WallsSpec,
    lattice: Lattice,
    reach: f64,
) -> Result<Walls, SceneError> {
    check_keys(spec)?;
    let shape = shape_of(spec, lattice)?;
    let solid = shape.solid(lattice);
    let n_solid = solid.iter().filter(|&&s| s).count();
    if n_solid == 0 || n_solid == solid.len() {
        return Err(invalid(
            "walls",
            if spec.kind == WallKind::Mask {
                "mask"
            } else {
                "kind"
            },
            format!("\"{}\"", kind_name(spec.kind)),
            if n_solid == 0 {
                "no node is solid"
            } else {
                "every node is solid"
            },
            if spec.kind == WallKind::Mask {
                "check the mask (bright or non-zero is solid; invert = true swaps them)"
            } else {
                "enlarge [domain] or change the wall's size"
            },
        ));
    }
    let walls = Walls::new(
        WallField::new(lattice, &solid, spec.thickness, reach),
        spec.kappa,
        spec.omega,
    )
    .with_friction(spec.friction);
    Ok(match spec.kind {
        WallKind::Wound => walls.replaced_when_active(None),
        _ => walls,
    })
}

/// The name of a kind of walls, as the scene writes it.
fn kind_name(k: WallKind) -> &'static str {
    match k {
        WallKind::Channel => "channel",
        WallKind::Box => "box",
        WallKind::Disc => "disc",
        WallKind::Wound => "wound",
        WallKind::Mask => "mask",
    }
}

/// The keys of `[walls]` that do not depend on the lattice: the thickness and coefficients,
/// and each key given only for the kinds it applies to.
fn check_keys(spec: &WallsSpec) -> Result<(), SceneError> {
    if !(spec.thickness.is_finite() && spec.thickness > 0.0 && spec.thickness <= 10.0) {
        return Err(invalid(
            "walls",
            "thickness",
            spec.thickness,
            "the wall thickness must be positive and at most 10 nodes",
            "use 0.5–1 (the reference code's examples)",
        ));
    }
    for (key, v) in [
        ("kappa", spec.kappa),
        ("omega", spec.omega),
        ("friction", spec.friction),
    ] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(
                "walls",
                key,
                v,
                "must be zero or positive",
                match key {
                    "kappa" => "use 1 (the reference code's examples)",
                    "omega" => "use 0 (no wall adhesion) or a small value such as 0.002",
                    _ => "use 0 (no wall friction) or a value of the order of ξ (2)",
                },
            ));
        }
    }
    let only = |key: &'static str, set: bool, kinds: &[WallKind]| {
        if set && !kinds.contains(&spec.kind) {
            let names: Vec<_> = kinds
                .iter()
                .map(|&k| format!("\"{}\"", kind_name(k)))
                .collect();
            Err(invalid(
                "walls",
                key,
                "…",
                format!(
                    "{key} applies to kind = {}, not to kind = \"{}\"",
                    names.join(" or "),
                    kind_name(spec.kind)
                ),
                format!("remove {key}, or change kind"),
            ))
        } else {
            Ok(())
        }
    };
    only(
        "width",
        spec.width.is_some(),
        &[WallKind::Channel, WallKind::Wound],
    )?;
    only("radius", spec.radius.is_some(), &[WallKind::Disc])?;
    only("semi_axes", spec.semi_axes.is_some(), &[WallKind::Disc])?;
    only("mask", spec.mask.is_some(), &[WallKind::Mask])?;
    only("invert", spec.invert, &[WallKind::Mask])?;
    if spec.radius.is_some() && spec.semi_axes.is_some() {
        return Err(invalid(
            "walls",
            "semi_axes",
            "…",
            "both radius and semi_axes are given",
            "give radius for a disc or semi_axes for an ellipse",
        ));
    }
    Ok(())
}

/// The shape of the walls of `spec` on `lattice`, its sizes checked against the domain.
fn shape_of(spec: &WallsSpec, lattice: Lattice) -> Result<WallShape, SceneError> {
    let (lx, ly) = (lattice.lx as f64, lattice.ly as f64);
    let width = |default: f64, most: f64, along: &str| -> Result<f64, SceneError> {
        let w = spec.width.unwrap_or(default);
        if !(w.is_finite() && w >= 1.0 && w <= most) {
            return Err(invalid(
                "walls",
                "width",
                w,
                format!("the width must lie between 1 node and {most} (the domain's {along} less two solid rows)"),
                format!("use a width up to {most}, or enlarge [domain]"),
            ));
        }
        Ok(w)
    };
    Ok(match spec.kind {
        WallKind::Channel => WallShape::Channel {
            width: width(ly - 2.0, ly - 2.0, "ly")?,
        },
        WallKind::Box => WallShape::Box {
            width: [lx - 2.0, ly - 2.0],
        },
        WallKind::Wound => WallShape::Band {
            width: width((lx / 4.0).round(), lx - 2.0, "lx")?,
        },
        WallKind::Disc => {
            let largest = [lx / 2.0 - 1.0, ly / 2.0 - 1.0];
            let semi_axes = match (spec.radius, spec.semi_axes) {
                (Some(r), _) => [r, r],
                (None, Some(ab)) => ab,
                (None, None) => [largest[0].min(largest[1]); 2],
            };
            let key = if spec.semi_axes.is_some() {
                "semi_axes"
            } else {
                "radius"
            };
            if (0..2).any(|k| {
                !(semi_axes[k].is_finite() && semi_axes[k] >= 2.0 && semi_axes[k] <= largest[k])
            }) {
                return Err(invalid(
                    "walls",
                    key,
                    spec.radius.map_or_else(|| format!("{semi_axes:?}"), |r| r.to_string()),
                    format!(
                        "the disc must lie inside the domain with a solid rim: at most {} along x and {} along y, and at least 2",
                        largest[0], largest[1]
                    ),
                    "use a smaller radius or enlarge [domain]",
                ));
            }
            WallShape::Ellipse { semi_axes }
        }
        WallKind::Mask => {
            let Some(path) = spec.mask.as_deref() else {
                return Err(invalid(
                    "walls",
                    "mask",
                    "(none)",
                    "kind = \"mask\" needs the mask file",
                    "set mask = \"pattern.png\" (bright pixels solid) or \"pattern.npy\" (non-zero solid)",
                ));
            };
            let mut solid = read_mask(Path::new(path), lattice)?;
            if spec.invert {
                solid.iter_mut().for_each(|s| *s = !*s);
            }
            WallShape::Mask(solid)
        }
    })
}

/// The solid nodes of a mask file: a PNG image (bright solid) or a `.npy` array (non-zero
/// solid), on `lattice`.
fn read_mask(path: &Path, lattice: Lattice) -> Result<Vec<bool>, SceneError> {
    let shown = path.display().to_string();
    let bad = |problem: String, fix: &str| invalid("walls", "mask", &shown, problem, fix);
    let bytes = std::fs::read(path).map_err(|e| {
        bad(
            format!("cannot read the mask file: {e}"),
            "give the path of a PNG or .npy file (relative to the scene file's directory)",
        )
    })?;
    let (lx, ly) = (lattice.lx, lattice.ly);
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "png" => {
            let mut decoder = png::Decoder::new(&bytes[..]);
            decoder
                .set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
            let mut reader = decoder.read_info().map_err(|e| {
                bad(
                    format!("not a readable PNG image: {e}"),
                    "save the mask as an 8-bit PNG",
                )
            })?;
            let mut buf = vec![0; reader.output_buffer_size()];
            let info = reader.next_frame(&mut buf).map_err(|e| {
                bad(
                    format!("not a readable PNG image: {e}"),
                    "save the mask as an 8-bit PNG",
                )
            })?;
            let (w, h) = (info.width as usize, info.height as usize);
            if (w, h) != (lx, ly) {
                return Err(bad(
                    format!("the image is {w}×{h} pixels, the lattice {lx}×{ly} nodes (a pixel is a node)"),
                    &format!("scale the image to {lx}×{ly} pixels, or set [domain] lx = {w}, ly = {h}"),
                ));
            }
            let channels = info.color_type.samples();
            let luminance = |p: &[u8]| -> f64 {
                let v = |c: u8| c as f64 / 255.0;
                match channels {
                    1 | 2 => v(p[0]),
                    _ => 0.2126 * v(p[0]) + 0.7152 * v(p[1]) + 0.0722 * v(p[2]),
                }
            };
            let mut solid = vec![false; lx * ly];
            for row in 0..h {
                let line = &buf[row * info.line_size..];
                for col in 0..w {
                    let y = ly - 1 - row;
                    solid[col * ly + y] = luminance(&line[col * channels..]) >= 0.5;
                }
            }
            Ok(solid)
        }
        "npy" => {
            let fix = "save a 2-D array of shape (lx, ly), indexed [x, y], of numbers or booleans";
            let npy = npyz::NpyFile::new(&bytes[..])
                .map_err(|e| bad(format!("not a readable .npy array: {e}"), fix))?;
            let shape = npy.shape().to_vec();
            if shape != [lx as u64, ly as u64] {
                return Err(bad(
                    format!("the array's shape is {shape:?}, the lattice's ({lx}, {ly})"),
                    &format!("save an array of shape ({lx}, {ly}) indexed [x, y] (transpose an image's [row, column] array), or change [domain]"),
                ));
            }
            let fortran = npy.order() == npyz::Order::Fortran;
            let values: Vec<f64> = match npy.dtype() {
                npyz::DType::Plain(t) if t.type_char() == npyz::TypeChar::Bool => npy
                    .into_vec::<bool>()
                    .map(|v| v.into_iter().map(|b| f64::from(u8::from(b))).collect()),
                npyz::DType::Plain(t)
                    if t.type_char() == npyz::TypeChar::Uint && t.size_field() == 1 =>
                {
                    npy.into_vec::<u8>()
                        .map(|v| v.into_iter().map(f64::from).collect())
                }
                npyz::DType::Plain(t) if t.type_char() == npyz::TypeChar::Int => npy
                    .into_vec::<i64>()
                    .map(|v| v.into_iter().map(|x| x as f64).collect()),
                npyz::DType::Plain(t)
                    if t.type_char() == npyz::TypeChar::Float && t.size_field() == 4 =>
                {
                    npy.into_vec::<f32>()
                        .map(|v| v.into_iter().map(f64::from).collect())
                }
                _ => npy.into_vec::<f64>(),
            }
            .map_err(|e| bad(format!("cannot read the array's values: {e}"), fix))?;
            if values.iter().any(|v| !v.is_finite()) {
                return Err(bad("the array holds a NaN or an infinity".into(), fix));
            }
            Ok((0..lx * ly)
                .map(|k| {
                    let (x, y) = (k / ly, k % ly);
                    values[if fortran { y * lx + x } else { k }] != 0.0
                })
                .collect())
        }
        _ => Err(bad(
            "the mask must be a .png or a .npy file".into(),
            "convert it to PNG (bright pixels solid) or to a .npy array (non-zero solid)",
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Scene;
    use npyz::WriterBuilder;

    const BASE: &str = "[domain]\nlx = 40\nly = 30\n[cells]\ncount = 2\nradius = 6.0\n[integrator]\nmargin = 12\n[run]\ntime = 1\n";

    fn parse(set: &[&str]) -> Result<Scene, SceneError> {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        Scene::parse(BASE, &set)
    }

    fn npy<T: npyz::Serialize + npyz::AutoSerialize + Copy>(shape: &[u64], data: &[T]) -> Vec<u8> {
        let mut buf = Vec::new();
        let mut w = npyz::WriteOptions::new()
            .default_dtype()
            .shape(shape)
            .writer(&mut buf)
            .begin_nd()
            .unwrap();
        w.extend(data.iter().copied()).unwrap();
        w.finish().unwrap();
        buf
    }

    /// A PNG of `w × h` pixels with `channels` samples each, bright where `bright(col, row)`.
    fn png(w: u32, h: u32, color: png::ColorType, bright: impl Fn(u32, u32) -> bool) -> Vec<u8> {
        let channels = color.samples();
        let mut data = Vec::new();
        for row in 0..h {
            for col in 0..w {
                let v = if bright(col, row) { 230 } else { 20 };
                data.extend(std::iter::repeat_n(v, channels));
            }
        }
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(color);
        enc.set_depth(png::BitDepth::Eight);
        enc.write_header().unwrap().write_image_data(&data).unwrap();
        out
    }

    /// A PNG's top row is the lattice's top (y = ly − 1), its left column x = 0, in grey and in
    /// colour; `invert` swaps solid and free; a `.npy` array is indexed `[x, y]`.
    #[test]
    fn masks_are_read_with_the_lattice_orientation() {
        let dir = tempfile::tempdir().unwrap();
        let l = Lattice::new(40, 30);
        // Bright: the top 3 rows and the left 2 columns.
        let bright = |col: u32, row: u32| row < 3 || col < 2;
        for color in [
            png::ColorType::Grayscale,
            png::ColorType::Rgb,
            png::ColorType::Rgba,
        ] {
            let path = dir.path().join("m.png");
            std::fs::write(&path, png(40, 30, color, bright)).unwrap();
            let solid = read_mask(&path, l).unwrap();
            for x in 0..40 {
                for y in 0..30 {
                    let expected = y >= 27 || x < 2;
                    assert_eq!(solid[l.index(x, y)], expected, "({x}, {y}) {color:?}");
                }
            }
            let m = format!("walls.mask={:?}", path.display().to_string());
            let s = parse(&["walls.kind=\"mask\"", &m]).unwrap();
            let (f, after) = s.wall_fields().unwrap();
            assert!(f.is_solid(l.index(20, 29)) && !f.is_solid(l.index(20, 10)));
            assert!(after.is_some(), "a mask stays after the relaxation");
            let set = [
                "walls.kind=\"mask\"".to_string(),
                m,
                "walls.invert=true".into(),
            ];
            let file = crate::SceneFile::parse(BASE, &set).unwrap();
            let w = walls_of(file.walls.as_ref().unwrap(), l, 0.0).unwrap();
            let f = w.field(false).unwrap();
            assert!(!f.is_solid(l.index(20, 29)) && f.is_solid(l.index(20, 10)));
        }
        let path = dir.path().join("m.npy");
        let values: Vec<f64> = (0..40 * 30)
            .map(|k| if k / 30 == 5 { 1.0 } else { 0.0 })
            .collect();
        std::fs::write(&path, npy(&[40, 30], &values)).unwrap();
        let solid = read_mask(&path, l).unwrap();
        assert!((0..30).all(|y| solid[l.index(5, y)]));
        assert_eq!(solid.iter().filter(|&&s| s).count(), 30);
        let bools: Vec<bool> = values.iter().map(|&v| v != 0.0).collect();
        std::fs::write(&path, npy(&[40, 30], &bools)).unwrap();
        assert_eq!(read_mask(&path, l).unwrap(), solid);
    }

    /// Bad `[walls]` values and bad mask files end in an error naming the key and a fix.
    #[test]
    fn bad_walls_name_their_key() {
        let dir = tempfile::tempdir().unwrap();
        let small = dir.path().join("small.png");
        std::fs::write(&small, png(10, 10, png::ColorType::Grayscale, |c, _| c < 3)).unwrap();
        let shape = dir.path().join("shape.npy");
        std::fs::write(&shape, npy(&[30, 40], &vec![0u8; 1200])).unwrap();
        let text = dir.path().join("text.png");
        std::fs::write(&text, "not an image").unwrap();
        let mask = |p: &std::path::Path| format!("walls.mask={:?}", p.display().to_string());
        let (small, shape, text) = (mask(&small), mask(&shape), mask(&text));
        let missing = mask(&dir.path().join("none.png"));
        let cases: &[(&[&str], &[&str])] = &[
            (
                &["walls.kind=\"channel\"", "walls.width=40"],
                &["[walls] width", "up to 28"],
            ),
            (
                &["walls.kind=\"channel\"", "walls.thickness=0"],
                &["[walls] thickness"],
            ),
            (
                &["walls.kind=\"box\"", "walls.kappa=-1"],
                &["[walls] kappa"],
            ),
            (
                &["walls.kind=\"disc\"", "walls.width=10"],
                &["[walls] width", "kind = \"channel\" or \"wound\""],
            ),
            (
                &["walls.kind=\"disc\"", "walls.radius=20"],
                &["[walls] radius = 20:", "14 along y"],
            ),
            (
                &["walls.kind=\"mask\""],
                &["[walls] mask", "needs the mask file"],
            ),
            (
                &["walls.kind=\"mask\"", &small],
                &["[walls] mask", "10×10 pixels", "lx = 10, ly = 10"],
            ),
            (
                &["walls.kind=\"mask\"", &shape],
                &["[walls] mask", "shape is [30, 40]"],
            ),
            (
                &["walls.kind=\"mask\"", &text],
                &["[walls] mask", "not a readable PNG"],
            ),
            (
                &["walls.kind=\"mask\"", &missing],
                &["[walls] mask", "cannot read"],
            ),
            (
                &["walls.kind=\"channel\"", "walls.invert=true"],
                &["[walls] invert"],
            ),
            (
                &["walls.kind=\"disc\"", "walls.radius=4"],
                &["[cells] count", "clear of the walls"],
            ),
        ];
        for (set, needles) in cases {
            crate::check_rejected(BASE, set, needles);
        }
        // A stiff wall needs a smaller step: the estimate λ/κ_w.
        let e = parse(&[
            "walls.kind=\"channel\"",
            "walls.kappa=20",
            "model.zeta=0.005",
            "integrator.dt=0.5",
        ])
        .unwrap_err()
        .to_string();
        assert!(e.contains("dt"), "{e}");
    }

    /// Initial discs stay clear of the walls in every layout.
    #[test]
    fn initial_discs_avoid_the_walls() {
        for init in ["\"random\"", "\"hexagonal\""] {
            let s = Scene::parse(
                "[domain]\nlx = 80\nly = 60\n[cells]\ncount = 12\nradius = 8.0\n[walls]\nkind = \"disc\"\n[run]\ntime = 1\n",
                &[format!("cells.init={init}")],
            )
            .unwrap();
            let (f, _) = s.wall_fields().unwrap();
            for c in &s.centres {
                assert!(
                    f.distance_at(*c) >= phasefield::init::wall_clearance(4.0),
                    "{init}: {c:?}"
                );
            }
        }
    }
}
