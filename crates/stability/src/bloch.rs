//! Floquet–Bloch stability of the infinite ordered tissue (issue 54).
//!
//! A finite box allows only the wave vectors that fit it, so its threshold depends on its size.
//! The infinite tiling of a rest state that is periodic with a *primitive cell* of a few cells
//! has a Jacobian that commutes with the tiling's translations: its eigenmodes are Bloch waves
//! `δφ_{p,R}(x + R) = e^{ik·R} u_p(x)` (cell `p` of the primitive cell, copied by the lattice
//! vector `R`), one family for every wave vector `k` of the Brillouin zone, with `u` living on
//! the primitive cell's cells. The growth rates `σ(k)` of the map restricted to each `k` make
//! up the whole spectrum; a box of `n × m` primitive cells has exactly the `k` with
//! `k·(n a₁) ∈ 2πℤ` and `k·(m a₂) ∈ 2πℤ`, and the infinite tissue has them all. Its threshold
//! is where `max_k σ(k)` crosses zero.
//!
//! **The primitive cell.** A packing's translation is a symmetry of the lattice only by a whole
//! number of nodes. The hexagonal packing of the stability figure, 6 × 10 cells on 83 × 120
//! nodes, repeats every 83 nodes along the rows and every two rows (24 nodes) across them, so
//! its primitive cell is 6 × 2 cells on 83 × 24 nodes (`HexBox::new(6, 2, area)`), and the
//! figure's box and its tilings 83k × 120k are boxes of `k × 5k` primitive cells. `q` is the
//! wave vector in units of the reciprocal vectors, `k = 2π(q_x/83, q_y/24)`, `q ∈ (−½, ½]²`.
//! The rest state is relaxed on a box of a few primitive cells ([`BlochTiling::relax`]) and
//! copied onto every primitive cell of a larger *supercell*, so that it is periodic with the
//! primitive cell exactly ([`BlochTiling::supercell`]).
//!
//! **The Bloch map.** Applying `J_k` to `u` is done with the real model, one time step at a
//! time: the Bloch wave's real and imaginary parts, `Re(e^{ik·R} u_p)` and `Im(e^{ik·R} u_p)`,
//! are laid on every cell of the supercell, each is pushed through one step's Jacobian–vector
//! product (forward differences, as [`crate::StepMap::jvp`]), and cell `p`'s result is read
//! at its copy nearest the supercell's middle, `R_p`, times `e^{−ik·R_p}`. A step couples a
//! cell only to cells within a few patches of it, so the result is exact when every copy read
//! is farther than that from the supercell's edge, whatever `k` (checked by a test against a
//! supercell that allows the `k`); for a `k` that the supercell allows (`q_x n`, `q_y m`
//! whole), it is exact for any supercell. `τ` is `steps` such steps about the same rest state.
//!
//! `J_k` is complex-linear; the eigensolvers see its real form on `(Re u, Im u)`, whose
//! spectrum is that of `k` together with its conjugate, the spectrum of `−k`: the growth rates
//! are those of `±k`. At `k = 0` the two uniform translations of the whole tissue are
//! projected out as in [`crate::StepMap`].

use mechanics::{ModelParams, StepParams, Tissue};
use phasefield::Cells;

use crate::map::{dot, norm, translations_of, Operator, StepMap};
use crate::rest::{rest_state, HexBox, Relaxation, RestState};
use crate::StabilityError;

/// A rest state periodic with a primitive cell of a hexagonal packing (a [`HexBox`] of `cols`
/// columns and an even number of rows), relaxed on a box of `reps` primitive cells, that can
/// be laid on any supercell.
#[derive(Debug, Clone)]
pub struct BlochTiling {
    /// The primitive cell.
    pub primitive: HexBox,
    /// Primitive cells along x and y of the box the rest state was relaxed on.
    pub reps: [usize; 2],
    /// The relaxed rest state on that box.
    pub rest: RestState,
}

