//! ParaView files: VTK XML ImageData (`.vti`) for lattice fields, PolyData (`.vtp`) for
//! points with data, and a `.pvd` collection that makes a time series of them.
//!
//! The `.vti` and `.vtp` files carry their arrays as raw little-endian binary in an appended
//! block (`<AppendedData encoding="raw">`, `header_type="UInt64"`: each array is preceded by
//! its byte count as a `u64`), the compact form ParaView and VTK's readers load fastest.
//!
//! Lattice arrays are given in this project's order, node `(x, y)` at `x * ly + y`, and
//! written in VTK's, x fastest; [`read_vti`] turns them back. The image has `lx × ly × 1`
//! points at spacing 1 from the origin, so point `(x, y)` of ParaView is lattice node
//! `(x, y)`.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use crate::{Result, RunDirError};

/// The values of one array.
#[derive(Debug, Clone, PartialEq)]
pub enum VtkValues {
    /// `Float32`.
    F32(Vec<f32>),
    /// `Float64`.
    F64(Vec<f64>),
    /// `Int32`.
    I32(Vec<i32>),
}

impl VtkValues {
    fn len(&self) -> usize {
        match self {
            Self::F32(v) => v.len(),
            Self::F64(v) => v.len(),
            Self::I32(v) => v.len(),
        }
    }

    fn type_name(&self) -> &'static str {
        match self {
            Self::F32(_) => "Float32",
            Self::F64(_) => "Float64",
            Self::I32(_) => "Int32",
        }
    }

    /// Appends the bytes of the values `order` picks (all, in order, when `None`).
    fn bytes_into(&self, order: Option<&[usize]>, comps: usize, out: &mut Vec<u8>) {
        macro_rules! put {
            ($v:expr) => {
                match order {
                    None => $v
                        .iter()
                        .for_each(|x| out.extend_from_slice(&x.to_le_bytes())),
                    Some(o) => o.iter().for_each(|&k| {
                        $v[k * comps..(k + 1) * comps]
                            .iter()
                            .for_each(|x| out.extend_from_slice(&x.to_le_bytes()))
                    }),
                }
            };
        }
        match self {
            Self::F32(v) => put!(v),
            Self::F64(v) => put!(v),
            Self::I32(v) => put!(v),
        }
    }
}

/// A named array of `components` values per point.
#[derive(Debug, Clone, PartialEq)]
pub struct VtkArray {
    /// The name ParaView shows.
    pub name: String,
    /// Values per point (1 scalar, 3 vector, ...).
    pub components: usize,
    /// The values, point after point.
    pub values: VtkValues,
}

impl VtkArray {
    /// An array named `name` with `components` values per point.
    pub fn new(name: impl Into<String>, components: usize, values: VtkValues) -> Self {
        Self {
            name: name.into(),
            components,
            values,
        }
    }
}

fn check(path: &Path, arrays: &[VtkArray], points: usize) -> Result<()> {
    for a in arrays {
        if a.components == 0 || a.values.len() != a.components * points {
            return Err(RunDirError::BadArray {
                path: path.to_path_buf(),
                name: a.name.clone(),
                reason: format!(
                    "{} values for {points} points of {} components",
                    a.values.len(),
                    a.components
                ),
            });
        }
    }
    Ok(())
}

/// The `<DataArray>` headers and the appended block of `arrays`.
fn data_arrays(
    arrays: &[VtkArray],
    order: Option<&[usize]>,
    indent: &str,
    xml: &mut String,
    blob: &mut Vec<u8>,
) {
    for a in arrays {
        let _ = writeln!(
            xml,
            r#"{indent}<DataArray type="{}" Name="{}" NumberOfComponents="{}" format="appended" offset="{}"/>"#,
            a.values.type_name(),
            a.name,
            a.components,
            blob.len()
        );
        let start = blob.len();
        blob.extend_from_slice(&0u64.to_le_bytes());
        a.values.bytes_into(order, a.components, blob);
        let n = (blob.len() - start - 8) as u64;
        blob[start..start + 8].copy_from_slice(&n.to_le_bytes());
    }
}

fn finish(path: &Path, mut xml: String, blob: &[u8]) -> Result<()> {
    xml.push_str("  <AppendedData encoding=\"raw\">\n   _");
    let mut bytes = xml.into_bytes();
    bytes.extend_from_slice(blob);
    bytes.extend_from_slice(b"\n  </AppendedData>\n</VTKFile>\n");
    write_atomic(path, &bytes)
}

fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension(format!(
        "{}.partial",
        path.extension().and_then(|e| e.to_str()).unwrap_or("")
    ));
    let write = || -> std::io::Result<()> {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.flush()
    };
    write().map_err(|e| RunDirError::io("write", &tmp, e))?;
    std::fs::rename(&tmp, path).map_err(|e| RunDirError::io("rename", &tmp, e))
}

const HEADER: &str = r#"<?xml version="1.0"?>"#;

