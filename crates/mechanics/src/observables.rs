//! Scalar observables of a state (docs/model.md §7) and the lattice fields they are built from.

use phasefield::Real;

use crate::tissue::Tissue;
use crate::workspace::Workspace;

/// Scalar summary of one state, computed on output steps only.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[non_exhaustive]
pub struct Observables {
    /// `sqrt(⟨|v|²⟩)` over the lattice of the tissue velocity `v = Σ_i φ_i v_i`.
    pub v_rms: f64,
    /// `sqrt(mean_i (S_xx² + S_xy²))` over cells.
    pub s_rms: f64,
    /// Mean cell area `⟨Σ_x φ_i²⟩`.
    pub area_mean: f64,
    /// Smallest cell area.
    pub area_min: f64,
    /// Largest cell area.
    pub area_max: f64,
    /// `sqrt(mean_i |v_i|²)` over cells.
    pub cell_speed_rms: f64,
    /// Smallest φ over all patches.
    pub phi_min: f64,
    /// Largest φ over all patches.
    pub phi_max: f64,
}

impl<T: Real> Tissue<T> {
    /// Refreshes the derived quantities into `ws` ([`Tissue::refresh`]) and computes the
    /// observables of the current state. Leaves the tissue velocity field `Σ φ_i v_i` in the
    /// workspace ([`Workspace::velocity_field`]). Takes `&self`: observing never changes the
    /// dynamics.
    pub fn observe(&self, ws: &mut Workspace<T>) -> Observables {
        self.refresh(ws);
        self.scatter_velocity(ws);
        let Workspace {
            cell_state,
            velocity_field,
            ..
        } = ws;
        let cs: &[_] = cell_state;
        let n_nodes = self.lattice().len() as f64;
        let v2: f64 = velocity_field.values().iter().map(|v| v * v).sum::<f64>() / n_nodes;
        let n = cs.len().max(1) as f64;
        let mut o = Observables {
            v_rms: v2.sqrt(),
            area_min: f64::INFINITY,
            area_max: f64::NEG_INFINITY,
            phi_min: f64::INFINITY,
            phi_max: f64::NEG_INFINITY,
            ..Default::default()
        };
        let (mut s2, mut a, mut u2) = (0.0, 0.0, 0.0);
        for c in cs {
            s2 += c.shape.xx * c.shape.xx + c.shape.xy * c.shape.xy;
            u2 += c.velocity.x * c.velocity.x + c.velocity.y * c.velocity.y;
            a += c.area;
            o.area_min = o.area_min.min(c.area);
            o.area_max = o.area_max.max(c.area);
            o.phi_min = o.phi_min.min(c.phi_min);
            o.phi_max = o.phi_max.max(c.phi_max);
        }
        o.s_rms = (s2 / n).sqrt();
        o.area_mean = a / n;
        o.cell_speed_rms = (u2 / n).sqrt();
        o
    }
}
