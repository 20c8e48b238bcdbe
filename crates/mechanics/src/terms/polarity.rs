//! Self-propulsion and polarity (docs/model.md §11.1): each cell carries an angle `θ_i`, its
//! polarity `p_i = (cos θ_i, sin θ_i)`, and is pushed by the whole-cell force `α p_i`
//! (or `α A_i p_i`, the force density `α φ_i² p_i` summed over the cell), with
//!
//! ```text
//! dθ_i = −J |f_i| Δ(f_i, p_i) dt + √(2 D_r) dW_i
//! ```
//!
//! `Δ(f, p)` the signed angle from the alignment target `f_i` to `p_i` ([`Align`]), `J` the
//! alignment rate per unit of `|f|`, and `D_r` the rotational diffusion constant. Contact
//! inhibition of locomotion comes in two forms: repolarisation away from the cells a cell
//! presses on (`Align::Force`, the reference code's default rule) and a stall of the
//! propulsion against them ([`Polarity::contact_inhibition`]). The reference
//! code's noise amplitude `D_pol` (a step `θ += √dt D_pol N`) is `D_r = D_pol²/2`.

use nalgebra::Vector2;

use super::{signed_angle, CellContext, CellTerm, NoiseKey};

/// What a cell's polarity turns towards.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Align {
    /// Nothing: a persistent random walk.
    #[default]
    None,
    /// The cell's own velocity `v_i` (self-alignment; flocking).
    Velocity,
    /// The interface force `F_i` (pressure and active stress), which points away from the
    /// cells it presses against: a contact-inhibition-like repolarisation.
    Force,
    /// The cell's long axis, `|S_i|` along its eigenvector, the end nearer to `p_i`.
    Shape,
}

/// How the propulsion is spread over the cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Propulsion {
    /// A whole-cell force `α p_i` (the reference code's).
    #[default]
    Cell,
    /// A force density `α φ_i² p_i`, which sums to `α A_i p_i`: `α` is then a force per unit
    /// area, and larger cells are pushed harder.
    Density,
}

/// Self-propulsion along a polarity with rotational diffusion and alignment.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Polarity {
    /// The propulsion force `α` (per cell, or per unit area with [`Propulsion::Density`]).
    pub alpha: f64,
    /// How the force is spread.
    pub propulsion: Propulsion,
    /// The rotational diffusion constant `D_r` (per unit time): `⟨p(t)·p(0)⟩ = e^{−D_r t}`.
    pub rotational_diffusion: f64,
    /// The alignment target.
    pub align: Align,
    /// The alignment rate `J` per unit of the target's magnitude.
    pub align_rate: f64,
    /// Every cell's initial angle; `None`: uniform on the circle, drawn from the seed.
    pub initial_angle: Option<f64>,
    /// Contact inhibition of locomotion η ≥ 0 (0: none): the propulsion stalls against the
    /// cells in front, `α → α exp(−η max(0, −F_i·p_i)/α)` with `F_i` the interface force of the
    /// last evaluation, so a cell that presses on a neighbour along its polarity with a force
    /// `α` pushes with `α e^{−η}`.
    pub contact_inhibition: f64,
    /// Per population (`crate::terms::Populations`), its own `[α, D_r, J]` where given.
    pub by_population: Vec<[Option<f64>; 3]>,
}

impl Polarity {
    /// Propulsion `alpha`, no noise, no alignment, random initial angles.
    pub fn new(alpha: f64) -> Self {
        Self {
            alpha,
            propulsion: Propulsion::Cell,
            rotational_diffusion: 0.0,
            align: Align::None,
            align_rate: 0.0,
            initial_angle: None,
            contact_inhibition: 0.0,
            by_population: Vec::new(),
        }
    }

    /// With contact inhibition of locomotion `eta` (see [`Polarity::contact_inhibition`]).
    pub fn with_contact_inhibition(mut self, eta: f64) -> Self {
        self.contact_inhibition = eta;
        self
    }

    /// With population `k`'s own propulsion, rotational diffusion and alignment rate, where
    /// given.
    pub fn with_population(
        mut self,
        k: usize,
        alpha: Option<f64>,
        rotational_diffusion: Option<f64>,
        align_rate: Option<f64>,
    ) -> Self {
        if self.by_population.len() <= k {
            self.by_population.resize(k + 1, [None; 3]);
        }
        self.by_population[k] = [alpha, rotational_diffusion, align_rate];
        self
    }

