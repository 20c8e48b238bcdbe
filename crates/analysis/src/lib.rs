//! # analysis
//!
//! The quantities of Mueller, Yeomans & Doostmohammadi (PRL 2019), figures 2–4, from lattice
//! fields: a Q field, a velocity field, a stress field. The crate takes plain lattice-sized
//! slices (index `x * ly + y`, see [`phasefield::Lattice`]), so it serves simulated fields
//! and fields measured in experiments (PIV velocities, Q from segmented images) alike; it
//! never sees a simulation type.
//!
//! - [`smooth`]: periodic sliding-box mean in O(L²) for any box;
//! - [`fields`]: vorticity, rms values, `S_rms`;
//! - [`correlation`]: normalised autocorrelations by FFT, radial averages, first minima;
//! - [`defects`]: ±½ defects by winding, orientation by Vromans & Giomi;
//! - [`tracking`]: links between frames, creation and annihilation in pairs;
//! - [`crop`]: fields averaged in the frame of each defect;
//! - [`proximity`]: how near events come to defects, against random points in the tissue;
//! - [`motion`]: mean squared displacements of tracked cells, and the shape index of a cell.
//!
//! Axis convention: x first index, y second, right-handed; angles counterclockwise from +x.
//!
//! ```
//! use analysis::defects::detect;
//! use phasefield::Lattice;
//!
//! // A +1/2 defect at the centre of a 16 × 16 lattice: director angle θ = φ/2.
//! let lattice = Lattice::new(16, 16);
//! let (mut qxx, mut qxy) = (vec![0.0; 256], vec![0.0; 256]);
//! for x in 0..16 {
//!     for y in 0..16 {
//!         let phi = (y as f64 - 8.5).atan2(x as f64 - 8.5);
//!         qxx[x * 16 + y] = phi.cos();
//!         qxy[x * 16 + y] = phi.sin();
//!     }
//! }
//! let defects = detect(lattice, &qxx, &qxy);
//! let plus: Vec<_> = defects.iter().filter(|d| d.x == 8.5 && d.y == 8.5).collect();
//! assert_eq!(plus.len(), 1);
//! assert_eq!(plus[0].charge, 0.5);
//! assert!(plus[0].angle.abs() < 1e-12);
//! ```
#![deny(missing_docs)]

pub mod confinement;
pub mod correlation;
pub mod crop;
pub mod defects;
pub mod fields;
pub mod mixing;
pub mod motion;
pub mod proximity;
pub mod smooth;
pub mod tracking;

/// Errors of the analysis routines.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// A smoothing box that is even or larger than the lattice.
    #[error("smoothing box side {side} must be odd and at most the lattice side ({lx}×{ly}); use e.g. 3R rounded to an odd number")]
    BadBox {
        /// The side asked for.
        side: usize,
        /// Lattice side along x.
        lx: usize,
        /// Lattice side along y.
        ly: usize,
    },
}
