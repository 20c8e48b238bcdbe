//! Lattice fields of a state for analysis (docs/model.md §7), built by the same code as the step:
//! the tissue velocity `v = Σ_i φ_i v_i`, the nematic field `Q = Σ_i φ_i S_i`, the pressure
//! `P` and the stress `σ = −P𝕀 − ζQ`.

use phasefield::kernel::StencilRun;
use phasefield::Real;

use crate::evaluation::{CellState, SumField};
use crate::geometry::TracelessTensor;
use crate::scatter::scatter;
use crate::tissue::Tissue;
use crate::workspace::Workspace;

/// Lattice fields, each `lx * ly` long with index `x * ly + y`.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct TissueFields {
    /// `v_x = Σ_i φ_i v_i,x`.
    pub vx: Vec<f64>,
    /// `v_y = Σ_i φ_i v_i,y`.
    pub vy: Vec<f64>,
    /// `Q_xx = Σ_i φ_i S_i,xx` (`Q_yy = −Q_xx`).
    pub qxx: Vec<f64>,
    /// With `[nematic]`, the cells' own nematic field `M = Σ_i φ_i q_i` (`[M_xx, M_xy]`,
    /// docs/model.md §11.6), whose defects `analyze` finds as it finds `Q`'s.
    pub cell_nematic: Option<[Vec<f64>; 2]>,
    /// `Q_xy = Σ_i φ_i S_i,xy`.
    pub qxy: Vec<f64>,
    /// The pressure `P` of the run's [`crate::PressureKind`].
    pub pressure: Vec<f64>,
    /// `σ_xx = −P − ζ Q_xx` (with populations of their own ζ or the cells' nematic, the
    /// active part is `−Σ_j φ_j (ζ_j S_j + ζ_Q,j q_j)`, docs/model.md §11.6).
    pub sigma_xx: Vec<f64>,
    /// `σ_yy = −P + ζ Q_xx`.
    pub sigma_yy: Vec<f64>,
    /// `σ_xy = −ζ Q_xy`.
    pub sigma_xy: Vec<f64>,
}

impl<T: Real> Tissue<T> {
    /// Scatters the tissue velocity `Σ_i φ_i v_i` into the workspace, from the velocities
    /// of the last evaluation.
    pub(crate) fn scatter_velocity(&self, ws: &mut Workspace<T>) {
        self.scatter_pair(ws, |c, _| [c.velocity.x, c.velocity.y]);
    }

    /// Scatters `Σ_i φ_i a_i` of a per-cell pair `a_i = value(cell state, slot)` of the last
    /// evaluation into the workspace's two-field lattice buffer
    /// ([`Workspace::velocity_field`]).
    fn scatter_pair(
        &self,
        ws: &mut Workspace<T>,
        value: impl Fn(&CellState, usize) -> [f64; 2] + Sync,
    ) {
        let Workspace {
            cell_state,
            velocity_field,
            ..
        } = ws;
        let cs: &[_] = cell_state;
        scatter::<2, T, _, _, _>(
            &self.cells,
            self.cells.phi(),
            velocity_field,
            |i| {
                let [a, b] = value(&cs[i], i);
                move |run: &StencilRun<'_, T>, sums| {
                    run.add_to([], |s, []| [s.c * a, s.c * b], sums)
                }
            },
            |_| {},
        );
    }

    /// Evaluates the state and returns its lattice fields. Allocates the result; meant for
    /// output steps, not for the time step.
    ///
    /// The pressure is the one the force kernel reads ([`SumField::P`]):
    /// [`crate::equations::pressure`] of the lattice sums.
    pub fn fields(&self, ws: &mut Workspace<T>) -> TissueFields {
        self.refresh(ws);
        self.scatter_velocity(ws);
        // With populations of their own ζ, or the cells' nematic stress, the sums hold the
        // active stress's tensor `Σ φ_j (ζ_j S_j + ζ_Q,j q_j)` (as the evaluation weighted
        // them, `kernels::evaluate`), and `Q` is scattered again unweighted.
        let mixed = self.ext.populations.mixed_zeta(&self.params, self.active)
            || self.ext.terms.nematic_stress(self.active);
        let zeta = if mixed { 1.0 } else { self.params.zeta };
        let [vx, vy] = ws.velocity_field();
        let mut f = TissueFields {
            vx,
            vy,
            qxx: ws.sum_field(SumField::Qxx),
            qxy: ws.sum_field(SumField::Qxy),
            pressure: ws.sum_field(SumField::P),
            ..Default::default()
        };
        let n = f.pressure.len();
        f.sigma_xx = (0..n).map(|k| -f.pressure[k] - zeta * f.qxx[k]).collect();
        f.sigma_yy = (0..n).map(|k| -f.pressure[k] + zeta * f.qxx[k]).collect();
        f.sigma_xy = (0..n).map(|k| -zeta * f.qxy[k]).collect();
        if mixed {
            self.scatter_pair(ws, |c, _| c.shape.components());
            [f.qxx, f.qxy] = ws.velocity_field();
        }
        if let Some((nem, theta)) = self.ext.terms.nematic() {
            self.scatter_pair(ws, |_, slot| nem.tensor(theta[self.cell_id[slot]]));
            f.cell_nematic = Some(ws.velocity_field());
        }
        f
    }
}

impl TissueFields {
    /// The nematic field `Q` at lattice node `node` as a tensor (its axis is the local
    /// director).
    pub fn q(&self, node: usize) -> TracelessTensor {
        TracelessTensor::new(self.qxx[node], self.qxy[node])
    }
}
