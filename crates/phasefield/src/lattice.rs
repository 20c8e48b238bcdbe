//! The periodic square lattice on which every field lives.
//!
//! Node `(x, y)` with `0 <= x < lx`, `0 <= y < ly` has linear index `x * ly + y`:
//! x is the first (slow) index, y the second (contiguous) one, and the frame is right-handed.
//! Lattice spacing is 1.

/// A periodic `lx × ly` lattice with spacing 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lattice {
    /// Number of nodes along x.
    pub lx: usize,
    /// Number of nodes along y.
    pub ly: usize,
}

impl Lattice {
    /// A lattice of `lx × ly` nodes.
    ///
    /// # Panics
    /// If either side is zero.
    pub fn new(lx: usize, ly: usize) -> Self {
        assert!(lx > 0 && ly > 0, "lattice sides must be positive");
        Self { lx, ly }
    }

    /// Number of nodes, `lx * ly`.
    pub fn len(&self) -> usize {
        self.lx * self.ly
    }

    /// Always false: a lattice has at least one node.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Linear index of node `(x, y)` (both already in range).
    #[inline]
    pub fn index(&self, x: usize, y: usize) -> usize {
        x * self.ly + y
    }

    /// Wraps any integer coordinate into `[0, lx)`.
    #[inline]
    pub fn wrap_x(&self, x: i64) -> usize {
        x.rem_euclid(self.lx as i64) as usize
    }

    /// Wraps any integer coordinate into `[0, ly)`.
    #[inline]
    pub fn wrap_y(&self, y: i64) -> usize {
        y.rem_euclid(self.ly as i64) as usize
    }

    /// Minimum-image displacement `b - a` along x, in `[-lx/2, lx/2)`.
    #[inline]
    pub fn delta_x(&self, a: f64, b: f64) -> f64 {
        min_image(b - a, self.lx as f64)
    }

    /// Minimum-image displacement `b - a` along y, in `[-ly/2, ly/2)`.
    #[inline]
    pub fn delta_y(&self, a: f64, b: f64) -> f64 {
        min_image(b - a, self.ly as f64)
    }

    /// Minimum-image distance between two points.
    pub fn distance(&self, a: [f64; 2], b: [f64; 2]) -> f64 {
        self.delta_x(a[0], b[0]).hypot(self.delta_y(a[1], b[1]))
    }

    /// Wraps a real position into `[0, lx) × [0, ly)`.
    pub fn wrap_point(&self, p: [f64; 2]) -> [f64; 2] {
        [
            wrap_real(p[0], self.lx as f64),
            wrap_real(p[1], self.ly as f64),
        ]
    }
}

/// Minimum image of a displacement `d` on a period `l`, in `[-l/2, l/2)`.
#[inline]
pub fn min_image(d: f64, l: f64) -> f64 {
    d - l * (d / l + 0.5).floor()
}

/// Wraps a real coordinate into `[0, l)`.
#[inline]
pub fn wrap_real(x: f64, l: f64) -> f64 {
    let w = x.rem_euclid(l);
    // rem_euclid can round up to exactly l for tiny negative inputs.
    if w >= l {
        0.0
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_image_is_in_half_open_range() {
        for &d in &[-151.0, -50.0, -49.9, 0.0, 49.9, 50.0, 123.4] {
            let m = min_image(d, 100.0);
            assert!((-50.0..50.0).contains(&m), "{d} -> {m}");
            assert!(((d - m) / 100.0 - ((d - m) / 100.0).round()).abs() < 1e-12);
        }
    }
}
