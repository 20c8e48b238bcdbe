//! Geometric types at the API boundary (nalgebra): vectors are [`nalgebra::Vector2`], and the
//! deformation tensor `S_i` and the nematic field `Q` are [`TracelessTensor`]s.

use nalgebra::{Matrix2, SymmetricEigen, Vector2};

/// A symmetric traceless 2×2 tensor `[[xx, xy], [xy, −xx]]`: the deformation tensor `S_i`
/// of a cell or the nematic field `Q` at a node (docs/model.md §3).
///
/// Its eigenvalues are `±|T|` with `|T| = sqrt(xx² + xy²)`; the eigenvector of `+|T|` is the
/// *axis* (a cell's long axis, the local director), defined up to sign, at angle
/// `½ atan2(xy, xx)` from +x.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TracelessTensor {
    /// The `xx` component (`yy = −xx`).
    pub xx: f64,
    /// The `xy` component.
    pub xy: f64,
}

impl TracelessTensor {
    /// The tensor with components `xx` and `xy`.
    pub const fn new(xx: f64, xy: f64) -> Self {
        Self { xx, xy }
    }

    /// `[xx, xy]`, the form the kernels and the frame files use.
    #[inline(always)]
    pub const fn components(self) -> [f64; 2] {
        [self.xx, self.xy]
    }

    /// The full 2×2 matrix.
    pub fn matrix(self) -> Matrix2<f64> {
        Matrix2::new(self.xx, self.xy, self.xy, -self.xx)
    }

    /// The magnitude `|T| = sqrt(xx² + xy²)`, the positive eigenvalue.
    pub fn magnitude(self) -> f64 {
        self.xx.hypot(self.xy)
    }

    /// The eigen-decomposition of [`TracelessTensor::matrix`]: the positive eigenvalue and its
    /// unit eigenvector (the axis, sign chosen with a non-negative x component, or +y when
    /// it is vertical). For the zero tensor the axis is +x.
    pub fn axis(self) -> (f64, Vector2<f64>) {
        if self.xx == 0.0 && self.xy == 0.0 {
            return (0.0, Vector2::x());
        }
        let eig = SymmetricEigen::new(self.matrix());
        let k = if eig.eigenvalues[0] >= eig.eigenvalues[1] {
            0
        } else {
            1
        };
        let mut v: Vector2<f64> = eig.eigenvectors.column(k).into_owned();
        if v.x < 0.0 || (v.x == 0.0 && v.y < 0.0) {
            v = -v;
        }
        (eig.eigenvalues[k], v)
    }

    /// The angle of the axis from +x, in `(−π/2, π/2]`: `½ atan2(xy, xx)`.
    pub fn angle(self) -> f64 {
        0.5 * self.xy.atan2(self.xx)
    }
}

impl From<[f64; 2]> for TracelessTensor {
    fn from([xx, xy]: [f64; 2]) -> Self {
        Self { xx, xy }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The eigen-decomposition agrees with the closed form: eigenvalue `|T|`, axis at
    /// `½ atan2(xy, xx)`, to round-off, and `T a = |T| a`.
    #[test]
    fn the_axis_is_the_closed_form_eigenvector() {
        for &(xx, xy) in &[
            (1.0, 0.0),
            (-1.0, 0.0),
            (0.3, 0.4),
            (-0.2, -0.9),
            (0.0, 2.0),
        ] {
            let t = TracelessTensor::new(xx, xy);
            let (lambda, a) = t.axis();
            assert!((lambda - t.magnitude()).abs() < 1e-14 * t.magnitude().max(1.0));
            let r = t.matrix() * a - lambda * a;
            assert!(r.norm() < 1e-14, "{r:?}");
            let theta = t.angle();
            let closed = Vector2::new(theta.cos(), theta.sin());
            assert!(
                (a.dot(&closed).abs() - 1.0).abs() < 1e-14,
                "{a:?} {closed:?}"
            );
        }
    }
}
