//! Walls: a static wall field `w` ([`phasefield::WallField`]) that repels the cells and,
//! optionally, adheres to them (docs/model.md §11.4):
//!
//! ```text
//! F_wall = Σ_i Σ_x [ (κ_w/λ) φ_i² w² + 2ω_wλ ∇φ_i·∇w ],
//! δF_wall/δφ_i = (2κ_w/λ) φ_i w² − 2ω_wλ ∇²w           (equations::wall_derivative)
//! ```
//!
//! Both are interaction terms: they enter the pressure as `Σ_i φ_i δF_wall/δφ_i`
//! ([`crate::equations::wall_pressure`]) and through it the force `F_i = Σ_x P ∇φ_i`, which is
//! how a wall pushes a cell. A wall can be removed when the activity switches on (a wound that
//! opens after the relaxation).

use std::sync::Arc;

use phasefield::WallField;

/// Walls of a tissue: the field, its repulsion `κ_w` and adhesion `ω_w`, and what happens
/// to it when the activity switches on.
#[derive(Debug, Clone)]
pub struct Walls {
    /// Repulsion `κ_w`.
    pub kappa: f64,
    /// Adhesion `ω_w`.
    pub omega: f64,
    relaxation: Arc<WallField>,
    active: Option<Arc<WallField>>,
}

impl Walls {
    /// Walls of field `field` with repulsion `kappa` and adhesion `omega`, the same before
    /// and after the activity switches on.
    pub fn new(field: WallField, kappa: f64, omega: f64) -> Self {
        let field = Arc::new(field);
        Self {
            kappa,
            omega,
            active: Some(field.clone()),
            relaxation: field,
        }
    }

    /// These walls during the relaxation only, replaced by `after` (none: removed) when the
    /// activity switches on ([`crate::Tissue::set_active`]): a wound that opens.
    pub fn replaced_when_active(mut self, after: Option<WallField>) -> Self {
        self.active = after.map(Arc::new);
        self
    }

    /// The field in effect: during the relaxation (`active` false) or after it.
    pub fn field(&self, active: bool) -> Option<&WallField> {
        if active {
            self.active.as_deref()
        } else {
            Some(&self.relaxation)
        }
    }

    /// Whether the walls change when the activity switches on.
    pub fn open_when_active(&self) -> bool {
        match &self.active {
            None => true,
            Some(a) => !Arc::ptr_eq(a, &self.relaxation),
        }
    }

    /// Every setting of `[walls]` in effect, as `(scene key, value)` (the destructuring has
    /// no `..`: a field added here does not compile until it is listed): the coefficients,
    /// and whether the field changes when the activity starts (a wound that opens).
    pub fn settings(&self) -> Vec<(String, String)> {
        let Walls {
            kappa,
            omega,
            relaxation: _,
            active: _,
        } = self;
        let mut out = vec![("[walls] kappa".to_string(), kappa.to_string())];
        if *omega != 0.0 {
            out.push(("[walls] omega".into(), omega.to_string()));
        }
        if self.open_when_active() {
            out.push((
                "[walls] kind".into(),
                "walls that change when the activity starts (a wound)".into(),
            ));
        }
        out
    }

    /// Whether `other` is the same walls: the same coefficients and the same fields before
    /// and after the activity switch (compared by value, so a wall rebuilt from the scene
    /// equals the one it was built from before).
    pub fn same_as(&self, other: &Walls) -> bool {
        self.kappa == other.kappa
            && self.omega == other.omega
            && *self.relaxation == *other.relaxation
            && self.active.as_deref() == other.active.as_deref()
    }

    /// Bytes of heap memory held.
    pub fn heap_bytes(&self) -> usize {
        self.relaxation.heap_bytes()
            + self
                .active
                .as_ref()
                .filter(|a| !Arc::ptr_eq(a, &self.relaxation))
                .map_or(0, |a| a.heap_bytes())
    }
}

#[cfg(test)]
mod tests;
