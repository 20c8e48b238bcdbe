//! The step map about a base state, its Jacobian–vector products and the vector space they
//! live in.
//!
//! A state is the vector `x` of every cell's φ on the patches of the *reference layout* (the
//! base state's patches, in storage order). The map `M` is `steps` time steps; its Jacobian at
//! the base `x₀` acts on a vector `v` as the forward difference
//! `J v ≈ (M(x₀ + εv) − M(x₀))/ε`. A state whose patches have moved since is read back onto
//! the reference layout node by node (a node off the reference patch is dropped; with the
//! margin of a relaxed cell its value is below the patch-edge tail of the tanh profile).

use mechanics::{ModelParams, StepParams, Tissue, Workspace};
use phasefield::Cells;

use crate::StabilityError;

/// Storage index, in `cells`' layout, of cell `i`'s value at lattice node `(x, y)`, or `None`
/// off its patch.
fn index_in(cells: &Cells<f64>, i: usize, x: usize, y: usize) -> Option<usize> {
    let shape = cells.shape();
    let lattice = cells.lattice();
    let (nx, ny) = (shape.nx, shape.ny);
    let [ox, oy] = cells.map().origin[i];
    let u = (x + lattice.lx - ox) % lattice.lx;
    let v = (y + lattice.ly - oy) % lattice.ly;
    if u >= nx || v >= ny {
        return None;
    }
    let [fx, fy] = cells.map().offset[i];
    Some(i * shape.len() + ((u + fx) % nx) * ny + (v + fy) % ny)
}

fn same_layout(a: &Cells<f64>, b: &Cells<f64>, i: usize) -> bool {
    a.map().origin[i] == b.map().origin[i] && a.map().offset[i] == b.map().offset[i]
}

/// Reads `from`'s values at the nodes of `to`'s layout into `out` (length of `to`'s storage);
/// nodes off `from`'s patch read 0.
pub fn transfer(from_cells: &Cells<f64>, from: &[f64], to: &Cells<f64>, out: &mut [f64]) {
    let shape = to.shape();
    let n = shape.len();
    for i in 0..to.n_cells() {
        let dst = &mut out[i * n..(i + 1) * n];
        if same_layout(from_cells, to, i) {
            dst.copy_from_slice(&from[i * n..(i + 1) * n]);
            continue;
        }
        let xs = to.map().cell_x(shape, i);
        let ys = to.map().cell_y(shape, i);
        for (a, &x) in xs.iter().enumerate() {
            for (b, &y) in ys.iter().enumerate() {
                dst[a * shape.ny + b] =
                    index_in(from_cells, i, x as usize, y as usize).map_or(0.0, |k| from[k]);
            }
        }
    }
}

