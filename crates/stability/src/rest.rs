//! The rest state: a hexagonal packing on a box commensurate with it, relaxed at ζ = 0.

use mechanics::{ModelParams, StepError, StepParams, Tissue, Workspace};
use phasefield::{init, Cells, Lattice, PatchShape};

use crate::StabilityError;

/// A hexagonal packing of `cols × rows` cells on a box chosen to fit it.
///
/// Rows are `a·√3/2` apart and alternate rows are shifted by half a spacing, so `rows` must be
/// even for the packing to be periodic. The box is the nearest integer box, `lx = round(cols·a)`,
/// `ly = round(rows·a·√3/2)`; the spacings it implies, `a_x = lx/cols` along the rows and
/// `a_y = (ly/rows)·2/√3` across them, differ by the *residual anisotropy* `a_x/a_y − 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HexBox {
    /// Cells per row.
    pub cols: usize,
    /// Rows (even).
    pub rows: usize,
    /// Lattice nodes along x.
    pub lx: usize,
    /// Lattice nodes along y.
    pub ly: usize,
}

impl HexBox {
    /// The box for `cols × rows` cells at the density of `area_per_cell` nodes per cell (the
    /// paper's 60 cells on 100 × 100: 166.7).
    ///
    /// # Errors
    /// [`StabilityError::Packing`] for an odd `rows` or a zero count.
    pub fn new(cols: usize, rows: usize, area_per_cell: f64) -> Result<Self, StabilityError> {
        if cols == 0 || rows == 0 || rows % 2 == 1 {
            return Err(StabilityError::Packing(format!(
                "{cols} × {rows}: a periodic hexagonal packing needs at least one column and an even, non-zero number of rows"
            )));
        }
        let a = (2.0 * area_per_cell / 3f64.sqrt()).sqrt();
        Ok(Self {
            cols,
            rows,
            lx: (cols as f64 * a).round() as usize,
            ly: (rows as f64 * a * 3f64.sqrt() / 2.0).round() as usize,
        })
    }

    /// `k × k` copies of this box: `k` times the columns, rows and sides, so that the spacings,
    /// the residual anisotropy and the packing's alignment to the grid are exactly this box's
    /// (a box made by [`HexBox::new`] for the larger packing rounds its sides afresh, e.g.
    /// 24 × 40 cells on 333 × 481 against 4 × (83 × 120) = 332 × 480).
    pub fn tiled(&self, k: usize) -> Self {
        Self {
            cols: self.cols * k,
            rows: self.rows * k,
            lx: self.lx * k,
            ly: self.ly * k,
        }
    }

    /// Number of cells.
    pub fn n_cells(&self) -> usize {
        self.cols * self.rows
    }

    /// The spacings `[a_x, a_y]` the box implies along and across the rows.
    pub fn spacings(&self) -> [f64; 2] {
        [
            self.lx as f64 / self.cols as f64,
            self.ly as f64 / self.rows as f64 * 2.0 / 3f64.sqrt(),
        ]
    }

    /// The residual anisotropy `a_x/a_y − 1` of the packing on this box.
    pub fn anisotropy(&self) -> f64 {
        let [ax, ay] = self.spacings();
        ax / ay - 1.0
    }

    /// The lattice of the box.
    pub fn lattice(&self) -> Lattice {
        Lattice::new(self.lx, self.ly)
    }

    /// The centres of the packing, row by row; odd rows shifted by half a spacing.
    pub fn centres(&self) -> Vec<[f64; 2]> {
        let (sx, sy) = (
            self.lx as f64 / self.cols as f64,
            self.ly as f64 / self.rows as f64,
        );
        let mut out = Vec::with_capacity(self.n_cells());
        for r in 0..self.rows {
            let shift = if r % 2 == 1 { 0.5 } else { 0.0 };
            for c in 0..self.cols {
                out.push([(c as f64 + 0.25 + shift) * sx, (r as f64 + 0.5) * sy]);
            }
        }
        out
    }
}

/// A relaxed rest state and how it got there.
#[derive(Debug, Clone)]
pub struct RestState {
    /// The relaxed tissue (f64 storage).
    pub tissue: Tissue<f64>,
    /// Time it was relaxed for.
    pub time: f64,
    /// The largest cell speed `max_i |v_i|` at the end.
    pub v_max: f64,
    /// The largest rate of change of a field, `max |Δφ|/Δt` over the last check interval.
    pub phi_rate: f64,
    /// `S_rms` at the end: the shape anisotropy the packing keeps at rest.
    pub s_rms: f64,
}

/// How to relax a packing to rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Relaxation {
    /// The step.
    pub step: StepParams,
    /// The patch margin (0: the full domain).
    pub margin: usize,
    /// Initial disc radius as a fraction of the target radius R.
    pub init_radius: f64,
    /// Stop when every field changes by less than this per unit time, `max |Δφ|/Δt`, over a
    /// check interval (a fixed point of the step is a zero of the right-hand side whatever
    /// the time step, so the relaxation may use a larger step than the analysis).
    pub phi_rate: f64,
    /// Do not stop before this time.
    pub min_time: f64,
    /// Give up after this time.
    pub max_time: f64,
    /// Check every this many steps.
    pub check_every: usize,
}

impl Default for Relaxation {
    fn default() -> Self {
        Self {
            step: StepParams::new(0.5, 1),
            margin: 16,
            init_radius: 0.8,
            phi_rate: 1e-7,
            min_time: 200.0,
            max_time: 20_000.0,
            check_every: 200,
        }
    }
}

/// Builds the packing of `hex` as discs and relaxes it at ζ = 0 (whatever `params.zeta`), until
/// its fields change by less than `relax.phi_rate` per unit time, or `relax.max_time`.
///
/// # Errors
/// [`StabilityError::Packing`] when the patch does not fit the box, [`StabilityError::Step`]
/// when a step fails.
pub fn rest_state(
    hex: &HexBox,
    params: &ModelParams,
    relax: &Relaxation,
) -> Result<RestState, StabilityError> {
    let lattice = hex.lattice();
    let shape = PatchShape::new(lattice, relax.margin)
        .map_err(|e| StabilityError::Packing(e.to_string()))?;
    let centres = hex.centres();
    let radius = relax.init_radius * params.energy.radius;
    let cells: Cells<f64> = init::discs(lattice, shape, &centres, radius, params.energy.lambda);
    let mut tissue = Tissue::new(cells, (*params).with_zeta(0.0));
    let mut ws = Workspace::new(tissue.cells());
    loop {
        let before = tissue.clone();
        for _ in 0..relax.check_every {
            tissue.step(&mut ws, &relax.step)?;
        }
        let t = tissue.time();
        let phi_rate = crate::map::max_change(before.cells(), tissue.cells()) / (t - before.time());
        if t >= relax.max_time || (t >= relax.min_time && phi_rate < relax.phi_rate) {
            tissue.refresh(&mut ws);
            let v = crate::map::v_max(&ws);
            let s_rms = tissue.observe(&mut ws).s_rms;
            return Ok(RestState {
                tissue,
                time: t,
                v_max: v,
                phi_rate,
                s_rms,
            });
        }
    }
}

impl From<StepError> for StabilityError {
    fn from(e: StepError) -> Self {
        StabilityError::Step(e.to_string())
    }
}
