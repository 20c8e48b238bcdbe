//! A nematic inside each cell (docs/model.md §11.6): each cell carries an angle `θ_i`, its
//! nematic tensor `q_i = S (cos 2θ_i, sin 2θ_i)` (the `[xx, xy]` components of a traceless
//! symmetric tensor), which adds the active stress `−ζ_Q Σ_j φ_j q_j` to the tissue's, beside
//! the shape activity `−ζ Σ_j φ_j S_j`, so that the interface force gains
//! `Σ_x ζ_Q (Σ_j φ_j q_j) · ∇φ_i` by the same formula. `θ_i` turns as
//!
//! ```text
//! dθ_i = [ K ⟨q_i × M⟩_i − J |t_i| δ(θ_i, ψ_i) + W ω_i ] dt + √(2 D_r) dW_i
//! ```
//!
//! - `M = Σ_j φ_j q_j`, `q × M = q_xx M_xy − q_xy M_xx = S |M| sin 2(ψ_M − θ)`: an elastic
//!   torque that turns the cell's nematic towards its neighbours' (its own `q_i` drops out);
//!   `⟨f⟩_i = Σ_x φ_i f / Σ_x φ_i` is the mean over the cell;
//! - `t_i` the alignment target (velocity, interface force or long axis, as for the polarity),
//!   `ψ_i` its angle and `δ(θ, ψ) = ½ wrap(2(θ − ψ))` the nematic angle from `ψ` to `θ`, in
//!   `(−π/2, π/2]`: a relaxation to the target's axis at the rate `J |t_i|`;
//! - `ω_i = ⟨½ ∇ × u⟩_i` the mean rotation rate of the flow over the cell, with the flow
//!   `u = Σ_j φ_j v_j / max(Σ_j φ_j, ½)` (uniform inside a translating tissue, so a
//!   translation turns nothing); `W = 1` corotates the nematic with the flow;
//! - `D_r` the rotational diffusion constant.
//!
//! While the activity is off (the relaxation of docs/model.md §6) the nematic neither acts nor
//! turns: the angles a scene sets are those the activity starts from.
//!
//! ζ_Q > 0 is extensile (a cell whose `q` is along x pushes its neighbours along x outward),
//! as ζ > 0 is for the shape activity. How each constant maps to the reference code's is in
//! docs/model.md §11.6; it differs from it in three places (listed there): the force is
//! recomputed at every evaluation, the vorticity term is a rate, and one sign convention holds
//! throughout.

use super::{CellContext, CellTerm, NoiseKey};
use crate::terms::Align;

/// A nematic in each cell, with its activity and its dynamics (docs/model.md §11.6): the
/// stress `−ζ_Q Σ_j φ_j q_j` of `q_i = S (cos 2θ_i, sin 2θ_i)`, and
/// `dθ_i = [K ⟨q_i × M⟩_i − J |t_i| δ(θ_i, ψ_i) + W ω_i] dt + √(2 D_r) dW_i`.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct CellNematic {
    /// The activity `ζ_Q` of the nematic (> 0 extensile).
    pub zeta: f64,
    /// The magnitude `S` of each cell's nematic.
    pub order: f64,
    /// The alignment target.
    pub align: Align,
    /// The alignment rate `J` per unit of the target's magnitude.
    pub align_rate: f64,
    /// The elastic constant `K` (a rate per unit of `q × M`).
    pub elastic: f64,
    /// The coupling `W` to the flow's rotation rate (1: corotation).
    pub vorticity: f64,
    /// The rotational diffusion constant `D_r`.
    pub rotational_diffusion: f64,
    /// Every cell's initial angle; `None`: uniform in `(−π/2, π/2]`, drawn from the seed.
    pub initial_angle: Option<f64>,
    /// Per population (`crate::terms::Populations`), its own `[ζ_Q, J, K, D_r]` where given.
    pub by_population: Vec<[Option<f64>; 4]>,
}

