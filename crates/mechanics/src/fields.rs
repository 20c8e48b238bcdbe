//! Lattice fields of a state for analysis (MODEL.md §7), built by the same code as the step:
//! the tissue velocity `v = Σ_i φ_i v_i`, the nematic field `Q = Σ_i φ_i S_i`, the pressure
//! `P` and the stress `σ = −P𝕀 − ζQ`.

use phasefield::Real;

use crate::scatter::scatter;
use crate::tissue::{pressure, Tissue, Workspace, G_QXX, G_QXY, N_GLOBAL};

/// Lattice fields, each `lx * ly` long with index `x * ly + y`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TissueFields {
    /// `v_x = Σ_i φ_i v_i,x`.
    pub vx: Vec<f64>,
    /// `v_y = Σ_i φ_i v_i,y`.
    pub vy: Vec<f64>,
    /// `Q_xx = Σ_i φ_i S_i,xx` (`Q_yy = −Q_xx`).
    pub qxx: Vec<f64>,
    /// `Q_xy = Σ_i φ_i S_i,xy`.
    pub qxy: Vec<f64>,
    /// The pressure `P` of the run's [`crate::PressureKind`].
    pub pressure: Vec<f64>,
    /// `σ_xx = −P − ζ Q_xx`.
    pub sigma_xx: Vec<f64>,
    /// `σ_yy = −P + ζ Q_xx`.
    pub sigma_yy: Vec<f64>,
    /// `σ_xy = −ζ Q_xy`.
    pub sigma_xy: Vec<f64>,
}

impl<T: Real> Tissue<T> {
    /// Scatters the tissue velocity `Σ_i φ_i v_i` into `ws.field2` (`[vx, vy]` per node), from
    /// the velocities of the last evaluation.
    pub(crate) fn scatter_velocity(&self, ws: &mut Workspace<T>) {
        let Workspace {
            cell_state,
            field2,
            field2_stripes,
            ..
        } = ws;
        let cs: &[_] = cell_state;
        scatter::<2, T, _>(
            &self.cells,
            self.cells.phi(),
            field2,
            field2_stripes,
            |i, _, s| [s.c * cs[i].velocity[0], s.c * cs[i].velocity[1]],
        );
    }

    /// Evaluates the state and returns its lattice fields. Allocates the result; meant for
    /// output steps, not for the time step.
    pub fn fields(&mut self, ws: &mut Workspace<T>) -> TissueFields {
        self.refresh(ws);
        self.scatter_velocity(ws);
        let n = self.lattice().len();
        let zeta = self.params.zeta;
        let rep = self.params.energy.coefficients().repulsion;
        let mut f = TissueFields {
            vx: ws.field2.iter().step_by(2).copied().collect(),
            vy: ws.field2.iter().skip(1).step_by(2).copied().collect(),
            qxx: ws
                .global
                .iter()
                .skip(G_QXX)
                .step_by(N_GLOBAL)
                .copied()
                .collect(),
            qxy: ws
                .global
                .iter()
                .skip(G_QXY)
                .step_by(N_GLOBAL)
                .copied()
                .collect(),
            pressure: ws
                .global
                .chunks_exact(N_GLOBAL)
                .map(|n| pressure(self.params.pressure, rep, n))
                .collect(),
            ..Default::default()
        };
        f.sigma_xx = (0..n).map(|k| -f.pressure[k] - zeta * f.qxx[k]).collect();
        f.sigma_yy = (0..n).map(|k| -f.pressure[k] + zeta * f.qxx[k]).collect();
        f.sigma_xy = (0..n).map(|k| -zeta * f.qxy[k]).collect();
        f
    }
}