/// Writes an ImageData file of an `lx × ly` lattice with point arrays in lattice order
/// (`x * ly + y`), and the time as field data `TimeValue`.
///
/// # Errors
/// An array of the wrong length ([`RunDirError::BadArray`]); I/O errors.
pub fn write_vti(path: &Path, lx: usize, ly: usize, time: f64, arrays: &[VtkArray]) -> Result<()> {
    check(path, arrays, lx * ly)?;
    // VTK order: point (x, y) at y * lx + x; the lattice index of each.
    let order: Vec<usize> = (0..ly)
        .flat_map(|y| (0..lx).map(move |x| x * ly + y))
        .collect();
    let extent = format!("0 {} 0 {} 0 0", lx - 1, ly - 1);
    let mut xml = String::new();
    let _ = writeln!(
        xml,
        r#"{HEADER}
<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <ImageData WholeExtent="{extent}" Origin="0 0 0" Spacing="1 1 1">
    <FieldData>
      <DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="ascii">{time:e}</DataArray>
    </FieldData>
    <Piece Extent="{extent}">
      <PointData>"#
    );
    let mut blob = Vec::new();
    data_arrays(arrays, Some(&order), "        ", &mut xml, &mut blob);
    xml.push_str("      </PointData>\n      <CellData/>\n    </Piece>\n  </ImageData>\n");
    finish(path, xml, &blob)
}

/// Writes a PolyData file of `points` (one vertex each) with point arrays.
///
/// # Errors
/// An array of the wrong length; I/O errors.
pub fn write_vtp(path: &Path, points: &[[f64; 3]], time: f64, arrays: &[VtkArray]) -> Result<()> {
    let n = points.len();
    check(path, arrays, n)?;
    let mut xml = String::new();
    let _ = writeln!(
        xml,
        r#"{HEADER}
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <PolyData>
    <FieldData>
      <DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" format="ascii">{time:e}</DataArray>
    </FieldData>
    <Piece NumberOfPoints="{n}" NumberOfVerts="{n}" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="0">
      <PointData>"#
    );
    let mut blob = Vec::new();
    data_arrays(arrays, None, "        ", &mut xml, &mut blob);
    xml.push_str("      </PointData>\n      <Points>\n");
    let pts = VtkArray::new(
        "Points",
        3,
        VtkValues::F64(points.iter().flatten().copied().collect()),
    );
    data_arrays(&[pts], None, "        ", &mut xml, &mut blob);
    xml.push_str("      </Points>\n      <Verts>\n");
    let conn = VtkArray::new("connectivity", 1, VtkValues::I32((0..n as i32).collect()));
    let offs = VtkArray::new("offsets", 1, VtkValues::I32((1..=n as i32).collect()));
    data_arrays(&[conn, offs], None, "        ", &mut xml, &mut blob);
    xml.push_str("      </Verts>\n    </Piece>\n  </PolyData>\n");
    finish(path, xml, &blob)
}

/// Writes a `.pvd` collection: `(time, file)` pairs, each file relative to the `.pvd`.
///
/// # Errors
/// I/O errors.
pub fn write_pvd(path: &Path, entries: &[(f64, String)]) -> Result<()> {
    let mut xml = format!(
        "{HEADER}\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <Collection>\n"
    );
    for (t, file) in entries {
        let _ = writeln!(
            xml,
            r#"    <DataSet timestep="{t:e}" group="" part="0" file="{file}"/>"#
        );
    }
    xml.push_str("  </Collection>\n</VTKFile>\n");
    write_atomic(path, xml.as_bytes())
}

/// What [`read_vti`] finds: the lattice, the time and each array (name, components, values
/// as `f64` in lattice order).
#[derive(Debug, Clone, PartialEq)]
pub struct VtiFile {
    /// Points along x.
    pub lx: usize,
    /// Points along y.
    pub ly: usize,
    /// The `TimeValue` field.
    pub time: f64,
    /// `(name, components, values)`, values in lattice order `x * ly + y`.
    pub arrays: Vec<(String, usize, Vec<f64>)>,
}

fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let len = tag[start..].find('"')?;
    Some(&tag[start..start + len])
}