impl CellNematic {
    /// Activity `zeta`, `S = 1`, no dynamics, random initial angles.
    pub fn new(zeta: f64) -> Self {
        Self {
            zeta,
            order: 1.0,
            align: Align::None,
            align_rate: 0.0,
            elastic: 0.0,
            vorticity: 0.0,
            rotational_diffusion: 0.0,
            initial_angle: None,
            by_population: Vec::new(),
        }
    }

    /// With the magnitude `order` (`S`).
    pub fn with_order(mut self, order: f64) -> Self {
        self.order = order;
        self
    }

    /// Aligning to `align` at rate `rate`.
    pub fn with_alignment(mut self, align: Align, rate: f64) -> Self {
        self.align = align;
        self.align_rate = rate;
        self
    }

    /// With the elastic constant `k`.
    pub fn with_elastic(mut self, k: f64) -> Self {
        self.elastic = k;
        self
    }

    /// With the coupling `w` to the flow's rotation.
    pub fn with_vorticity(mut self, w: f64) -> Self {
        self.vorticity = w;
        self
    }

    /// With rotational diffusion `d_r`.
    pub fn with_rotational_diffusion(mut self, d_r: f64) -> Self {
        self.rotational_diffusion = d_r;
        self
    }

    /// With every cell starting at angle `theta`.
    pub fn with_initial_angle(mut self, theta: f64) -> Self {
        self.initial_angle = Some(theta);
        self
    }

    /// With population `k`'s own `[ζ_Q, J, K, D_r]`, where given.
    pub fn with_population(mut self, k: usize, values: [Option<f64>; 4]) -> Self {
        if self.by_population.len() <= k {
            self.by_population.resize(k + 1, [None; 4]);
        }
        self.by_population[k] = values;
        self
    }

    /// `[ζ_Q, J, K, D_r]` of a cell of population `k`.
    pub fn values(&self, k: usize) -> [f64; 4] {
        let own = self.by_population.get(k).copied().unwrap_or([None; 4]);
        let base = [
            self.zeta,
            self.align_rate,
            self.elastic,
            self.rotational_diffusion,
        ];
        std::array::from_fn(|i| own[i].unwrap_or(base[i]))
    }

    /// The `ζ_Q` of a cell of population `k`.
    pub fn zeta_of(&self, k: usize) -> f64 {
        self.values(k)[0]
    }

    /// Whether any cell's nematic is active (a `ζ_Q` not zero).
    pub fn is_active(&self) -> bool {
        self.zeta != 0.0
            || self
                .by_population
                .iter()
                .any(|v| v[0].is_some_and(|z| z != 0.0))
    }

    /// Whether the dynamics read the lattice's nematic and flow fields (`K` or `W` not zero):
    /// only then does an evaluation measure them (`crate::nematic_fields`).
    pub fn reads_fields(&self) -> bool {
        self.elastic != 0.0
            || self.vorticity != 0.0
            || self
                .by_population
                .iter()
                .any(|v| v[2].is_some_and(|k| k != 0.0))
    }

    /// The nematic tensor `q = S (cos 2θ, sin 2θ)` of angle `theta`.
    pub fn tensor(&self, theta: f64) -> [f64; 2] {
        nematic_tensor(self.order, theta)
    }
}

/// The nematic tensor `S (cos 2θ, sin 2θ)` (`[xx, xy]`).
pub fn nematic_tensor(order: f64, theta: f64) -> [f64; 2] {
    let (s, c) = (2.0 * theta).sin_cos();
    [order * c, order * s]
}

/// `δ(θ, ψ) = ½ wrap(2(θ − ψ))`: the nematic angle from the axis `ψ` to the axis `θ`, in
/// `(−π/2, π/2]` (axes differ by a multiple of π when it is zero).
pub fn nematic_angle(theta: f64, psi: f64) -> f64 {
    let d = 2.0 * (theta - psi);
    0.5 * d.sin().atan2(d.cos())
}

/// The elastic rate `K (q × m)` of a nematic `q = S(cos 2θ, sin 2θ)` in the mean field `m`
/// (`q × m = q_xx m_xy − q_xy m_xx`), which turns `θ` towards `m`'s axis.
pub fn elastic_rate(elastic: f64, order: f64, theta: f64, m: [f64; 2]) -> f64 {
    let q = nematic_tensor(order, theta);
    elastic * (q[0] * m[1] - q[1] * m[0])
}

