//! Shared builders and proptest strategies with named domain constants.

use mechanics::{ModelParams, PressureKind, StepParams, Tissue, Workspace};
use phasefield::{init, Cells, Lattice, PatchShape, Real};
use proptest::prelude::*;

/// The paper's time step.
pub const DT: f64 = 0.2;
/// Heun with one corrector pass.
pub const HEUN: StepParams = StepParams::new(DT, 1);
/// Activities swept by the tests: contractile, passive, and the paper's extensile range.
pub const ZETAS: [f64; 4] = [-0.0018, 0.0, 0.005, 0.01];

/// Discs of radius `r0` at `centres` on a square `l × l` lattice with margin `margin`.
pub fn discs(l: usize, margin: usize, centres: &[[f64; 2]], r0: f64) -> Cells {
    let lattice = Lattice::new(l, l);
    init::discs(
        lattice,
        PatchShape::new(lattice, margin).unwrap(),
        centres,
        r0,
        2.5,
    )
}

/// A tissue with the paper's parameters at activity `zeta`.
pub fn tissue(cells: Cells, zeta: f64, pressure: PressureKind) -> (Tissue, Workspace) {
    let mut p = ModelParams::paper(zeta);
    p.pressure = pressure;
    let t = Tissue::new(cells, p);
    let ws = Workspace::new(t.cells());
    (t, ws)
}

/// Advances `n` steps, panicking on a step error.
pub fn advance<T: Real>(t: &mut Tissue<T>, ws: &mut Workspace<T>, n: usize, sp: &StepParams) {
    for _ in 0..n {
        t.step(ws, sp).expect("stable step");
    }
}

/// A confluent state: `n_cells` random cells at the paper's density, relaxed `steps` steps at ζ = 0.
pub fn confluent(l: usize, seed: u64, steps: usize, pressure: PressureKind) -> (Tissue, Workspace) {
    let lattice = Lattice::new(l, l);
    let n = (l * l) as f64 * 15.0 / 2500.0;
    let centres = init::positions(
        lattice,
        n.round() as usize,
        4.0,
        &init::Layout::Random { seed },
    )
    .unwrap();
    let cells = init::discs(
        lattice,
        PatchShape::new(lattice, 12).unwrap(),
        &centres,
        4.0,
        2.5,
    );
    let (mut t, mut ws) = tissue(cells, 0.0, pressure);
    advance(&mut t, &mut ws, steps, &HEUN);
    (t, ws)
}

/// A lattice position: an integer node plus 0 or 1/2, anywhere on an `l × l` lattice.
pub fn node_or_half(l: usize) -> impl Strategy<Value = [f64; 2]> {
    (0..l, 0..l, 0..2u8, 0..2u8)
        .prop_map(|(x, y, hx, hy)| [x as f64 + 0.5 * hx as f64, y as f64 + 0.5 * hy as f64])
}