/// Reads back a `.vti` that [`write_vti`] wrote (raw appended data, UInt64 headers).
///
/// # Errors
/// A file that is not such a `.vti`, naming what is missing.
pub fn read_vti(path: &Path) -> Result<VtiFile> {
    let bytes = std::fs::read(path).map_err(|e| RunDirError::io("open", path, e))?;
    let bad = |reason: &str| RunDirError::Archive {
        path: path.to_path_buf(),
        reason: reason.to_string(),
    };
    let marker = b"<AppendedData encoding=\"raw\">";
    let at = bytes
        .windows(marker.len())
        .position(|w| w == marker)
        .ok_or_else(|| bad("no raw appended data"))?;
    let head = std::str::from_utf8(&bytes[..at]).map_err(|_| bad("the XML is not UTF-8"))?;
    let blob_start = at
        + marker.len()
        + bytes[at + marker.len()..]
            .iter()
            .position(|&b| b == b'_')
            .ok_or_else(|| bad("no '_' before the appended data"))?
        + 1;
    let whole = head
        .find("<ImageData ")
        .and_then(|i| attr(&head[i..], "WholeExtent"))
        .ok_or_else(|| bad("no ImageData WholeExtent"))?;
    let e: Vec<usize> = whole
        .split_whitespace()
        .map(|v| v.parse().map_err(|_| bad("a bad extent")))
        .collect::<Result<_>>()?;
    if e.len() != 6 || e[0] != 0 || e[2] != 0 {
        return Err(bad("an extent that does not start at 0"));
    }
    let (lx, ly) = (e[1] + 1, e[3] + 1);
    let time = head
        .find("Name=\"TimeValue\"")
        .and_then(|i| {
            let rest = &head[i..];
            let open = rest.find('>')? + 1;
            let close = rest.find("</DataArray>")?;
            rest[open..close].trim().parse().ok()
        })
        .unwrap_or(f64::NAN);
    let mut arrays = Vec::new();
    for tag in head.split("<DataArray ").skip(1) {
        let tag = &format!(" {}", &tag[..tag.find('>').unwrap_or(tag.len())]);
        if attr(tag, "format") != Some("appended") {
            continue;
        }
        let name = attr(tag, "Name").ok_or_else(|| bad("an array without a name"))?;
        let comps: usize = attr(tag, "NumberOfComponents")
            .unwrap_or("1")
            .parse()
            .map_err(|_| bad("bad NumberOfComponents"))?;
        let offset: usize = attr(tag, "offset")
            .and_then(|o| o.parse().ok())
            .ok_or_else(|| bad("an array without an offset"))?;
        let p = blob_start + offset;
        let len_bytes = bytes.get(p..p + 8).ok_or_else(|| bad("truncated"))?;
        let n = u64::from_le_bytes(len_bytes.try_into().expect("8 bytes")) as usize;
        let raw = bytes
            .get(p + 8..p + 8 + n)
            .ok_or_else(|| bad("truncated"))?;
        let vtk: Vec<f64> = match attr(tag, "type") {
            Some("Float32") => raw
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().expect("4")) as f64)
                .collect(),
            Some("Float64") => raw
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().expect("8")))
                .collect(),
            Some("Int32") => raw
                .chunks_exact(4)
                .map(|c| i32::from_le_bytes(c.try_into().expect("4")) as f64)
                .collect(),
            _ => return Err(bad("an array type other than Float32, Float64, Int32")),
        };
        if vtk.len() != comps * lx * ly {
            return Err(bad("an array of the wrong length"));
        }
        let mut values = vec![0.0; vtk.len()];
        for y in 0..ly {
            for x in 0..lx {
                let (v, l) = (y * lx + x, x * ly + y);
                values[l * comps..(l + 1) * comps]
                    .copy_from_slice(&vtk[v * comps..(v + 1) * comps]);
            }
        }
        arrays.push((name.to_string(), comps, values));
    }
    Ok(VtiFile {
        lx,
        ly,
        time,
        arrays,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A non-square lattice with a scalar and a vector array reads back exactly (f64, i32)
    /// or to f32 rounding, in lattice order, with its dimensions and time.
    #[test]
    fn a_vti_round_trips_through_its_reader() {
        let (lx, ly) = (5, 3);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.vti");
        let scalar: Vec<f64> = (0..lx * ly).map(|k| k as f64 * 0.1).collect();
        let vector: Vec<f32> = (0..3 * lx * ly).map(|k| k as f32 / 7.0).collect();
        let ids: Vec<i32> = (0..lx * ly).map(|k| k as i32 - 4).collect();
        write_vti(
            &path,
            lx,
            ly,
            12.5,
            &[
                VtkArray::new("s", 1, VtkValues::F64(scalar.clone())),
                VtkArray::new("v", 3, VtkValues::F32(vector.clone())),
                VtkArray::new("id", 1, VtkValues::I32(ids.clone())),
            ],
        )
        .unwrap();
        let back = read_vti(&path).unwrap();
        assert_eq!((back.lx, back.ly, back.time), (lx, ly, 12.5));
        assert_eq!(back.arrays[0], ("s".into(), 1, scalar));
        let v: Vec<f64> = vector.iter().map(|&x| x as f64).collect();
        assert_eq!(back.arrays[1], ("v".into(), 3, v));
        let i: Vec<f64> = ids.iter().map(|&x| x as f64).collect();
        assert_eq!(back.arrays[2], ("id".into(), 1, i));
        let e = write_vti(
            &path,
            lx,
            ly,
            0.0,
            &[VtkArray::new("short", 1, VtkValues::F64(vec![0.0; 3]))],
        )
        .unwrap_err();
        assert!(e.to_string().contains("'short'"), "{e}");
    }
}
