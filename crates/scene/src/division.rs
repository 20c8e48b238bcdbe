//! `[division]` into a cell-cycle clock (`mechanics::division::Proliferation`), checked key
//! by key.

use mechanics::division::{Proliferation, SplitAxis};
use mechanics::Tissue;
use phasefield::Real;

use crate::error::{invalid, sig3, SceneError};
use crate::file::{DivisionAxis, DivisionSpec, InitKind, SceneFile};

/// The most cells `[division] max_cells` may allow without being asked: twice as many as fill
/// the lattice at the target area, `2 lx ly / (πR²)`.
pub(crate) fn default_max_cells(file: &SceneFile) -> usize {
    let r = file.cells.radius;
    let area = (file.domain.lx * file.domain.ly) as f64;
    (2.0 * area / (std::f64::consts::PI * r * r)).ceil() as usize
}

impl DivisionSpec {
    /// The fixed part `T₀ = cycle_time − cycle_spread` and the rate `k = 1/cycle_spread` of
    /// the cycle `T₀ + Exp(1/k)`.
    pub fn cycle(&self) -> (f64, f64) {
        let spread = self.spread();
        (self.cycle_time - spread, 1.0 / spread)
    }

    /// `cycle_spread`, or its default, a quarter of `cycle_time`.
    pub fn spread(&self) -> f64 {
        self.cycle_spread.unwrap_or(0.25 * self.cycle_time)
    }
}

/// Checks `[division]` against the rest of the scene.
///
/// # Errors
/// [`SceneError::Invalid`] naming the first bad key.
pub(crate) fn check(spec: &DivisionSpec, file: &SceneFile) -> Result<(), SceneError> {
    let s = "division";
    if !(spec.cycle_time.is_finite() && spec.cycle_time > 0.0) {
        return Err(invalid(
            s,
            "cycle_time",
            spec.cycle_time,
            "the mean cell-cycle time must be positive",
            "give it in model time units (e.g. 300, a few hundred steps of dt 0.5 per cell size moved)",
        ));
    }
    let spread = spec.spread();
    if !(spread.is_finite() && spread > 0.0 && spread <= spec.cycle_time) {
        return Err(invalid(
            s,
            "cycle_spread",
            spread,
            format!(
                "the mean of the cycle's exponential part must be positive and at most cycle_time = {}",
                spec.cycle_time
            ),
            format!(
                "use e.g. {} (a quarter of cycle_time; cycle_spread = cycle_time is a memoryless clock)",
                sig3(spec.cycle_time / 4.0)
            ),
        ));
    }
    let n = file.cells.count;
    let max = spec.max_cells.unwrap_or_else(|| default_max_cells(file));
    if max < n {
        return Err(invalid(
            s,
            "max_cells",
            max,
            format!("the cap is below the {n} cells the scene starts with"),
            format!("use at least {n}"),
        ));
    }
    if let Some(f) = spec.extrusion {
        if !(f.is_finite() && (0.0..1.0).contains(&f)) {
            return Err(invalid(
                s,
                "extrusion",
                f,
                "the extrusion threshold is a fraction of the target area in [0, 1)",
                "use 0.2 (a cell is extruded when its area falls below a fifth of πR²), or leave it out for no extrusion",
            ));
        }
    }
    if let Some(f) = spec.extrusion.filter(|&f| f > 0.0) {
        // Without a relaxation the clock acts from the first step, on the initial discs.
        let (r0, r) = (file.init_radius(), file.cells.radius);
        if file.run.relax_time == 0.0 && file.cells.init != InitKind::Frame && r0 * r0 < f * r * r {
            return Err(invalid(
                s,
                "extrusion",
                f,
                format!(
                    "the initial discs (init_radius {r0}) have about {} of the target area πR² (R = {r}), below the threshold, and with relax_time = 0 they would all be extruded at the first step",
                    sig3(r0 * r0 / (r * r))
                ),
                format!(
                    "give [run] relax_time > 0 (the clock starts after it; e.g. 100), [cells] init_radius ≥ {}, or a lower extrusion",
                    sig3(r * f.sqrt() * 1.05)
                ),
            ));
        }
    }
    if !(spec.growth_time.is_finite() && spec.growth_time >= 0.0) {
        return Err(invalid(
            s,
            "growth_time",
            spec.growth_time,
            "the growth time must be zero or positive",
            format!(
                "give it in time units (e.g. {}, a third of cycle_time), or 0 for daughters that regrow from half the area",
                sig3(spec.cycle_time / 3.0)
            ),
        ));
    }
    if !(spec.death_rate.is_finite() && spec.death_rate >= 0.0) {
        return Err(invalid(
            s,
            "death_rate",
            spec.death_rate,
            "the death rate must be zero or positive",
            "give it per time unit (e.g. 1e-3), or 0 for none",
        ));
    }
    if let Some(p) = spec.pressure_gate {
        if !p.is_finite() {
            return Err(invalid(
                s,
                "pressure_gate",
                p,
                "the pressure gate must be a finite pressure",
                "use a value of the cells' pressure p_i = Σφ_i P/Σφ_i (about 0.001–0.01 at confluence), or leave it out",
            ));
        }
    }
    if let Some(p) = spec.extrusion_pressure {
        if !(p.is_finite() && p > 0.0) {
            return Err(invalid(
                s,
                "extrusion_pressure",
                p,
                "the extrusion pressure must be a positive, finite pressure: at zero or below it every cell of a confluent tissue, whose pressures are positive, is extruded at once",
                "use a value above the cells' pressures p_i = Σφ_i P/Σφ_i at rest (0.005–0.013 in the paper's relaxed tissue), or leave it out",
            ));
        }
    }
    Ok(())
}

