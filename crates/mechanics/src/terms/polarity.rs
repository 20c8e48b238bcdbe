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

impl Align {
    /// Its value in a scene (`"velocity"`), as the terms' settings list it.
    pub fn key(self) -> &'static str {
        match self {
            Align::None => "none",
            Align::Velocity => "velocity",
            Align::Force => "force",
            Align::Shape => "shape",
        }
    }

    /// The target it names for `cell` ([`alignment_target`] of what the cell's evaluation
    /// left), with the polarity or nematic angle `theta`.
    pub(crate) fn target_of(self, cell: &CellContext<'_>, theta: f64) -> [f64; 2] {
        let s = cell.state;
        alignment_target(
            self,
            [s.velocity.x, s.velocity.y],
            [s.force.x, s.force.y],
            s.shape.components(),
            theta,
        )
    }
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
    fn target(&self, cell: &CellContext<'_>, theta: f64) -> [f64; 2] {
        self.align.target_of(cell, theta)
    }
}

/// The alignment target of a cell whose polarity angle is `theta` ([`Align`]): its velocity
/// `v`, its interface force `f`, or its long axis `|S| n` (`S = [S_xx, S_xy]`, traceless:
/// the eigenvalue `|S| = √(S_xx² + S_xy²)` along `n = (cos φ, sin φ)`, `φ = ½ atan2(S_xy,
/// S_xx)`, turned to the end nearer the polarity); zero for [`Align::None`]. The GPU's
/// `polarity_target` is checked against this.
pub fn alignment_target(
    align: Align,
    v: [f64; 2],
    f: [f64; 2],
    s: [f64; 2],
    theta: f64,
) -> [f64; 2] {
    match align {
        Align::None => [0.0; 2],
        Align::Velocity => v,
        Align::Force => f,
        Align::Shape => {
            let magnitude = s[0].hypot(s[1]);
            if magnitude == 0.0 {
                return [0.0; 2];
            }
            let (sin, cos) = (0.5 * s[1].atan2(s[0])).sin_cos();
            let p = direction(theta);
            let m = if cos * p.x + sin * p.y < 0.0 {
                -magnitude
            } else {
                magnitude
            };
            [m * cos, m * sin]
        }
    }
}

/// The propulsion `m p` of a cell whose polarity angle is `theta`, from its magnitude
/// `magnitude` (`α`, or `α A_i` spread as a density) and its interface force `f`: with
/// contact inhibition `eta > 0` the magnitude stalls to `m = magnitude exp(−η max(0, −f·p) /
/// |magnitude|)`. The GPU's `polarity_force` is checked against this.
pub fn propulsion(magnitude: f64, eta: f64, f: [f64; 2], theta: f64) -> [f64; 2] {
    let p = direction(theta);
    let mut m = magnitude;
    if eta > 0.0 && m != 0.0 {
        let against = (-(f[0] * p.x + f[1] * p.y)).max(0.0);
        m *= (-eta * against / m.abs()).exp();
    }
    [m * p.x, m * p.y]
}

/// The alignment rate `dθ/dt = −J |t| Δ(t, p)` of a polarity angle `theta` towards the
/// target `t` at rate `rate` (`J`), zero for a zero target. The GPU's `polarity_rate` is
/// checked against this.
pub fn alignment_rate(rate: f64, t: [f64; 2], theta: f64) -> f64 {
    let t = Vector2::from(t);
    let norm = t.norm();
    if norm > 0.0 {
        -rate * norm * signed_angle(t, direction(theta))
    } else {
        0.0
    }
}