/// `reps` copies of the primitive cell `p`.
pub fn repeat(p: &HexBox, reps: [usize; 2]) -> HexBox {
    HexBox {
        cols: p.cols * reps[0],
        rows: p.rows * reps[1],
        lx: p.lx * reps[0],
        ly: p.ly * reps[1],
    }
}

/// Where cell `j` of a box of copies of `primitive` (`cols` columns in all) sits: its cell `p`
/// of the primitive cell and the copy `R` (in primitive cells).
fn place(primitive: &HexBox, cols: usize, j: usize) -> (usize, [usize; 2]) {
    let (row, col) = (j / cols, j % cols);
    let (pc, pr) = (primitive.cols, primitive.rows);
    ((row % pr) * pc + col % pc, [col / pc, row / pr])
}

/// Index of cell `p` of copy `r` in a box of copies of `primitive` with `cols` columns in all.
fn index(primitive: &HexBox, cols: usize, p: usize, r: [usize; 2]) -> usize {
    let (pc, pr) = (primitive.cols, primitive.rows);
    (r[1] * pr + p / pc) * cols + r[0] * pc + p % pc
}

impl BlochTiling {
    /// Relaxes the packing at ζ = 0 on `reps` copies of `primitive` (each side must hold a
    /// patch: `2·margin + 1` nodes).
    ///
    /// # Errors
    /// [`StabilityError::Packing`] when the patches do not fit or the relaxed state is not
    /// periodic with the primitive cell, [`StabilityError::Step`] when a step fails.
    pub fn relax(
        primitive: HexBox,
        reps: [usize; 2],
        params: &ModelParams,
        relax: &Relaxation,
    ) -> Result<Self, StabilityError> {
        let boxed = repeat(&primitive, reps);
        let rest = rest_state(&boxed, params, relax)?;
        let tiling = Self {
            primitive,
            reps,
            rest,
        };
        tiling.check_periodic()?;
        Ok(tiling)
    }

    /// The largest difference between a cell of the relaxed box and the same cell of the
    /// first copy of the primitive cell (round-off: the packing and the dynamics are periodic).
    pub fn asymmetry(&self) -> f64 {
        let cells = self.rest.tissue.cells();
        let n = cells.patch_len();
        let cols = self.reps[0] * self.primitive.cols;
        let mut worst: f64 = 0.0;
        for j in 0..cells.n_cells() {
            let (p, _) = place(&self.primitive, cols, j);
            let r = index(&self.primitive, cols, p, [0, 0]);
            let a = &cells.phi()[j * n..(j + 1) * n];
            let b = &cells.phi()[r * n..(r + 1) * n];
            for (x, y) in a.iter().zip(b) {
                worst = worst.max((x - y).abs());
            }
        }
        worst
    }

    /// Copy `r`'s displacement in nodes.
    fn shift(&self, r: [usize; 2]) -> [usize; 2] {
        [r[0] * self.primitive.lx, r[1] * self.primitive.ly]
    }

    fn check_periodic(&self) -> Result<(), StabilityError> {
        let cells = self.rest.tissue.cells();
        let lattice = cells.lattice();
        let cols = self.reps[0] * self.primitive.cols;
        for j in 0..cells.n_cells() {
            let (p, r) = place(&self.primitive, cols, j);
            let first = index(&self.primitive, cols, p, [0, 0]);
            let o = cells.map().origin[first];
            let d = self.shift(r);
            let want = [(o[0] + d[0]) % lattice.lx, (o[1] + d[1]) % lattice.ly];
            if cells.map().origin[j] != want || cells.map().offset[j] != cells.map().offset[first] {
                return Err(StabilityError::Packing(format!(
                    "cell {j} of the relaxed box is not a translate of cell {first}: its patch moved on its own"
                )));
            }
        }
        let a = self.asymmetry();
        if a > 1e-8 {
            return Err(StabilityError::Packing(format!(
                "the relaxed box is not periodic with the primitive cell: fields differ by {a:.1e}"
            )));
        }
        Ok(())
    }