/// The alignment rate `−J |t| δ(θ, ψ)` towards the axis of the target `t` (`ψ = atan2(t)`),
/// zero for a zero target.
pub fn nematic_alignment_rate(rate: f64, t: [f64; 2], theta: f64) -> f64 {
    let norm = t[0].hypot(t[1]);
    if norm > 0.0 {
        -rate * norm * nematic_angle(theta, t[1].atan2(t[0]))
    } else {
        0.0
    }
}

impl CellNematic {
    /// The alignment target of a cell ([`crate::terms::alignment_target`]: its sign does not
    /// matter to an axis).
    fn target(&self, cell: &CellContext<'_>, theta: f64) -> [f64; 2] {
        self.align.target_of(cell, theta)
    }

    /// The deterministic rate of `θ` of a cell (the module's equation without the noise).
    pub fn rate_of(&self, cell: &CellContext<'_>, theta: f64) -> f64 {
        if !cell.active {
            return 0.0;
        }
        let s = cell.state;
        let [_, j, k, _] = self.values(cell.population);
        let mut r =
            elastic_rate(k, self.order, theta, s.nematic_field) + self.vorticity * s.vorticity;
        if self.align != Align::None && j != 0.0 {
            r += nematic_alignment_rate(j, self.target(cell, theta), theta);
        }
        r
    }
}

impl CellTerm for CellNematic {
    fn name(&self) -> &str {
        "nematic"
    }

    fn state_names(&self) -> &[&'static str] {
        &["theta"]
    }

    /// Its force is a stress, which the interface force carries: no whole-cell force.
    fn has_force(&self) -> bool {
        false
    }

    fn needs_shapes(&self) -> bool {
        self.align == Align::Shape
    }

    fn describe_state(&self, _variable: &str) -> String {
        "each cell's nematic angle, radians counterclockwise from +x (an axis: θ and θ + π are the same)".into()
    }

    fn derived(&self, x: &[f64]) -> Vec<(&'static str, &'static str, Vec<f64>)> {
        vec![(
            "nematic",
            "each cell's nematic tensor S (cos 2 theta, sin 2 theta), components xx and xy",
            self.tensor(x[0]).to_vec(),
        )]
    }

