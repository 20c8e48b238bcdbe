//! The storage precision of the phase fields.
//!
//! Fields are stored as `f64` (the default) or `f32`; every arithmetic operation is done in
//! `f64`. A value is widened when it is loaded into a [`crate::Stencil`] and rounded once when
//! it is stored. `f32` storage halves the memory the step moves; its cost in accuracy is
//! measured in `docs/performance.md` (work–precision study).

/// A floating-point type the phase fields can be stored in: `f64` or `f32`.
pub trait Real:
    Copy + Default + Send + Sync + PartialEq + PartialOrd + std::fmt::Debug + 'static
{
    /// The type's name as written in scene files and archives (`"f64"`, `"f32"`).
    const NAME: &'static str;
    /// Widens to `f64` (exact).
    fn to_f64(self) -> f64;
    /// Rounds an `f64` to this type (to nearest).
    fn from_f64(v: f64) -> Self;
}

impl Real for f64 {
    const NAME: &'static str = "f64";
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v
    }
}

impl Real for f32 {
    const NAME: &'static str = "f32";
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self as f64
    }
    #[inline(always)]
    fn from_f64(v: f64) -> Self {
        v as f32
    }
}