    /// How far one time step reaches, in nodes: three patch margins (a cell's field at a node
    /// feeds the velocities of the cells whose patches hold the node, whose fields move over
    /// their own patches, at both stages of Heun's step). Measured: with margin 16 a copy read
    /// 48 nodes from the supercell's edge gives the exact step to 4·10⁻⁸ and one read 36 or
    /// 41.5 nodes from it is off by 10⁻² (and with margin 11, 36 nodes against 28).
    pub fn reach(&self) -> usize {
        3 * self.rest.tissue.cells().shape().margin.unwrap_or(0)
    }

    /// The supercell for the wave vector `q`: along each axis the fewest copies that fit `q`
    /// exactly (`q n` whole; then the edge does not matter) when that is no more than the
    /// copies that put every cell read [`BlochTiling::reach`] from the edge; otherwise those.
    /// Never fewer than a patch needs.
    pub fn supercell_for(&self, q: [f64; 2]) -> [usize; 2] {
        let side = 2 * self.rest.tissue.cells().shape().margin.unwrap_or(0) + 1;
        let reach = self.reach();
        let mut reps = [1; 2];
        for (axis, a) in [self.primitive.lx, self.primitive.ly]
            .into_iter()
            .enumerate()
        {
            // The copy read is at most a/2 from the middle: (n − 1) a / 2 ≥ reach.
            let safe = (2 * reach).div_ceil(a) + 1;
            let fits = side.div_ceil(a);
            let whole = (1..=safe).find(|&n| {
                let x = q[axis] * n as f64;
                (x - x.round()).abs() < 1e-9
            });
            reps[axis] = whole.unwrap_or(safe).max(fits);
        }
        reps
    }

    /// The rest state laid on `reps` primitive cells, every cell a translated copy of the
    /// relaxed box's first copy (so periodic with the primitive cell exactly), with the model
    /// parameters `params`.
    ///
    /// # Errors
    /// [`StabilityError::Packing`] when the supercell does not hold a patch.
    pub fn supercell(
        &self,
        reps: [usize; 2],
        params: &ModelParams,
    ) -> Result<Tissue<f64>, StabilityError> {
        let hex = repeat(&self.primitive, reps);
        let lattice = hex.lattice();
        let src = self.rest.tissue.cells();
        let shape = phasefield::PatchShape::new(lattice, src.shape().margin.unwrap_or(0))
            .map_err(|e| StabilityError::Packing(e.to_string()))?;
        if shape.nx != src.shape().nx || shape.ny != src.shape().ny {
            return Err(StabilityError::Packing(
                "the supercell's patches differ from the relaxed box's".into(),
            ));
        }
        let n = src.patch_len();
        let src_cols = self.reps[0] * self.primitive.cols;
        let (mut phi, mut origin, mut offset, mut centres) = (vec![], vec![], vec![], vec![]);
        for j in 0..hex.n_cells() {
            let (p, r) = place(&self.primitive, hex.cols, j);
            let first = index(&self.primitive, src_cols, p, [0, 0]);
            phi.extend_from_slice(&src.phi()[first * n..(first + 1) * n]);
            let o = src.map().origin[first];
            let d = self.shift(r);
            origin.push([(o[0] + d[0]) % lattice.lx, (o[1] + d[1]) % lattice.ly]);
            offset.push(src.map().offset[first]);
            let c = self.rest.tissue.centres()[first];
            centres.push([
                (c[0] + d[0] as f64) % lattice.lx as f64,
                (c[1] + d[1] as f64) % lattice.ly as f64,
            ]);
        }
        let cells = Cells::from_storage(lattice, shape, phi, origin, offset)
            .map_err(StabilityError::Packing)?;
        let ids = (0..cells.n_cells()).collect();
        Tissue::restore(cells, *params, 0.0, 0, centres, ids).map_err(StabilityError::Packing)
    }
}

