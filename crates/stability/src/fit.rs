//! Weighted least-squares polynomial fits with their covariance, solved by faer.

use faer::linalg::solvers::DenseSolveCore;
use faer::Mat;

/// A fitted polynomial `y = Σ_k coef[k] x^k`.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The coefficients, constant first.
    pub coef: Vec<f64>,
    /// Their standard errors: from the given errors when there are some, else from the
    /// residuals (scaled by `χ²/(n − p)`).
    pub se: Vec<f64>,
    /// `χ²` of the residuals (weighted when errors are given).
    pub chi2: f64,
    /// Degrees of freedom `n − p`.
    pub dof: usize,
}

/// The least-squares polynomial of `degree` through `(x, y)`, weighted by `1/err²` when
/// errors are given. `None` with fewer points than coefficients or a singular system.
pub fn poly(x: &[f64], y: &[f64], err: Option<&[f64]>, degree: usize) -> Option<Fit> {
    let (n, p) = (x.len(), degree + 1);
    if n < p || y.len() != n {
        return None;
    }
    let w: Vec<f64> = match err {
        Some(e) => e.iter().map(|s| 1.0 / (s * s).max(1e-300)).collect(),
        None => vec![1.0; n],
    };
    let a = Mat::<f64>::from_fn(p, p, |r, c| {
        (0..n).map(|i| w[i] * x[i].powi((r + c) as i32)).sum()
    });
    let b = Mat::<f64>::from_fn(p, 1, |r, _| {
        (0..n).map(|i| w[i] * x[i].powi(r as i32) * y[i]).sum()
    });
    let lu = a.partial_piv_lu();
    let inv = lu.inverse();
    if (0..p).any(|k| !inv[(k, k)].is_finite()) {
        return None;
    }
    let sol = &inv * &b;
    let coef: Vec<f64> = (0..p).map(|k| sol[(k, 0)]).collect();
    let chi2: f64 = (0..n)
        .map(|i| {
            let f: f64 = coef
                .iter()
                .enumerate()
                .map(|(k, c)| c * x[i].powi(k as i32))
                .sum();
            w[i] * (y[i] - f) * (y[i] - f)
        })
        .sum();
    let dof = n - p;
    let scale = if err.is_some() || dof == 0 {
        1.0
    } else {
        chi2 / dof as f64
    };
    let se = (0..p).map(|k| (inv[(k, k)] * scale).sqrt()).collect();
    Some(Fit {
        coef,
        se,
        chi2,
        dof,
    })
}

/// [`poly`] of degree 1.
pub fn line(x: &[f64], y: &[f64], err: Option<&[f64]>) -> Option<Fit> {
    poly(x, y, err, 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A line and a parabola are recovered exactly; the errors of a weighted fit are the
    /// textbook ones for two points.
    #[test]
    fn fits_recover_polynomials() {
        let x = [0.006, 0.008, 0.01, 0.012, 0.014];
        let y: Vec<f64> = x.iter().map(|v| 0.001 + 0.2 * v).collect();
        let f = line(&x, &y, None).unwrap();
        assert!((f.coef[0] - 0.001).abs() < 1e-12 && (f.coef[1] - 0.2).abs() < 1e-9);
        let y: Vec<f64> = x.iter().map(|v| 0.001 + 0.2 * v + 30.0 * v * v).collect();
        let f = poly(&x, &y, Some(&[1e-5; 5]), 2).unwrap();
        assert!((f.coef[2] - 30.0).abs() < 1e-6, "{:?}", f.coef);
        // Two points of error s: the slope's error is s·√2/Δx.
        let f = line(&[0.0, 1.0], &[1.0, 3.0], Some(&[0.1, 0.1])).unwrap();
        assert!((f.se[1] - 0.1 * 2f64.sqrt()).abs() < 1e-12);
        assert!(line(&[1.0], &[1.0], None).is_none());
    }
}