/// The clock of `[division]` for the founders of `tissue`, with the noise of `seed`.
pub(crate) fn clock<T: Real>(
    spec: &DivisionSpec,
    file: &SceneFile,
    tissue: &Tissue<T>,
) -> Proliferation {
    let (t0, rate) = spec.cycle();
    // The clocks start when the relaxation ends, when the tissue starts to proliferate.
    let start = tissue.time().max(file.run.relax_time);
    configure(
        Proliferation::starting_at(t0, rate, file.run.seed, tissue, start),
        spec,
        file,
    )
}

/// `clock` with the options of `[division]` besides the cycle.
pub(crate) fn configure(
    clock: Proliferation,
    spec: &DivisionSpec,
    file: &SceneFile,
) -> Proliferation {
    let mut clock = clock
        .with_axis(match spec.axis {
            DivisionAxis::Long => SplitAxis::Long,
            DivisionAxis::Random => SplitAxis::Random,
        })
        .with_max_cells(spec.max_cells.unwrap_or_else(|| default_max_cells(file)))
        .with_death_rate(spec.death_rate)
        .with_growth_time(spec.growth_time);
    if let Some(f) = spec.extrusion.filter(|&f| f > 0.0) {
        clock = clock.with_extrusion(f);
    }
    if let Some(p) = spec.pressure_gate {
        clock = clock.with_pressure_gate(p);
    }
    if let Some(p) = spec.extrusion_pressure {
        clock = clock.with_extrusion_pressure(p);
    }
    clock
}

#[cfg(test)]
mod tests {
    use crate::{Scene, SceneError};

    const BASE: &str = "[domain]\nlx = 40\nly = 30\n[cells]\ncount = 2\nradius = 6.0\n[integrator]\nmargin = 12\n[run]\ntime = 1\n[division]\ncycle_time = 100.0\n";

    fn parse(set: &[&str]) -> Result<Scene, SceneError> {
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        Scene::parse(BASE, &set)
    }

    /// Defaults: the spread a quarter of the cycle, the cap twice the cells that fill the
    /// lattice (40·30·2/(36π) = 21.2 → 22), which the memory estimate is sized for; the
    /// resolved scene writes the spread out, and parses back to the same scene.
    #[test]
    fn defaults_and_the_memory_cap() {
        let s = parse(&[]).unwrap();
        let d = s.file().division.clone().unwrap();
        assert_eq!(d.cycle_spread, Some(25.0));
        assert_eq!(d.cycle(), (75.0, 0.04));
        assert_eq!(s.max_cells(), 22);
        let fixed = Scene::parse(
            BASE.replace("[division]\ncycle_time = 100.0\n", "")
                .as_str(),
            &[],
        )
        .unwrap();
        assert_eq!(fixed.max_cells(), 2);
        let per_cell = (s.memory_estimate() - fixed.memory_estimate()) / 20.0;
        let p = (25 * 25) as f64;
        assert!(per_cell >= p * (4.0 * 4.0 + 16.0), "{per_cell}");
        let again = Scene::parse(&s.to_toml(), &[]).unwrap();
        assert_eq!(again.to_toml(), s.to_toml());
        let big = parse(&["division.max_cells=1000"]).unwrap();
        let grown = (big.memory_estimate() - s.memory_estimate()) / 978.0;
        assert!((grown / per_cell - 1.0).abs() < 1e-9, "{grown} {per_cell}");
    }

    /// Each bad `[division]` value names its key and a fix.
    #[test]
    fn bad_division_values_name_their_key() {
        let cases: &[(&[&str], &[&str])] = &[
            (
                &["division.cycle_time=0"],
                &["[division] cycle_time", "positive"],
            ),
            (
                &["division.cycle_spread=150"],
                &["[division] cycle_spread", "at most cycle_time = 100"],
            ),
            (&["division.cycle_spread=-1"], &["[division] cycle_spread"]),
            (
                &["division.max_cells=1"],
                &["[division] max_cells", "at least 2"],
            ),
            (
                &["division.extrusion=1.5"],
                &["[division] extrusion", "[0, 1)"],
            ),
            (&["division.death_rate=-0.1"], &["[division] death_rate"]),
            (
                &["division.growth_time=-5"],
                &["[division] growth_time", "e.g. 33.3"],
            ),
            (
                &["division.pressure_gate=nan"],
                &["[division] pressure_gate"],
            ),
            (
                &["division.extrusion_pressure=inf"],
                &["[division] extrusion_pressure"],
            ),
            (&["division.axis=\"short\""], &["axis", "long"]),
            (&["division.cycle=3"], &["cycle"]),
        ];
        for (set, want) in cases {
            crate::check_rejected(BASE, set, want);
        }
    }
}