/// The wave vectors a box of `n` primitive cells allows, `q = (a/n_x, b/n_y)` reduced to
/// `(−½, ½]`, one of each pair `±q` (their growth rates are the same).
pub fn box_wavevectors(n: [usize; 2]) -> Vec<[f64; 2]> {
    let reduce = |a: usize, m: usize| {
        let x = a as f64 / m as f64;
        if x > 0.5 {
            x - 1.0
        } else {
            x
        }
    };
    let mut out: Vec<[f64; 2]> = vec![];
    for a in 0..n[0] {
        for b in 0..n[1] {
            let q = [reduce(a, n[0]), reduce(b, n[1])];
            let minus = [
                reduce((n[0] - a) % n[0], n[0]),
                reduce((n[1] - b) % n[1], n[1]),
            ];
            if !out.contains(&minus) {
                out.push(q);
            }
        }
    }
    out
}

/// The Jacobian of `steps` time steps about a periodic rest state restricted to the Bloch
/// waves of one wave vector `q` (in units of the primitive cell's reciprocal vectors), in its
/// real form on `(Re u, Im u)` of the primitive cell's cells.
#[derive(Debug)]
pub struct BlochMap {
    one_step: StepMap,
    steps: usize,
    dt: f64,
    q: [f64; 2],
    /// For every supercell cell: its cell of the primitive cell and its copy.
    places: Vec<(usize, [usize; 2])>,
    /// For every cell of the primitive cell: the supercell index and copy it is read at.
    read: Vec<(usize, [usize; 2])>,
    patch: usize,
    translations: Option<[Vec<f64>; 2]>,
    field_re: Vec<f64>,
    field_im: Vec<f64>,
    out_re: Vec<f64>,
    out_im: Vec<f64>,
}

impl BlochMap {
    /// The map of `steps` steps of `step` at `params` (its activity) about `tiling`'s rest
    /// state, on a supercell of `reps` primitive cells, at wave vector `q`.
    ///
    /// # Errors
    /// [`StabilityError::Packing`] when the supercell does not fit, [`StabilityError::Step`]
    /// when a step of the base fails.
    pub fn new(
        tiling: &BlochTiling,
        params: &ModelParams,
        step: StepParams,
        steps: usize,
        reps: [usize; 2],
        q: [f64; 2],
    ) -> Result<Self, StabilityError> {
        let base = tiling.supercell(reps, params)?;
        let one_step = StepMap::new(&base, params, step, 1)?;
        let patch = base.cells().patch_len();
        let prim = &tiling.primitive;
        let cols = prim.cols * reps[0];
        let places: Vec<_> = (0..base.cells().n_cells())
            .map(|j| place(prim, cols, j))
            .collect();
        // Each cell is read at its copy nearest the middle of the supercell, along each axis.
        let lattice = base.cells().lattice();
        let middle = [lattice.lx as f64 / 2.0, lattice.ly as f64 / 2.0];
        let read: Vec<_> = (0..prim.n_cells())
            .map(|p| {
                let c = base.centres()[index(prim, cols, p, [0, 0])];
                let best = |axis: usize, side: usize, count: usize| {
                    (0..count)
                        .min_by(|&a, &b| {
                            let d = |r: usize| (c[axis] + (r * side) as f64 - middle[axis]).abs();
                            d(a).total_cmp(&d(b))
                        })
                        .unwrap_or(0)
                };
                let r = [best(0, prim.lx, reps[0]), best(1, prim.ly, reps[1])];
                (index(prim, cols, p, r), r)
            })
            .collect();
        let copies: Vec<usize> = read.iter().map(|r| r.0).collect();
        // At k = 0 the uniform translation of the primitive cell's cells is neutral.
        let translations = (q == [0.0, 0.0]).then(|| translations_of(base.cells(), &copies));
        let len = base.cells().phi().len();
        Ok(Self {
            one_step,
            steps: steps.max(1),
            dt: step.dt,
            q,
            places,
            read,
            patch,
            translations,
            field_re: vec![0.0; len],
            field_im: vec![0.0; len],
            out_re: vec![0.0; len],
            out_im: vec![0.0; len],
        })
    }

