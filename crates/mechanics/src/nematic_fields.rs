//! The lattice fields a cell nematic's dynamics read (docs/model.md §11.6), and what each cell
//! reads of them: the nematic field `M = Σ_j φ_j q_j`, the flow `u = Σ_j φ_j v_j /
//! max(Σ_j φ_j, ½)`, and per cell their means `⟨M⟩_i` and `⟨½ ∇ × u⟩_i` over the cell
//! (`⟨f⟩_i = Σ_x φ_i f / Σ_x φ_i`), into [`CellState::nematic_field`] and
//! [`CellState::vorticity`].
//!
//! One scatter of five fields (`s1`, `M`, `U`) after the evaluation's velocities are known,
//! then one pass over each patch: measured only when the nematic's dynamics read them
//! (`CellNematic::reads_fields`), so a run without the nematic never comes here. The curl is
//! the central difference on the lattice (spacing 1), exact for a linear flow; the scatter is
//! the evaluation's (in cell order per node), so the result does not depend on the threads.

use phasefield::{Cells, Real};
use rayon::prelude::*;

use crate::evaluation::CellState;
use crate::scatter::{scatter, LatticeSums};

/// The fields of the measurement: `s1`, `M_xx`, `M_xy`, `U_x`, `U_y`.
pub(crate) const N_FIELDS: usize = 5;

/// Below this `s1` the flow `U / s1` is damped to `U / ½` (a gap between cells: `u` goes to
/// zero continuously, where `U / s1` would divide by nearly nothing).
const S1_FLOOR: f64 = 0.5;

/// Measures `⟨M⟩_i` and `⟨½ ∇ × u⟩_i` of every cell into `cell_state` (whose velocities the
/// evaluation of the same fields left), with `q[i]` each slot's nematic tensor and `fields`
/// the scratch of the sums.
pub(crate) fn measure<T: Real>(
    cells: &Cells<T>,
    phi: &[T],
    q: &[[f64; 2]],
    cell_state: &mut [CellState],
    fields: &mut LatticeSums<N_FIELDS>,
) {
    let states: &[CellState] = cell_state;
    scatter::<N_FIELDS, T, _, _, _>(
        cells,
        phi,
        fields,
        |i| {
            let ([qxx, qxy], v) = (q[i], states[i].velocity);
            let (vx, vy) = (v.x, v.y);
            move |run: &phasefield::kernel::StencilRun<'_, T>, out: [&mut [f64]; N_FIELDS]| {
                run.add_to(
                    [],
                    move |s, []| {
                        let p = s.c;
                        [p, p * qxx, p * qxy, p * vx, p * vy]
                    },
                    out,
                )
            }
        },
        |_| {},
    );
    let fields: &LatticeSums<N_FIELDS> = fields;
    let lattice = cells.lattice();
    let (lx, ly) = (lattice.lx, lattice.ly);
    let (shape, map) = (cells.shape(), cells.map());
    let plen = shape.len();
    cell_state
        .par_iter_mut()
        .zip(phi.par_chunks(plen))
        .enumerate()
        .for_each(|(i, (st, cell))| {
            let ys = map.cell_y(shape, i);
            let flow = |u: f64, s1: f64| u / s1.max(S1_FLOOR);
            let (mut w, mut m, mut curl) = (0.0, [0.0; 2], 0.0);
            for (a, &x) in map.cell_x(shape, i).iter().enumerate() {
                let x = x as usize;
                let [s1, mxx, mxy, ux, _] = fields.columns(x);
                let [s1_right, _, _, _, uy_right] =
                    fields.columns(if x + 1 == lx { 0 } else { x + 1 });
                let [s1_left, _, _, _, uy_left] =
                    fields.columns(if x == 0 { lx - 1 } else { x - 1 });
                let column = &cell[a * shape.ny..(a + 1) * shape.ny];
                for (&y, p) in ys.iter().zip(column) {
                    let (y, p) = (y as usize, p.to_f64());
                    let up = if y + 1 == ly { 0 } else { y + 1 };
                    let down = if y == 0 { ly - 1 } else { y - 1 };
                    let dx_uy =
                        0.5 * (flow(uy_right[y], s1_right[y]) - flow(uy_left[y], s1_left[y]));
                    let dy_ux = 0.5 * (flow(ux[up], s1[up]) - flow(ux[down], s1[down]));
                    w += p;
                    m[0] += p * mxx[y];
                    m[1] += p * mxy[y];
                    curl += p * (dx_uy - dy_ux);
                }
            }
            if w != 0.0 {
                st.nematic_field = [m[0] / w, m[1] / w];
                st.vorticity = 0.5 * curl / w;
            } else {
                st.nematic_field = [0.0; 2];
                st.vorticity = 0.0;
            }
        });
}