/// `|⟨(cos a, sin a)⟩|` over the angles `angles` (NaN for none): the polar order of
/// polarity angles, and the nematic order of doubled axis angles.
pub(crate) fn mean_direction_length(angles: impl ExactSizeIterator<Item = f64>) -> f64 {
    let n = angles.len() as f64;
    let (c, s) = angles.fold((0.0, 0.0), |(c, s), a| (c + a.cos(), s + a.sin()));
    (c / n).hypot(s / n)
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

    fn needs_shapes(&self) -> bool {
        self.align == Align::Shape
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

    /// Every key of `[polarity]` in effect (the destructuring has no `..`: a field added to
    /// [`Polarity`] does not compile until it is listed here, so that no backend runs a
    /// setting it has never heard of).
    fn settings(&self) -> Vec<(String, String)> {
        let Polarity {
            alpha,
            propulsion,
            rotational_diffusion,
            align,
            align_rate,
            initial_angle,
            contact_inhibition,
            by_population,
        } = self;
        let mut out = vec![
            ("[polarity] alpha".to_string(), alpha.to_string()),
            (
                "[polarity] propulsion".into(),
                match propulsion {
                    Propulsion::Cell => "cell",
                    Propulsion::Density => "density",
                }
                .into(),
            ),
            (
                "[polarity] rotational_diffusion".into(),
                rotational_diffusion.to_string(),
            ),
            ("[polarity] align".into(), align.key().into()),
            ("[polarity] align_rate".into(), align_rate.to_string()),
        ];
        if let Some(theta) = initial_angle {
            out.push(("[polarity] angle".into(), theta.to_string()));
        }
        if *contact_inhibition != 0.0 {
            out.push((
                "[polarity] contact_inhibition".into(),
                contact_inhibition.to_string(),
            ));
        }
        for (k, [a, d, j]) in by_population.iter().enumerate() {
            for (key, v) in [("alpha", a), ("rotational_diffusion", d), ("align_rate", j)] {
                if let Some(v) = v {
                    out.push((
                        format!("[[population]] {key}"),
                        format!("{v} (population {k})"),
                    ));
                }
            }
        }
        out
    }

    /// `polar_order`: `|⟨p_i⟩|`, the length of the mean unit polarity (1 when all point the
    /// same way, about `1/√N` for random angles; NaN for no cell).
    fn observables(&self, x: &[f64], ids: &[usize]) -> Vec<(&'static str, f64)> {
        vec![(
            "polar_order",
            mean_direction_length(ids.iter().map(|&id| x[id])),
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
        let magnitude = match self.propulsion {
            Propulsion::Cell => alpha,
            Propulsion::Density => alpha * cell.state.area,
        };
        let f = cell.state.force;
        propulsion(magnitude, self.contact_inhibition, [f.x, f.y], x[0])
    }

    fn rate(&self, cell: &CellContext<'_>, x: &[f64], out: &mut [f64]) {
        out[0] = 0.0;
        let [.., rate] = self.values(cell.population);
        if !cell.active || self.align == Align::None || rate == 0.0 {
            return;
        }
        out[0] = alignment_rate(rate, self.target(cell, x[0]), x[0]);
    }

    fn stiffness(&self, cell: &CellContext<'_>, x: &[f64]) -> f64 {
        let [.., rate] = self.values(cell.population);
        if !cell.active || self.align == Align::None || rate == 0.0 {
            return 0.0;
        }
        // dθ/dt = −J|f| Δ(f, p): near alignment a relaxation at the rate J|f|.
        let [tx, ty] = self.target(cell, x[0]);
        rate * tx.hypot(ty)
    }

    fn noise(&self, cell: &CellContext<'_>, out: &mut [f64]) {
        out[0] = if cell.active {
            (2.0 * self.values(cell.population)[1]).sqrt()
        } else {
            0.0
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The polar order is 1 for cells that all point one way, 0 for two opposite pairs, and
    /// reads only the cells it is given (the third cell, pointing elsewhere, is left out).
    #[test]
    fn the_polar_order_is_the_length_of_the_mean_polarity() {
        let p = Polarity::new(0.01);
        let x = [0.3, 0.3, 2.0, 0.3];
        let order = |x: &[f64], ids: &[usize]| p.observables(x, ids)[0];
        assert_eq!(order(&x, &[0, 1, 3]).0, "polar_order");
        assert!((order(&x, &[0, 1, 3]).1 - 1.0).abs() < 1e-15);
        assert!(order(&x, &[0, 1, 2]).1 < 0.9);
        let pi = std::f64::consts::PI;
        let opposite = [0.0, pi, 0.5 * pi, -0.5 * pi];
        assert!(order(&opposite, &[0, 1, 2, 3]).1 < 1e-15);
    }
}