    /// The wave vector, in units of the reciprocal vectors.
    pub fn q(&self) -> [f64; 2] {
        self.q
    }

    /// Cells of the primitive cell.
    fn cells(&self) -> usize {
        self.read.len()
    }

    /// The Bloch phase `2π q·R` of copy `r`.
    fn phase(&self, r: [usize; 2]) -> f64 {
        std::f64::consts::TAU * (self.q[0] * r[0] as f64 + self.q[1] * r[1] as f64)
    }

    /// One step of `J_k` on `u = (re, im)` in place.
    fn step_once(
        &mut self,
        re: &mut [f64],
        im: &mut [f64],
        eps: f64,
    ) -> Result<(), StabilityError> {
        let n = self.patch;
        for (j, &(p, r)) in self.places.iter().enumerate() {
            let (s, c) = self.phase(r).sin_cos();
            let (ur, ui) = (&re[p * n..(p + 1) * n], &im[p * n..(p + 1) * n]);
            let fr = &mut self.field_re[j * n..(j + 1) * n];
            let fi = &mut self.field_im[j * n..(j + 1) * n];
            for k in 0..n {
                fr[k] = c * ur[k] - s * ui[k];
                fi[k] = s * ur[k] + c * ui[k];
            }
        }
        for (field, out) in [
            (&mut self.field_re, &mut self.out_re),
            (&mut self.field_im, &mut self.out_im),
        ] {
            let size = norm(field);
            if size == 0.0 {
                out.iter_mut().for_each(|x| *x = 0.0);
                continue;
            }
            field.iter_mut().for_each(|x| *x /= size);
            self.one_step.jvp(field, eps, out)?;
            out.iter_mut().for_each(|x| *x *= size);
        }
        for (p, &(j, r)) in self.read.iter().enumerate() {
            let (s, c) = (-self.phase(r)).sin_cos();
            let (or, oi) = (
                &self.out_re[j * n..(j + 1) * n],
                &self.out_im[j * n..(j + 1) * n],
            );
            for k in 0..n {
                re[p * n + k] = c * or[k] - s * oi[k];
                im[p * n + k] = s * or[k] + c * oi[k];
            }
        }
        Ok(())
    }
}

impl Operator for BlochMap {
    fn dim(&self) -> usize {
        2 * self.cells() * self.patch
    }

    fn horizon(&self) -> f64 {
        self.steps as f64 * self.dt
    }

    fn apply(&mut self, v: &[f64], eps: f64, out: &mut [f64]) -> Result<(), StabilityError> {
        let h = self.cells() * self.patch;
        let (mut re, mut im) = (v[..h].to_vec(), v[h..].to_vec());
        for _ in 0..self.steps {
            self.step_once(&mut re, &mut im, eps)?;
        }
        out[..h].copy_from_slice(&re);
        out[h..].copy_from_slice(&im);
        Ok(())
    }

    fn project(&self, v: &mut [f64]) {
        let Some(t) = &self.translations else { return };
        let h = self.cells() * self.patch;
        for part in [0, h] {
            for g in t {
                let c = dot(g, &v[part..part + h]);
                v[part..part + h]
                    .iter_mut()
                    .zip(g)
                    .for_each(|(x, y)| *x -= c * y);
            }
        }
    }

    /// `4φ(1 − φ)` of the base, as [`StepMap`]'s.
    fn weight(&self, k: usize) -> f64 {
        let n = self.patch;
        let k = k % (self.cells() * n);
        let j = self.read[k / n].0;
        let p = self.one_step.base().cells().phi()[j * n + k % n];
        (4.0 * p * (1.0 - p)).max(0.0)
    }
}
