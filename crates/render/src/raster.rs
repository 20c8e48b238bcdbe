//! An RGB picture in memory and the few drawing primitives the tissue pictures need: thick
//! lines and discs, clipped to a rectangle, and PNG output.

use std::io::{BufWriter, Write};
use std::path::Path;

use crate::RenderError;

/// An 8-bit RGB picture, rows top to bottom, `3 × width × height` bytes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Picture {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The pixels, `[r, g, b]` per pixel, row after row from the top.
    pub rgb: Vec<u8>,
}

impl Picture {
    /// A picture filled with one colour.
    pub fn filled(width: u32, height: u32, c: [u8; 3]) -> Self {
        let n = width as usize * height as usize;
        let mut rgb = Vec::with_capacity(3 * n);
        for _ in 0..n {
            rgb.extend_from_slice(&c);
        }
        Self { width, height, rgb }
    }

    /// The colour at column `x`, row `y` (from the top).
    ///
    /// # Panics
    /// Outside the picture.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside"
        );
        let k = 3 * (y as usize * self.width as usize + x as usize);
        [self.rgb[k], self.rgb[k + 1], self.rgb[k + 2]]
    }

    /// The picture encoded as a PNG (8-bit RGB, fast compression), in memory.
    ///
    /// # Errors
    /// The encoder's message.
    pub fn png_bytes(&self) -> Result<Vec<u8>, String> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, self.width, self.height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        let mut w = enc.write_header().map_err(|e| e.to_string())?;
        w.write_image_data(&self.rgb).map_err(|e| e.to_string())?;
        w.finish().map_err(|e| e.to_string())?;
        Ok(out)
    }

    /// Writes the picture as a PNG ([`Picture::png_bytes`]), through a temporary name.
    ///
    /// # Errors
    /// [`RenderError::Draw`] when the file cannot be written.
    pub fn save_png(&self, path: &Path) -> Result<(), RenderError> {
        let draw = |why: String| RenderError::Draw {
            path: path.to_path_buf(),
            why,
        };
        let tmp = path.with_extension("png.partial");
        let write = || -> Result<(), String> {
            let bytes = self.png_bytes()?;
            let mut f = BufWriter::new(std::fs::File::create(&tmp).map_err(|e| e.to_string())?);
            f.write_all(&bytes).map_err(|e| e.to_string())?;
            f.flush().map_err(|e| e.to_string())
        };
        write().map_err(&draw)?;
        std::fs::rename(&tmp, path).map_err(|e| draw(e.to_string()))
    }
}

/// A rectangle of a picture that drawing is clipped to: `[x0, x1) × [y0, y1)` in pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Clip {
    pub x0: i64,
    pub y0: i64,
    pub x1: i64,
    pub y1: i64,
}

/// Draws into a [`Picture`] within a [`Clip`].
pub(crate) struct Canvas<'a> {
    pub pic: &'a mut Picture,
    pub clip: Clip,
}

impl Canvas<'_> {
    #[inline]
    pub fn put(&mut self, x: i64, y: i64, c: [u8; 3]) {
        let k = &self.clip;
        if x >= k.x0 && x < k.x1 && y >= k.y0 && y < k.y1 {
            let i = 3 * (y as usize * self.pic.width as usize + x as usize);
            self.pic.rgb[i..i + 3].copy_from_slice(&c);
        }
    }

    /// A filled disc of radius `r` pixels centred at `(x, y)` (continuous pixel coordinates:
    /// pixel `(i, j)` covers `[i, i+1) × [j, j+1)`).
    pub fn disc(&mut self, x: f64, y: f64, r: f64, c: [u8; 3]) {
        let r = r.max(0.5);
        let (i0, i1) = ((x - r).floor() as i64, (x + r).ceil() as i64);
        let (j0, j1) = ((y - r).floor() as i64, (y + r).ceil() as i64);
        for j in j0..=j1 {
            for i in i0..=i1 {
                let (dx, dy) = (i as f64 + 0.5 - x, j as f64 + 0.5 - y);
                if dx * dx + dy * dy <= r * r {
                    self.put(i, j, c);
                }
            }
        }
    }

    /// A line of `width` pixels from `a` to `b`, with round ends.
    pub fn line(&mut self, a: (f64, f64), b: (f64, f64), width: f64, c: [u8; 3]) {
        let len = (b.0 - a.0).hypot(b.1 - a.1);
        let n = (2.0 * len).ceil().max(1.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            self.disc(a.0 + t * (b.0 - a.0), a.1 + t * (b.1 - a.1), 0.5 * width, c);
        }
    }

    /// True when a box of half-size `reach` around `(x, y)` meets the clip rectangle.
    pub fn near(&self, x: f64, y: f64, reach: f64) -> bool {
        let k = &self.clip;
        x + reach >= k.x0 as f64
            && x - reach <= k.x1 as f64
            && y + reach >= k.y0 as f64
            && y - reach <= k.y1 as f64
    }
}