    /// `[α, D_r, J]` of a cell of population `k`.
    pub fn values(&self, k: usize) -> [f64; 3] {
        let own = self.by_population.get(k).copied().unwrap_or([None; 3]);
        [
            own[0].unwrap_or(self.alpha),
            own[1].unwrap_or(self.rotational_diffusion),
            own[2].unwrap_or(self.align_rate),
        ]
    }

    /// With rotational diffusion `d_r`.
    pub fn with_rotational_diffusion(mut self, d_r: f64) -> Self {
        self.rotational_diffusion = d_r;
        self
    }

    /// Aligning to `align` at rate `rate`.
    pub fn with_alignment(mut self, align: Align, rate: f64) -> Self {
        self.align = align;
        self.align_rate = rate;
        self
    }

    /// With every cell starting at angle `theta`.
    pub fn with_initial_angle(mut self, theta: f64) -> Self {
        self.initial_angle = Some(theta);
        self
    }

    /// With the force spread as `propulsion`.
    pub fn with_propulsion(mut self, propulsion: Propulsion) -> Self {
        self.propulsion = propulsion;
        self
    }

    /// The alignment target of a cell whose polarity is `p`.
    fn target(&self, cell: &CellContext<'_>, p: Vector2<f64>) -> Vector2<f64> {
        match self.align {
            Align::None => Vector2::zeros(),
            Align::Velocity => cell.state.velocity,
            Align::Force => cell.state.force,
            Align::Shape => {
                let (magnitude, axis) = cell.state.shape.axis();
                let axis = if axis.dot(&p) < 0.0 { -axis } else { axis };
                magnitude * axis
            }
        }
    }
}

/// The polarity `(cos θ, sin θ)`.
pub(crate) fn direction(theta: f64) -> Vector2<f64> {
    let (s, c) = theta.sin_cos();
    Vector2::new(c, s)
}

impl CellTerm for Polarity {
    fn name(&self) -> &str {
        "polarity"
    }

    fn state_names(&self) -> &[&'static str] {
        &["theta"]
    }

    fn describe_state(&self, _variable: &str) -> String {
        "each cell's polarity angle, radians counterclockwise from +x".into()
    }

    fn derived(&self, x: &[f64]) -> Vec<(&'static str, &'static str, Vec<f64>)> {
        vec![(
            "polarity",
            "each cell's polarity (cos theta, sin theta)",
            vec![x[0].cos(), x[0].sin()],
        )]
    }

    fn initial_state(&self, _id: usize, keys: &dyn Fn(u64) -> NoiseKey, out: &mut [f64]) {
        out[0] = match self.initial_angle {
            Some(theta) => theta,
            None => std::f64::consts::PI * (2.0 * keys(0).uniform() - 1.0),
        };
    }

    fn force(&self, cell: &CellContext<'_>, x: &[f64]) -> [f64; 2] {
        if !cell.active {
            return [0.0; 2];
        }
        let [alpha, ..] = self.values(cell.population);
        let mut magnitude = match self.propulsion {
            Propulsion::Cell => alpha,
            Propulsion::Density => alpha * cell.state.area,
        };
        let p = direction(x[0]);
        if self.contact_inhibition > 0.0 && magnitude != 0.0 {
            let against = (-cell.state.force.dot(&p)).max(0.0);
            magnitude *= (-self.contact_inhibition * against / magnitude.abs()).exp();
        }
        [magnitude * p.x, magnitude * p.y]
    }

    fn rate(&self, cell: &CellContext<'_>, x: &[f64], out: &mut [f64]) {
        out[0] = 0.0;
        let [.., rate] = self.values(cell.population);
        if !cell.active || self.align == Align::None || rate == 0.0 {
            return;
        }
        let p = direction(x[0]);
        let f = self.target(cell, p);
        let norm = f.norm();
        if norm > 0.0 {
            out[0] = -rate * norm * signed_angle(f, p);
        }
    }

    fn stiffness(&self, cell: &CellContext<'_>, x: &[f64]) -> f64 {
        let [.., rate] = self.values(cell.population);
        if !cell.active || self.align == Align::None || rate == 0.0 {
            return 0.0;
        }
        // dθ/dt = −J|f| Δ(f, p): near alignment a relaxation at the rate J|f|.
        rate * self.target(cell, direction(x[0])).norm()
    }

    fn noise(&self, cell: &CellContext<'_>, out: &mut [f64]) {
        out[0] = if cell.active {
            (2.0 * self.values(cell.population)[1]).sqrt()
        } else {
            0.0
        };
    }
}