    /// Every key of `[nematic]` in effect (the destructuring has no `..`, as for the
    /// polarity's).
    fn settings(&self) -> Vec<(String, String)> {
        let CellNematic {
            zeta,
            order,
            align,
            align_rate,
            elastic,
            vorticity,
            rotational_diffusion,
            initial_angle,
            by_population,
        } = self;
        let mut out = vec![
            ("[nematic] zeta".to_string(), zeta.to_string()),
            ("[nematic] order".into(), order.to_string()),
            ("[nematic] align".into(), align.key().into()),
            ("[nematic] align_rate".into(), align_rate.to_string()),
            ("[nematic] elastic".into(), elastic.to_string()),
            ("[nematic] vorticity".into(), vorticity.to_string()),
            (
                "[nematic] rotational_diffusion".into(),
                rotational_diffusion.to_string(),
            ),
        ];
        if let Some(theta) = initial_angle {
            out.push(("[nematic] angle".into(), theta.to_string()));
        }
        for (k, values) in by_population.iter().enumerate() {
            let keys = [
                "nematic_zeta",
                "nematic_align_rate",
                "nematic_elastic",
                "nematic_rotational_diffusion",
            ];
            for (key, v) in keys.iter().zip(values) {
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

    /// `cell_nematic_order`: `|⟨(cos 2θ_i, sin 2θ_i)⟩|`, 1 when every cell's axis is the same,
    /// about `1/√N` for random axes (NaN for no cell).
    fn observables(&self, x: &[f64], ids: &[usize]) -> Vec<(&'static str, f64)> {
        let doubled = ids.iter().map(|&id| 2.0 * x[id]);
        vec![(
            "cell_nematic_order",
            super::polarity::mean_direction_length(doubled),
        )]
    }

    fn initial_state(&self, _id: usize, keys: &dyn Fn(u64) -> NoiseKey, out: &mut [f64]) {
        out[0] = match self.initial_angle {
            Some(theta) => theta,
            None => 0.5 * std::f64::consts::PI * (2.0 * keys(0).uniform() - 1.0),
        };
    }

    fn rate(&self, cell: &CellContext<'_>, x: &[f64], out: &mut [f64]) {
        out[0] = self.rate_of(cell, x[0]);
    }

    /// Near its fixed point `θ` relaxes at `2 K S |m| + J |t|` (the elastic torque is
    /// `K S |m| sin 2(ψ − θ)`).
    fn stiffness(&self, cell: &CellContext<'_>, x: &[f64]) -> f64 {
        if !cell.active {
            return 0.0;
        }
        let m = cell.state.nematic_field;
        let [_, j, elastic, _] = self.values(cell.population);
        let mut k = 2.0 * (elastic * self.order).abs() * m[0].hypot(m[1]);
        if self.align != Align::None {
            let [tx, ty] = self.target(cell, x[0]);
            k += j.abs() * tx.hypot(ty);
        }
        k
    }

    fn noise(&self, cell: &CellContext<'_>, out: &mut [f64]) {
        out[0] = if cell.active {
            (2.0 * self.values(cell.population)[3]).sqrt()
        } else {
            0.0
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nematic angle is the signed angle between axes: 0 for axes π apart, ±π/2 at most,
    /// and odd.
    #[test]
    fn the_nematic_angle_is_between_axes() {
        use std::f64::consts::PI;
        assert!(nematic_angle(0.3 + PI, 0.3).abs() < 1e-15);
        assert!((nematic_angle(0.5, 0.2) - 0.3).abs() < 1e-15);
        assert!((nematic_angle(0.2, 0.5) + 0.3).abs() < 1e-15);
        // 0.2 + π − 0.1 is 0.1 away from the axis 0.2 + π, on the other side.
        assert!((nematic_angle(0.2, 0.3 + PI) + 0.1).abs() < 1e-14);
        for k in 0..50 {
            let (t, p) = (0.37 * k as f64, -1.3 * k as f64);
            let d = nematic_angle(t, p);
            assert!(d > -PI / 2.0 - 1e-15 && d <= PI / 2.0 + 1e-15);
            assert!((d + nematic_angle(p, t)).abs() < 1e-12 || (d.abs() - PI / 2.0).abs() < 1e-12);
        }
    }

    /// The elastic rate is `K S |m| sin 2(ψ − θ)` (its closed form), and its derivative in θ
    /// at the fixed point is `−2 K S |m|` (the stiffness), against a central difference.
    #[test]
    fn the_elastic_torque_is_its_closed_form() {
        let (k, s) = (0.7, 0.8);
        let (mag, psi) = (0.3, 0.4);
        let m = nematic_tensor(mag, psi);
        for theta in [-1.0, -0.2, 0.1, 0.4, 1.3, 2.9] {
            let closed = k * s * mag * (2.0 * (psi - theta)).sin();
            assert!((elastic_rate(k, s, theta, m) - closed).abs() < 1e-15);
        }
        let h = 1e-5;
        let d = (elastic_rate(k, s, psi + h, m) - elastic_rate(k, s, psi - h, m)) / (2.0 * h);
        assert!((d + 2.0 * k * s * mag).abs() < 1e-9, "{d}");
    }

    /// The alignment rate is `−J |t| δ(θ, ψ)`: it points θ to the nearer end of the target's
    /// axis (a target and its opposite give the same rate).
    #[test]
    fn the_alignment_turns_to_the_nearer_end_of_the_axis() {
        let t = [0.0, 2.0];
        let r = nematic_alignment_rate(0.5, t, 1.2);
        assert!((r - (-0.5 * 2.0 * (1.2 - std::f64::consts::FRAC_PI_2))).abs() < 1e-14);
        assert!((r - nematic_alignment_rate(0.5, [0.0, -2.0], 1.2)).abs() < 1e-14);
        assert_eq!(nematic_alignment_rate(0.5, [0.0, 0.0], 1.2), 0.0);
    }
}