/// The largest change of a field value between two states, compared node by node.
pub fn max_change(a: &Cells<f64>, b: &Cells<f64>) -> f64 {
    let mut on_a = vec![0.0; a.phi().len()];
    transfer(b, b.phi(), a, &mut on_a);
    on_a.iter()
        .zip(a.phi())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The largest cell speed of the last evaluation in `ws`.
pub(crate) fn v_max(ws: &Workspace<f64>) -> f64 {
    ws.cell_states()
        .iter()
        .map(|c| c.velocity.norm())
        .fold(0.0, f64::max)
}

/// Euclidean norm.
pub fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Euclidean inner product.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// A linear operator for the eigensolvers ([`crate::arnoldi`], [`crate::growth_rate`]): the
/// Jacobian of a [`StepMap`] applied by forward differences, or any matrix.
pub trait Operator {
    /// Dimension of the vectors it acts on.
    fn dim(&self) -> usize;
    /// The time one application spans: an eigenvalue μ is the growth rate `ln|μ|/τ`.
    fn horizon(&self) -> f64;
    /// `out = A v`; `eps` is the finite-difference step of an operator that needs one.
    ///
    /// # Errors
    /// Whatever applying it can fail with (a time step).
    fn apply(&mut self, v: &[f64], eps: f64, out: &mut [f64]) -> Result<(), StabilityError>;
    /// Removes the neutral directions from `v` (none by default).
    fn project(&self, _v: &mut [f64]) {}
    /// The weight of component `k` in a random start (1 by default).
    fn weight(&self, _k: usize) -> f64 {
        1.0
    }
}

impl Operator for StepMap {
    fn dim(&self) -> usize {
        self.len()
    }

    fn horizon(&self) -> f64 {
        StepMap::horizon(self)
    }

    fn apply(&mut self, v: &[f64], eps: f64, out: &mut [f64]) -> Result<(), StabilityError> {
        self.jvp(v, eps, out)
    }

    fn project(&self, v: &mut [f64]) {
        StepMap::project(self, v);
    }

    /// `4φ(1 − φ)` of the base: random starts only where a cell's interface is (perturbing the
    /// far tail of a field starts with modes that the double well kills at once).
    fn weight(&self, k: usize) -> f64 {
        let p = self.base.cells().phi()[k];
        (4.0 * p * (1.0 - p)).max(0.0)
    }
}

/// The map `M` of `steps` time steps about a base state, at one activity.
#[derive(Debug)]
pub struct StepMap {
    base: Tissue<f64>,
    image: Tissue<f64>,
    image_vec: Vec<f64>,
    step: StepParams,
    steps: usize,
    ws: Workspace<f64>,
    translations: [Vec<f64>; 2],
    residual_speed: f64,
}

impl StepMap {
    /// The map of `steps` steps of `step` about `base`, with the model parameters `params`
    /// (the activity of the map is `params.zeta`; the base keeps its fields).
    ///
    /// # Errors
    /// [`StabilityError::Step`] when stepping the base fails.
    pub fn new(
        base: &Tissue<f64>,
        params: &ModelParams,
        step: StepParams,
        steps: usize,
    ) -> Result<Self, StabilityError> {
        let cells = base.cells().clone();
        let base = Tissue::restore(
            cells,
            *params,
            0.0,
            0,
            base.centres().to_vec(),
            base.cell_ids().to_vec(),
        )
        .map_err(StabilityError::Step)?;
        let mut ws = Workspace::new(base.cells());
        base.refresh(&mut ws);
        let residual_speed = v_max(&ws);
        let translations = translation_modes(base.cells());
        let steps = steps.max(1);
        let mut image = base.clone();
        for _ in 0..steps {
            image.step(&mut ws, &step)?;
        }
        let mut image_vec = vec![0.0; base.cells().phi().len()];
        transfer(
            image.cells(),
            image.cells().phi(),
            base.cells(),
            &mut image_vec,
        );
        Ok(Self {
            base,
            image,
            image_vec,
            step,
            steps,
            ws,
            translations,
            residual_speed,
        })
    }

    /// Dimension of the state vector.
    pub fn len(&self) -> usize {
        self.base.cells().phi().len()
    }

    /// Whether the state is empty (no cells).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The base state.
    pub fn base(&self) -> &Tissue<f64> {
        &self.base
    }

    /// The base state after one application of the map.
    pub fn image(&self) -> &Tissue<f64> {
        &self.image
    }

    /// The time one application spans, `steps · dt`.
    pub fn horizon(&self) -> f64 {
        self.steps as f64 * self.step.dt
    }

    /// The largest cell speed of the base state at this activity: how far it is from a fixed
    /// point of the map.
    pub fn residual_speed(&self) -> f64 {
        self.residual_speed
    }

    /// `|M(x₀) − x₀|`: how far one application moves the base.
    pub fn drift(&self) -> f64 {
        self.image_vec
            .iter()
            .zip(self.base.cells().phi())
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
            .sqrt()
    }

    /// Applies the map to `t` in place.
    ///
    /// # Errors
    /// [`StabilityError::Step`] when a step fails.
    pub fn advance(&mut self, t: &mut Tissue<f64>) -> Result<(), StabilityError> {
        for _ in 0..self.steps {
            t.step(&mut self.ws, &self.step)?;
        }
        Ok(())
    }

    /// The tissue `t + ε v`, with `v` given on `t`'s own layout.
    ///
    /// # Errors
    /// [`StabilityError::Step`] when the state cannot be rebuilt (never for a `v` of the right
    /// length).
    pub fn displaced(
        &self,
        t: &Tissue<f64>,
        v: &[f64],
        eps: f64,
    ) -> Result<Tissue<f64>, StabilityError> {
        let mut cells = t.cells().clone();
        for (p, d) in cells.phi_mut().iter_mut().zip(v) {
            *p += eps * d;
        }
        Tissue::restore(
            cells,
            *t.params(),
            t.time(),
            t.iteration(),
            t.centres().to_vec(),
            t.cell_ids().to_vec(),
        )
        .map_err(StabilityError::Step)
    }

    /// `t`'s fields on the reference layout.
    pub fn sample(&self, t: &Tissue<f64>, out: &mut [f64]) {
        transfer(t.cells(), t.cells().phi(), self.base.cells(), out);
    }

    /// A vector on the reference layout moved onto `t`'s layout.
    pub fn to_layout_of(&self, t: &Tissue<f64>, v: &[f64], out: &mut [f64]) {
        transfer(self.base.cells(), v, t.cells(), out);
    }

    /// The growth rates of the two uniform translations of the whole tissue (x, then y after
    /// orthogonalisation), which [`StepMap::project`] removes: `σ = ln|t·J t|/τ` for each unit
    /// generator `t` (its Rayleigh quotient: the rate of the translation's own component after
    /// one application). On a continuum they would be neutral (σ = 0); the lattice pins or
    /// frees them, so a study says how far they are from it.
    ///
    /// # Errors
    /// [`StabilityError::Step`] when a step fails.
    pub fn translation_rates(&mut self, eps: f64) -> Result<[f64; 2], StabilityError> {
        let mut out = vec![0.0; self.len()];
        let mut rates = [0.0; 2];
        for (k, rate) in rates.iter_mut().enumerate() {
            let t = self.translations[k].clone();
            self.jvp(&t, eps, &mut out)?;
            *rate = dot(&t, &out).abs().ln() / self.horizon();
        }
        Ok(rates)
    }

    /// Removes the two uniform translations of the whole tissue from `v` (on a continuum they
    /// are neutral, a translated rest state being a rest state; on the lattice they are pinned
    /// or freed a little, [`StepMap::translation_rates`]).
    pub fn project(&self, v: &mut [f64]) {
        for t in &self.translations {
            let c = dot(t, v);
            for (x, y) in v.iter_mut().zip(t) {
                *x -= c * y;
            }
        }
    }

    /// The Jacobian–vector product `(M(x₀ + εv) − M(x₀))/ε` into `out`.
    ///
    /// # Errors
    /// [`StabilityError::Step`] when a step fails.
    pub fn jvp(&mut self, v: &[f64], eps: f64, out: &mut [f64]) -> Result<(), StabilityError> {
        let mut t = self.displaced(&self.base, v, eps)?;
        self.advance(&mut t)?;
        self.sample(&t, out);
        for (o, b) in out.iter_mut().zip(&self.image_vec) {
            *o = (*o - b) / eps;
        }
        Ok(())
    }
}

/// The generators of the two uniform translations, `∂_x φ_i` and `∂_y φ_i` of every cell
/// (central differences on the patch), orthonormalised.
fn translation_modes(cells: &Cells<f64>) -> [Vec<f64>; 2] {
    let all: Vec<usize> = (0..cells.n_cells()).collect();
    translations_of(cells, &all)
}

/// The same generators restricted to the cells `which`, in that order (one patch each): the
/// uniform translation of those cells together, orthonormalised.
pub(crate) fn translations_of(cells: &Cells<f64>, which: &[usize]) -> [Vec<f64>; 2] {
    let shape = cells.shape();
    let (nx, ny, n) = (shape.nx, shape.ny, shape.len());
    let phi = cells.phi();
    let mut gx = vec![0.0; which.len() * n];
    let mut gy = vec![0.0; which.len() * n];
    for (p, &i) in which.iter().enumerate() {
        let f = &phi[i * n..(i + 1) * n];
        for a in 0..nx {
            for b in 0..ny {
                let k = p * n + a * ny + b;
                gx[k] = 0.5 * (f[shape.xp[a] * ny + b] - f[shape.xm[a] * ny + b]);
                gy[k] = 0.5 * (f[a * ny + (b + 1) % ny] - f[a * ny + (b + ny - 1) % ny]);
            }
        }
    }
    let size = norm(&gx);
    gx.iter_mut().for_each(|x| *x /= size);
    let c = dot(&gx, &gy);
    gy.iter_mut().zip(&gx).for_each(|(y, x)| *y -= c * x);
    let size = norm(&gy);
    gy.iter_mut().for_each(|y| *y /= size);
    [gx, gy]
}
