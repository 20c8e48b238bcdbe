//! `[walls]` into wall fields: the geometry's solid nodes, or a mask read from a PNG image or
//! a `.npy` array, checked key by key.

use std::path::Path;

use phasefield::{Lattice, WallField, WallShape};

use crate::file::{WallKind, WallsSpec};
use crate::validate::{invalid, SceneError};

/// The wall fields of `[walls]`: during the relaxation, and after it (none once a wound has
/// opened). `reach` is how far from the solid the distances must be exact (the initial
/// placement's clearance).
///
/// # Errors
/// [`SceneError::Invalid`] naming the key, for a bad value, a key of another kind, or a mask
/// file that cannot be read or does not fit the lattice.
pub(crate) fn wall_fields(
    spec: &WallsSpec,
    lattice: Lattice,
    reach: f64,
) -> Result<(WallField, Option<WallField>), SceneError> {
    let (lx, ly) = (lattice.lx as f64, lattice.ly as f64);
    if !(spec.thickness.is_finite() && spec.thickness > 0.0 && spec.thickness <= 10.0) {
        return Err(invalid(
            "walls",
            "thickness",
            spec.thickness,
            "the wall thickness must be positive and at most 10 nodes",
            "use 0.5–1 (the reference code's examples)",
        ));
    }
    for (key, v) in [("kappa", spec.kappa), ("omega", spec.omega)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(invalid(
                "walls",
                key,
                v,
                "must be zero or positive",
                if key == "kappa" {
                    "use 1 (the reference code's examples)"
                } else {
                    "use 0 (no wall adhesion) or a small value such as 0.002"
                },
            ));
        }
    }
    let kind_name = |k: WallKind| match k {
        WallKind::Channel => "channel",
        WallKind::Box => "box",
        WallKind::Disc => "disc",
        WallKind::Wound => "wound",
        WallKind::Mask => "mask",
    };
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
    let shape = match spec.kind {
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
                    format!("{:?}", semi_axes),
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
    };
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
    let field = WallField::new(lattice, &solid, spec.thickness, reach);
    let after = match spec.kind {
        WallKind::Wound => None,
        _ => Some(field.clone()),
    };
    Ok((field, after))
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