/// Viridis, the perceptually uniform sequential map, for `t` in [0, 1] (nine control points
/// of matplotlib's table, linearly interpolated).
pub(crate) fn viridis(t: f64) -> [u8; 3] {
    const C: [[f64; 3]; 9] = [
        [68.0, 1.0, 84.0],
        [71.0, 44.0, 122.0],
        [59.0, 81.0, 139.0],
        [44.0, 113.0, 142.0],
        [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0],
        [92.0, 200.0, 99.0],
        [170.0, 220.0, 50.0],
        [253.0, 231.0, 37.0],
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let s = t * 8.0;
    let k = (s.floor() as usize).min(7);
    let f = s - k as f64;
    let mix = |i: usize| (C[k][i] + (C[k + 1][i] - C[k][i]) * f).round() as u8;
    [mix(0), mix(1), mix(2)]
}

/// Blue (−1) through white (0) to red (+1).
pub(crate) fn diverging(t: f64) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let (r0, g0, b0) = (247.0, 247.0, 247.0);
    let (r1, g1, b1) = if t >= 0.0 {
        (178.0, 24.0, 43.0)
    } else {
        (33.0, 102.0, 172.0)
    };
    let a = t.abs();
    let mix = |p: f64, q: f64| (p + (q - p) * a).round() as u8;
    [mix(r0, r1), mix(g0, g1), mix(b0, b1)]
}

/// A light colour for cell `id`, neighbours in id order far apart in hue (golden-ratio
/// steps), for telling cells apart.
pub(crate) fn id_colour(id: usize) -> [u8; 3] {
    let h = (id as f64 * 0.618_033_988_75).fract() * 6.0;
    let (s, v) = (0.45, 0.95);
    let c = v * s;
    let x = c * (1.0 - (h % 2.0 - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    let q = |u: f64| ((u + m) * 255.0).round() as u8;
    [q(r), q(g), q(b)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colour_maps_hit_their_end_points() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(f64::NAN), viridis(0.0));
        assert_eq!(diverging(0.0), [247, 247, 247]);
        assert_eq!(diverging(-3.0), [33, 102, 172]);
        assert_ne!(id_colour(0), id_colour(1));
    }

    #[test]
    fn a_disc_covers_pi_r_squared_pixels_and_is_clipped() {
        let mut pic = Picture::filled(100, 100, [0, 0, 0]);
        let clip = Clip {
            x0: 0,
            y0: 0,
            x1: 100,
            y1: 100,
        };
        let mut c = Canvas {
            pic: &mut pic,
            clip,
        };
        c.disc(50.0, 50.0, 20.0, [255, 255, 255]);
        // A disc centred on the corner: only its quarter inside is drawn, without a panic.
        c.disc(100.0, 100.0, 10.0, [255, 255, 255]);
        let lit = pic.rgb.chunks(3).filter(|p| p[0] == 255).count() as f64;
        let want = std::f64::consts::PI * 400.0 + std::f64::consts::PI * 100.0 / 4.0;
        assert!((lit - want).abs() < 0.05 * want, "{lit} vs {want}");
    }
}
