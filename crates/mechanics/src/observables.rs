//! Scalar observables of a state (docs/model.md §7) and the lattice fields they are built from.

use phasefield::Real;

use crate::evaluation::CellState;
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
        Observables::from_cells(v2, cs.iter().map(CellObservables::from))
    }
}

/// What the observables read of one cell ([`Observables::from_cells`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellObservables {
    /// Its area `Σ_x φ_i²`.
    pub area: f64,
    /// Its deformation tensor `[S_xx, S_xy]`.
    pub shape: [f64; 2],
    /// Its velocity.
    pub velocity: [f64; 2],
    /// The smallest φ on its patch.
    pub phi_min: f64,
    /// The largest φ on its patch.
    pub phi_max: f64,
}

impl From<&CellState> for CellObservables {
    fn from(c: &CellState) -> Self {
        CellObservables {
            area: c.area,
            shape: c.shape.components(),
            velocity: [c.velocity.x, c.velocity.y],
            phi_min: c.phi_min,
            phi_max: c.phi_max,
        }
    }
}

impl Observables {
    /// The observables from the mean over the lattice of `|v|²` (`v = Σ_i φ_i v_i`) and each
    /// cell's quantities: the one formula of [`Tissue::observe`] and of a device's reduction
    /// ([`crate::backend::Backend::observe`]).
    pub fn from_cells(mean_v2: f64, cells: impl IntoIterator<Item = CellObservables>) -> Self {
        let mut o = Observables {
            v_rms: mean_v2.sqrt(),
            area_min: f64::INFINITY,
            area_max: f64::NEG_INFINITY,
            phi_min: f64::INFINITY,
            phi_max: f64::NEG_INFINITY,
            ..Default::default()
        };
        let (mut s2, mut a, mut u2, mut n) = (0.0, 0.0, 0.0, 0usize);
        for c in cells {
            let [sxx, sxy] = c.shape;
            let [vx, vy] = c.velocity;
            s2 += sxx * sxx + sxy * sxy;
            u2 += vx * vx + vy * vy;
            a += c.area;
            o.area_min = o.area_min.min(c.area);
            o.area_max = o.area_max.max(c.area);
            o.phi_min = o.phi_min.min(c.phi_min);
            o.phi_max = o.phi_max.max(c.phi_max);
            n += 1;
        }
        let n = n.max(1) as f64;
        o.s_rms = (s2 / n).sqrt();
        o.area_mean = a / n;
        o.cell_speed_rms = (u2 / n).sqrt();
        o
    }
}
