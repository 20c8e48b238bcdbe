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
//!
//! A wall may also hold the cells back (`[walls] friction`, ξ_w, default 0): a cell in contact
//! with it feels a friction in proportion to its overlap with the wall,
//!
//! ```text
//! (ξ + ξ_w o_i) v_i = F_i,        o_i = Σ_x φ_i w        (overlap, in nodes)
//! ```
//!
//! ([`wall_overlap`], evaluated with the cell's force at every evaluation): a cell far from the
//! wall moves as before, one pressed on it slides along it more slowly. This is the friction at
//! the walls that sets the flow profile of a confined active tissue (shear against plug flow).

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
    /// Friction `ξ_w` per node of overlap with the wall (0: none).
    pub friction: f64,
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
            friction: 0.0,
            active: Some(field.clone()),
            relaxation: field,
        }
    }

    /// These walls with friction `ξ_w` per node of overlap ([`wall_overlap`]).
    pub fn with_friction(mut self, friction: f64) -> Self {
        self.friction = friction;
        self
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
            friction,
            relaxation: _,
            active: _,
        } = self;
        let mut out = vec![("[walls] kappa".to_string(), kappa.to_string())];
        if *omega != 0.0 {
            out.push(("[walls] omega".into(), omega.to_string()));
        }
        if *friction != 0.0 {
            out.push(("[walls] friction".into(), friction.to_string()));
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
            && self.friction == other.friction
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

/// The overlap `o_i = Σ_x φ_i(x) w(x)` of a cell with the wall field `w`, over its patch:
/// `cell` its field in patch storage (`shape`), `xs` and `ys` the lattice column and row of
/// each storage column and row ([`phasefield::PatchMap::cell_x`]). In nodes: about the length
/// of its contact line times the wall's decay length for a cell pressed on a wall, 0 far from
/// it.
pub fn wall_overlap<T: phasefield::Real>(
    field: &WallField,
    cell: &[T],
    shape: &phasefield::PatchShape,
    xs: &[u32],
    ys: &[u32],
) -> f64 {
    let (w, ly) = (field.w(), field.lattice().ly);
    let mut sum = 0.0;
    for (column, &x) in cell.chunks_exact(shape.ny).zip(xs) {
        let wc = &w[x as usize * ly..(x as usize + 1) * ly];
        for (c, &y) in column.iter().zip(ys) {
            sum += c.to_f64() * wc[y as usize];
        }
    }
    sum
}

#[cfg(test)]
mod tests;
