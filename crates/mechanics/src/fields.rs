//! Lattice fields of a state for analysis (MODEL.md §7), built by the same code as the step:
//! the tissue velocity `v = Σ_i φ_i v_i`, the nematic field `Q = Σ_i φ_i S_i`, the pressure
//! `P` and the stress `σ = −P𝕀 − ζQ`.

use phasefield::Real;

use crate::scatter::scatter;
use crate::tissue::{pressure, Tissue, Workspace, G_QXX, G_QXY, G_S1, G_S2, G_U};

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
    /// Scatters the tissue velocity `Σ_i φ_i v_i` into `ws.field2` (fields `vx`, `vy`), from
    /// the velocities of the last evaluation.
    pub(crate) fn scatter_velocity(&self, ws: &mut Workspace<T>) {
        let Workspace {
            cell_state, field2, ..
        } = ws;
        let cs: &[_] = cell_state;
        scatter::<2, T, _>(&self.cells, self.cells.phi(), field2, |i, run, sums| {
            let [ux, uy] = cs[i].velocity;
            let [vx, vy] = sums;
            let n = run.c.len();
            let (vx, vy) = (&mut vx[..n], &mut vy[..n]);
            run.map(
                [],
                |s, []| [s.c * ux, s.c * uy],
                |j, [x, y]| {
                    vx[j] += x;
                    vy[j] += y;
                },
            );
        });
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
            vx: ws.field2.field(0),
            vy: ws.field2.field(1),
            qxx: ws.global.field(G_QXX),
            qxy: ws.global.field(G_QXY),
            pressure: (0..n)
                .map(|k| {
                    let g = |c| ws.global.get(c, k);
                    pressure(self.params.pressure, rep, g(G_S1), g(G_S2), g(G_U))
                })
                .collect(),
            ..Default::default()
        };
        f.sigma_xx = (0..n).map(|k| -f.pressure[k] - zeta * f.qxx[k]).collect();
        f.sigma_yy = (0..n).map(|k| -f.pressure[k] + zeta * f.qxx[k]).collect();
        f.sigma_xy = (0..n).map(|k| -zeta * f.qxy[k]).collect();
        f
    }
}
