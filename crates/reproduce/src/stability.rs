//! `reproduce stability`: the activity threshold as a linear-stability threshold of an ordered
//! rest state (the `stability` crate), against γ, the box size and the pressure form, by two
//! independent methods.
//!
//! The random packings of the threshold figure keep coarsening at ζ = 0, so the growth rate of
//! their v_rms is never a clean baseline, and their ζ_cr falls with the run length. Here the
//! rest state is a hexagonal packing on a box commensurate with it, relaxed at ζ = 0 until its
//! fields stop changing; ζ_cr is where the leading growth rate σ of small perturbations about
//! it crosses zero. σ is measured by Arnoldi on the step map's Jacobian and by perturbation
//! growth (simultaneous power iteration in time); the two must agree.

use std::collections::BTreeMap;
use std::path::Path;

use mechanics::{ModelParams, PressureKind, StepParams, Tissue};
use render::{CellAxes, Fill, LatticeVectors, Patches, Plot, Series, TissuePicture};
use stability::{
    rest_state, threshold, ArnoldiOptions, GrowthOptions, HexBox, Method, Relaxation, RestState,
    StabilityError, StepMap, Threshold, ThresholdOptions,
};

use super::pipeline::{cell, keep, kept, sci, Csv, Made, Picture};
use super::rules::{rule_agree, rule_box, rule_continuum, rule_linear, rule_proportional};
use super::{g, Claim, ReproduceParams, Scale, Verdict};
use study::SweepError;

/// The γ of the study: five values, so that a line and its curvature can be told apart.
const GAMMAS: [f64; 5] = [0.006, 0.008, 0.01, 0.012, 0.014];

/// The paper's density: 60 cells on 100 × 100 nodes.
const AREA_PER_CELL: f64 = 100.0 * 100.0 / 60.0;

/// The time step of the maps: the fixed points of Heun are those of the equations whatever
/// the step, and the slow modes that decide σ are integrated far inside Heun's accuracy (the
/// convergence table compares dt 0.2).
const DT: f64 = 0.5;

/// Steps per application of the map: τ = 50 TU, which damps the fast modes (σ ≲ −0.05) by
/// e⁻² or more per application, so that Krylov and power iteration see the slow band.
const STEPS: usize = 100;

/// Half the final bisection bracket, by method.
pub(super) const TOL_ARNOLDI: f64 = 2e-5;
const TOL_GROWTH: f64 = 5e-5;

/// The bracket: σ < 0 at ζ = 0 (a relaxed state is stable) and σ > 0 at ζ = 0.008 (the top of
/// the threshold figure's ζ grid).
const ZETA_HI: f64 = 0.008;

fn pressure_name(p: PressureKind) -> &'static str {
    match p {
        PressureKind::Paper => "paper",
        _ => "interaction",
    }
}

/// One configuration: a packing, a γ and a pressure form.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Config {
    hex: HexBox,
    gamma: f64,
    pressure: PressureKind,
}

impl Config {
    fn params(&self) -> ModelParams {
        let mut p = ModelParams::paper(0.0).with_pressure(self.pressure);
        p.energy.gamma = self.gamma;
        p
    }

    fn name(&self) -> String {
        format!(
            "γ = {}, {} × {} ({} cells), {} form",
            self.gamma,
            self.hex.lx,
            self.hex.ly,
            self.hex.n_cells(),
            pressure_name(self.pressure)
        )
    }
}

/// What a scale computes.
struct Plan {
    /// Configurations whose ζ_cr Arnoldi finds.
    arnoldi: Vec<Config>,
    /// Configurations whose ζ_cr perturbation growth finds.
    growth: Vec<Config>,
    arnoldi_opts: ArnoldiOptions,
    growth_opts: GrowthOptions,
}

/// The solvers' settings, the same at both scales (the scales differ in what they measure).
pub(super) const ARNOLDI: ArnoldiOptions = ArnoldiOptions {
    krylov: 30,
    eps: 1e-5,
    seed: 1,
};
const GROWTH: GrowthOptions = GrowthOptions {
    amplitude: 1e-4,
    intervals: 24,
    vectors: 4,
    seed: 2,
};

fn hex(cols: usize, rows: usize) -> HexBox {
    HexBox::new(cols, rows, AREA_PER_CELL).expect("even rows")
}

fn plan(scale: Scale) -> Plan {
    let forms = [PressureKind::Paper, PressureKind::Interaction];
    let configs = |boxes: &[HexBox], gammas: &[f64]| -> Vec<Config> {
        let mut v = Vec::new();
        for &pressure in &forms {
            for &hex in boxes {
                for &gamma in gammas {
                    v.push(Config {
                        hex,
                        gamma,
                        pressure,
                    });
                }
            }
        }
        v
    };
    // Exact tilings of the smallest box, so that every size has its spacings, anisotropy and
    // alignment to the grid (issue 41: 24 × 40 cells on 333 × 481 was 0.5 % less dense).
    let small = hex(6, 10);
    let (mid, k3, large) = (small.tiled(2), small.tiled(3), small.tiled(4));
    match scale {
        Scale::Quick => {
            let mut arnoldi = configs(&[small], &GAMMAS);
            arnoldi.extend(configs(&[mid], &[0.01]));
            Plan {
                arnoldi,
                growth: configs(&[small], &[0.01]),
                arnoldi_opts: ARNOLDI,
                growth_opts: GROWTH,
            }
        }
        Scale::Paper => {
            // The larger boxes (540 and 960 cells) cost 9× and 16× the smallest per
            // evaluation: one γ there, for the four sizes of the limit L → ∞.
            let mut arnoldi = configs(&[small, mid], &GAMMAS);
            arnoldi.extend(configs(&[k3, large], &[0.01]));
            Plan {
                arnoldi,
                growth: configs(&[small], &GAMMAS),
                arnoldi_opts: ARNOLDI,
                growth_opts: GROWTH,
            }
        }
    }
}

pub(super) fn threshold_opts(tol: f64) -> ThresholdOptions {
    ThresholdOptions {
        step: StepParams::new(DT, 1),
        steps: STEPS,
        lo: 0.0,
        hi: ZETA_HI,
        tol,
        narrow: 1e-4,
    }
}

fn failed(config: &Config, e: StabilityError) -> SweepError {
    SweepError::Reproduce {
        why: format!("stability, {}: {e}", config.name()),
    }
}

/// A configuration's result as kept on disk: its threshold, or why σ did not cross zero.
#[derive(serde::Serialize, serde::Deserialize)]
struct Outcome {
    threshold: Option<Threshold>,
    no_crossing: Option<String>,
}

/// One measured threshold.
struct Row {
    config: Config,
    method: &'static str,
    /// `None` when σ did not cross zero in the bracket (with why).
    result: Result<Threshold, String>,
}

impl Row {
    fn zeta(&self) -> Option<(f64, f64)> {
        self.result.as_ref().ok().map(|t| (t.zeta_cr, t.err))
    }
}

pub(super) fn make(p: &ReproduceParams, dir: &Path) -> Result<Made, SweepError> {
    let plan = plan(p.scale);
    let mut rests: BTreeMap<String, RestState> = BTreeMap::new();
    let relax = Relaxation::default();
    let key = |c: &Config| {
        format!(
            "{}x{} {} {}",
            c.hex.cols,
            c.hex.rows,
            c.gamma,
            pressure_name(c.pressure)
        )
    };
    let mut rows: Vec<Row> = Vec::new();
    let jobs: Vec<(Config, Method, f64)> = plan
        .arnoldi
        .iter()
        .map(|c| (*c, Method::Arnoldi(plan.arnoldi_opts), TOL_ARNOLDI))
        .chain(
            plan.growth
                .iter()
                .map(|c| (*c, Method::Growth(plan.growth_opts), TOL_GROWTH)),
        )
        .collect();
    let done = dir.join("configurations");
    std::fs::create_dir_all(&done).map_err(|e| SweepError::write("stability", &done, e))?;
    for (k, (config, method, tol)) in jobs.iter().enumerate() {
        p.reporter.stage(&format!(
            "stability {}/{}: ζ_cr by {} for {}",
            k + 1,
            jobs.len(),
            method.name(),
            config.name()
        ));
        if let std::collections::btree_map::Entry::Vacant(slot) = rests.entry(key(config)) {
            slot.insert(
                rest_state(&config.hex, &config.params(), &relax).map_err(|e| failed(config, e))?,
            );
        }
        let rest = &rests[&key(config)];
        let opts = threshold_opts(*tol);
        // Each configuration's result is kept as it finishes, so that a stopped figure goes
        // on from the next one.
        let file = done.join(format!(
            "{}-g{}-{}x{}-{}.toml",
            method.name(),
            config.gamma,
            config.hex.lx,
            config.hex.ly,
            pressure_name(config.pressure)
        ));
        let fingerprint = format!("{config:?} {method:?} {opts:?} {relax:?}");
        let outcome: Outcome = match kept(&file, &fingerprint) {
            Some(o) => o,
            None => {
                let o = match threshold(&rest.tissue, &config.params(), method, &opts) {
                    Ok(t) => Outcome {
                        threshold: Some(t),
                        no_crossing: None,
                    },
                    Err(e @ StabilityError::NoCrossing { .. }) => Outcome {
                        threshold: None,
                        no_crossing: Some(e.to_string()),
                    },
                    Err(e) => return Err(failed(config, e)),
                };
                keep(&file, &fingerprint, o)?
            }
        };
        let result = match outcome {
            Outcome {
                threshold: Some(t), ..
            } => Ok(t),
            Outcome { no_crossing, .. } => Err(no_crossing.unwrap_or_default()),
        };
        rows.push(Row {
            config: *config,
            method: method.name(),
            result,
        });
    }
    let mut made = Made::new(Vec::new(), String::new());
    write_tables(&mut made, &rows, &rests, &key);
    p.reporter
        .stage("stability: the uniform translations and the map's drift");
    translations(dir, &mut made, &rows, &rests, &key)?;
    p.reporter
        .stage("stability: convergence in dt, margin, Krylov dimension and ε");
    let (convergence, discretisation) = convergence(dir, &mut made, &rows, &plan, &rests, &key)?;
    p.reporter.stage("stability: pictures");
    draw(&mut made, &rows);
    if let Some(row) = rows
        .iter()
        .find(|r| r.method == "arnoldi" && r.config.gamma == 0.01 && r.config.hex == hex(6, 10))
    {
        if let Ok(t) = &row.result {
            if let Some(sp) = &t.spectrum {
                let mode = draw_mode(&rests[&key(&row.config)].tissue, &sp.mode, t.zeta_cr)?;
                made.add_plot("mode.png", Picture::Raster(mode));
            }
        }
    }
    p.reporter
        .stage("stability: an isolated cell under activity");
    let measured: Vec<Measured> = rows.iter().map(Measured::of).collect();
    let mut claims = claims(&measured);
    claims.extend(discretisation);
    claims.push(isolated_cell()?);
    made.settings = settings(p.scale, &plan, &rests, &convergence);
    made.claims = claims;
    Ok(made)
}

fn write_tables(
    made: &mut Made,
    rows: &[Row],
    rests: &BTreeMap<String, RestState>,
    key: &dyn Fn(&Config) -> String,
) {
    let mut zc = Csv::new(&[
        "gamma",
        "lx",
        "pressure",
        "method",
        "zeta_cr",
        "zeta_cr_err",
    ]);
    let mut gr = Csv::new(&[
        "gamma",
        "lx",
        "pressure",
        "method",
        "zeta",
        "sigma",
        "sigma_err",
    ]);
    let mut sp = Csv::new(&[
        "gamma", "lx", "pressure", "zeta", "rank", "sigma", "omega", "residual",
    ]);
    for r in rows {
        let c = &r.config;
        let config = [
            cell(c.gamma),
            cell(c.hex.lx),
            cell(pressure_name(c.pressure)),
        ];
        let (z, e) = r.zeta().unwrap_or((f64::NAN, f64::NAN));
        zc.row(
            config
                .iter()
                .cloned()
                .chain([cell(r.method), sci(z), sci(e)]),
        );
        if let Ok(t) = &r.result {
            for ev in &t.evaluations {
                gr.row(config.iter().cloned().chain([
                    cell(r.method),
                    sci(ev.zeta),
                    sci(ev.sigma),
                    sci(ev.sigma_err),
                ]));
            }
            if let Some(s) = &t.spectrum {
                let last = t.evaluations.last().map_or(f64::NAN, |e| e.zeta);
                for (rank, ritz) in s.ritz.iter().enumerate().take(10) {
                    sp.row(config.iter().cloned().chain([
                        sci(last),
                        cell(rank),
                        sci(ritz.sigma),
                        sci(ritz.omega),
                        sci(ritz.residual),
                    ]));
                }
            }
        }
    }
    made.add_table("zeta_cr.csv", zc);
    made.add_table("growth_rates.csv", gr);
    made.add_table("spectrum.csv", sp);
    let mut rs = Csv::new(&[
        "cols",
        "rows",
        "lx",
        "ly",
        "cells",
        "anisotropy",
        "gamma",
        "pressure",
        "relax_time",
        "v_max",
        "phi_rate",
        "s_rms",
    ]);
    let mut seen = std::collections::BTreeSet::new();
    for r in rows {
        let k = key(&r.config);
        if !seen.insert(k.clone()) {
            continue;
        }
        let c = &r.config;
        let s = &rests[&k];
        rs.row([
            cell(c.hex.cols),
            cell(c.hex.rows),
            cell(c.hex.lx),
            cell(c.hex.ly),
            cell(c.hex.n_cells()),
            sci(c.hex.anisotropy()),
            cell(c.gamma),
            cell(pressure_name(c.pressure)),
            cell(s.time),
            sci(s.v_max),
            sci(s.phi_rate),
            sci(s.s_rms),
        ]);
    }
    made.add_table("rest_states.csv", rs);
}

/// One line of `translations.csv`: the growth rates of the two uniform translations (which the
/// threshold projects out) and the map's drift, at one ζ.
#[derive(serde::Serialize, serde::Deserialize)]
struct TranslationRow {
    zeta: f64,
    sigma_x: f64,
    sigma_y: f64,
    drift: f64,
}

/// For every configuration Arnoldi measured: the translations' own growth rates
/// ([`StepMap::translation_rates`]) and the map's drift `|M(x₀) − x₀|` at ζ = 0 and at its
/// ζ_cr, into `translations.csv` (each kept in `configurations/` as it finishes).
fn translations(
    dir: &Path,
    made: &mut Made,
    rows: &[Row],
    rests: &BTreeMap<String, RestState>,
    key: &dyn Fn(&Config) -> String,
) -> Result<(), SweepError> {
    let done = dir.join("configurations");
    let mut csv = Csv::new(&[
        "gamma", "lx", "ly", "pressure", "zeta", "sigma_x", "sigma_y", "drift",
    ]);
    for r in rows.iter().filter(|r| r.method == "arnoldi") {
        let c = &r.config;
        let zetas = [0.0, r.zeta().map_or(f64::NAN, |z| z.0)];
        for zeta in zetas.into_iter().filter(|z| z.is_finite()) {
            let fingerprint = format!("{c:?} ζ {zeta:e} dt {DT} steps {STEPS} ε {:e}", ARNOLDI.eps);
            let file = done.join(format!(
                "translations-g{}-{}x{}-{}-z{zeta:e}.toml",
                c.gamma,
                c.hex.lx,
                c.hex.ly,
                pressure_name(c.pressure)
            ));
            let row = match kept(&file, &fingerprint) {
                Some(row) => row,
                None => {
                    let mut map = StepMap::new(
                        &rests[&key(c)].tissue,
                        &c.params().with_zeta(zeta),
                        StepParams::new(DT, 1),
                        STEPS,
                    )
                    .map_err(|e| failed(c, e))?;
                    let [sigma_x, sigma_y] = map
                        .translation_rates(ARNOLDI.eps)
                        .map_err(|e| failed(c, e))?;
                    let row = TranslationRow {
                        zeta,
                        sigma_x,
                        sigma_y,
                        drift: map.drift(),
                    };
                    keep(&file, &fingerprint, row)?
                }
            };
            csv.row([
                cell(c.gamma),
                cell(c.hex.lx),
                cell(c.hex.ly),
                cell(pressure_name(c.pressure)),
                sci(row.zeta),
                sci(row.sigma_x),
                sci(row.sigma_y),
                sci(row.drift),
            ]);
        }
    }
    made.add_table("translations.csv", csv);
    Ok(())
}

/// One line of the convergence table: what changed, σ at the reference ζ, its error.
#[derive(serde::Serialize, serde::Deserialize)]
struct Conv {
    what: String,
    sigma: f64,
    err: f64,
}

/// σ at the Arnoldi ζ_cr of γ = 0.01, 6 × 10, paper form, as each numerical parameter changes;
/// the shift of ζ_cr it implies is −Δσ over the slope dσ/dζ (σ ≈ slope·(ζ − ζ_cr): a σ lower
/// by Δ at the same ζ puts the threshold higher by Δ/slope).
fn convergence(
    dir: &Path,
    made: &mut Made,
    rows: &[Row],
    plan: &Plan,
    rests: &BTreeMap<String, RestState>,
    key: &dyn Fn(&Config) -> String,
) -> Result<(Vec<Conv>, Option<Claim>), SweepError> {
    let reference = rows.iter().find(|r| {
        r.method == "arnoldi"
            && r.config.gamma == 0.01
            && r.config.hex == hex(6, 10)
            && r.config.pressure == PressureKind::Paper
    });
    let Some((config, Ok(t))) = reference.map(|r| (r.config, &r.result)) else {
        return Ok((Vec::new(), None));
    };
    let zeta = t.zeta_cr;
    let base = plan.arnoldi_opts;
    let mut out = Vec::new();
    // The rest state at the study's own margin is already relaxed.
    let mut rest_at = BTreeMap::new();
    rest_at.insert(Relaxation::default().margin, rests[&key(&config)].clone());
    let cases: Vec<(String, f64, usize, usize, ArnoldiOptions)> = vec![
        (
            format!(
                "reference: dt {DT}, margin 16, k {}, ε {:e}",
                base.krylov, base.eps
            ),
            DT,
            16,
            STEPS,
            base,
        ),
        ("dt 0.2 (τ the same)".into(), 0.2, 16, STEPS * 5 / 2, base),
        ("margin 12".into(), DT, 12, STEPS, base),
        ("margin 20".into(), DT, 20, STEPS, base),
        (
            format!("Krylov dimension {}", 2 * base.krylov),
            DT,
            16,
            STEPS,
            ArnoldiOptions {
                krylov: 2 * base.krylov,
                ..base
            },
        ),
        (
            format!("ε {}", g(base.eps / 10.0)),
            DT,
            16,
            STEPS,
            ArnoldiOptions {
                eps: base.eps / 10.0,
                ..base
            },
        ),
        (
            format!("ε {}", g(base.eps * 10.0)),
            DT,
            16,
            STEPS,
            ArnoldiOptions {
                eps: base.eps * 10.0,
                ..base
            },
        ), // Half the time step (issue 54's systematics); last, so that the kept cases above keep
        // their files.
        (
            format!("dt {} (τ the same)", DT / 2.0),
            DT / 2.0,
            16,
            STEPS * 2,
            base,
        ),
    ];
    let done = dir.join("configurations");
    for (k, (what, dt, margin, steps, opts)) in cases.into_iter().enumerate() {
        let fingerprint =
            format!("{config:?} ζ {zeta:e} dt {dt} margin {margin} steps {steps} {opts:?}");
        let file = done.join(format!("convergence-{k}.toml"));
        if let Some(conv) = kept(&file, &fingerprint) {
            out.push(conv);
            continue;
        }
        if let std::collections::btree_map::Entry::Vacant(slot) = rest_at.entry(margin) {
            let relax = Relaxation {
                margin,
                ..Relaxation::default()
            };
            slot.insert(
                rest_state(&config.hex, &config.params(), &relax)
                    .map_err(|e| failed(&config, e))?,
            );
        }
        let rest = &rest_at[&margin];
        let mut map = StepMap::new(
            &rest.tissue,
            &config.params().with_zeta(zeta),
            StepParams::new(dt, 1),
            steps,
        )
        .map_err(|e| failed(&config, e))?;
        let s = stability::arnoldi(&mut map, &opts, None).map_err(|e| failed(&config, e))?;
        let conv = Conv {
            what,
            sigma: s.sigma(),
            err: s.ritz[0].residual,
        };
        out.push(keep(&file, &fingerprint, conv)?);
    }
    // A grid twice as fine (issue 54): every length doubled in nodes (docs/model.md §12's
    // scaling, `systematics::finer_params`), the rest state relaxed again on it.
    let what = "grid twice as fine (R = 16, every length 2× in nodes, margin 32)".to_string();
    let fine_params = super::systematics::finer_params(&config.params());
    let fine_hex = HexBox {
        lx: 2 * config.hex.lx,
        ly: 2 * config.hex.ly,
        ..config.hex
    };
    let fingerprint =
        format!("{fine_hex:?} {fine_params:?} ζ {zeta:e} dt {DT} margin 32 steps {STEPS} {base:?}");
    let file = done.join("convergence-grid.toml");
    let conv = match kept(&file, &fingerprint) {
        Some(c) => c,
        None => {
            let relax = Relaxation {
                margin: 32,
                ..Relaxation::default()
            };
            let rest =
                rest_state(&fine_hex, &fine_params, &relax).map_err(|e| failed(&config, e))?;
            let mut map = StepMap::new(
                &rest.tissue,
                &fine_params.with_zeta(zeta),
                StepParams::new(DT, 1),
                STEPS,
            )
            .map_err(|e| failed(&config, e))?;
            let s = stability::arnoldi(&mut map, &base, None).map_err(|e| failed(&config, e))?;
            keep(
                &file,
                &fingerprint,
                Conv {
                    what,
                    sigma: s.sigma(),
                    err: s.ritz[0].residual,
                },
            )?
        }
    };
    out.push(conv);
    let mut csv = Csv::new(&[
        "case",
        "zeta",
        "sigma",
        "sigma_err",
        "zeta_shift",
        "zeta_shift_err",
        "slope",
    ]);
    let reference = out[0].sigma;
    let ref_err = out[0].err;
    for c in &out {
        csv.row([
            // Without commas: a case is one cell of the table.
            c.what.replace(", ", "; "),
            sci(zeta),
            sci(c.sigma),
            sci(c.err),
            sci((reference - c.sigma) / t.slope),
            sci(c.err.hypot(ref_err) / t.slope.abs()),
            sci(t.slope),
        ]);
    }
    made.add_table("convergence.csv", csv);
    let shifts: Vec<(String, f64, f64)> = out
        .iter()
        .map(|c| {
            (
                c.what.clone(),
                (reference - c.sigma) / t.slope,
                c.err.hypot(ref_err) / t.slope.abs(),
            )
        })
        .collect();
    let claim = claim_discretisation(zeta, t.err, &shifts);
    Ok((out, claim))
}

/// The discretisation claim (issue 54) on the reference configuration's ζ_cr (`zeta` ± `stat`)
/// from the convergence table's shifts `(case, shift, its error)`: the rule of an absence on
/// each relative shift at the smaller time step and on the grid twice as fine, with
/// [`super::systematics::SHIFT`] counting; holds when both hold. `None` without both cases.
fn claim_discretisation(zeta: f64, stat: f64, shifts: &[(String, f64, f64)]) -> Option<Claim> {
    let find = |prefix: &str| shifts.iter().find(|s| s.0.starts_with(prefix));
    let (dt, grid) = (find(&format!("dt {} ", DT / 2.0))?, find("grid ")?);
    let rule = super::rule::Rule::absence("relative shift of ζ_cr", super::systematics::SHIFT);
    let outcomes: Vec<super::rule::Outcome> = [dt, grid]
        .iter()
        .map(|(what, m, e)| {
            let o = rule.decide(m / zeta, e / zeta);
            super::rule::Outcome {
                verdict: o.verdict,
                why: format!("{what}: {}", o.why),
            }
        })
        .collect();
    let (v, why) = super::rules::all_of(&outcomes);
    let sys = super::systematics::Systematics {
        value: zeta,
        stat,
        dt: dt.1,
        grid: grid.1,
    };
    Some(Claim::new(
        "Discretisation (issue 54): ζ_cr of the 83 × 120 box (γ = 0.01, paper form) moves by less than 20 % at half the time step and on a grid twice as fine",
        format!("ζ_cr = {}", sys.describe()),
        v,
        why,
    ))
}

fn draw(made: &mut Made, rows: &[Row]) {
    // ζ_cr against γ, from zero, one series per (box, form, method).
    let mut pg = Plot::new(
        "ζ_cr of the hexagonal rest state against γ",
        "γ",
        "ζ_cr (bars: bracket and σ error)",
    );
    pg.zero_x = true;
    pg.zero_y = true;
    let mut series: BTreeMap<String, Vec<(f64, f64, f64)>> = BTreeMap::new();
    for r in rows {
        if let Some((z, e)) = r.zeta() {
            series
                .entry(format!(
                    "L = {}, {}, {}",
                    r.config.hex.lx,
                    pressure_name(r.config.pressure),
                    r.method
                ))
                .or_default()
                .push((r.config.gamma, z, e));
        }
    }
    let mut pl = Plot::new(
        "ζ_cr of the hexagonal rest state against the box (γ = 0.01)",
        "box side lx",
        "ζ_cr",
    );
    pl.zero_y = true;
    let mut by_l: BTreeMap<String, Vec<(f64, f64, f64)>> = BTreeMap::new();
    for r in rows.iter().filter(|r| r.config.gamma == 0.01) {
        if let Some((z, e)) = r.zeta() {
            by_l.entry(format!(
                "{}, {}",
                pressure_name(r.config.pressure),
                r.method
            ))
            .or_default()
            .push((r.config.hex.lx as f64, z, e));
        }
    }
    // The weighted line of each Arnoldi series, drawn from γ = 0 to show its intercept.
    let mut lines = Vec::new();
    for (label, pts) in series
        .iter()
        .filter(|(l, v)| l.ends_with("arnoldi") && v.len() > 1)
    {
        let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
        let e: Vec<f64> = pts.iter().map(|p| p.2.max(1e-9)).collect();
        if let Some(f) = stability::fit::line(&x, &y, Some(&e)) {
            let xs = [0.0, x.iter().copied().fold(0.0, f64::max)];
            let ys = xs.map(|x| f.coef[0] + f.coef[1] * x);
            lines.push(
                Series::new(format!(
                    "{label}: line, intercept {} ± {}",
                    g(f.coef[0]),
                    g(f.se[0])
                ))
                .with_points(&xs, &ys, &[0.0, 0.0])
                .line_only(),
            );
        }
    }
    pg.series.extend(lines);
    for (plot, map, path) in [
        (&mut pg, &series, "zeta_cr_gamma.png"),
        (&mut pl, &by_l, "zeta_cr_box.png"),
    ] {
        for (label, pts) in map.iter().filter(|(_, v)| v.len() > 1) {
            let (x, y, e): (Vec<f64>, Vec<f64>, Vec<f64>) = (
                pts.iter().map(|p| p.0).collect(),
                pts.iter().map(|p| p.1).collect(),
                pts.iter().map(|p| p.2).collect(),
            );
            plot.series
                .push(Series::new(label.clone()).with_points(&x, &y, &e));
        }
        if !plot.series.is_empty() {
            made.add_plot(path, plot.clone());
        }
    }
    // σ(ζ) of γ = 0.01 on the smallest box, both methods.
    let mut ps = Plot::new(
        "σ(ζ) near the threshold, γ = 0.01, 6 × 10 packing (ζ ≤ 0.003)",
        "ζ",
        "σ (1/TU)",
    );
    ps.hlines.push((0.0, String::new()));
    ps.legend = render::LegendAt::UpperLeft;
    for r in rows
        .iter()
        .filter(|r| r.config.gamma == 0.01 && r.config.hex == hex(6, 10))
    {
        if let Ok(t) = &r.result {
            // The bracket's upper end (ζ = 0.008) is in growth_rates.csv; the plot shows the
            // crossing.
            let mut ev: Vec<_> = t
                .evaluations
                .iter()
                .filter(|e| e.zeta <= 0.003)
                .copied()
                .collect();
            ev.sort_by(|a, b| a.zeta.total_cmp(&b.zeta));
            let x: Vec<f64> = ev.iter().map(|e| e.zeta).collect();
            let y: Vec<f64> = ev.iter().map(|e| e.sigma).collect();
            let err: Vec<f64> = ev.iter().map(|e| e.sigma_err).collect();
            ps.series.push(
                Series::new(format!(
                    "{}, {}",
                    pressure_name(r.config.pressure),
                    r.method
                ))
                .with_points(&x, &y, &err),
            );
        }
    }
    if !ps.series.is_empty() {
        made.add_plot("growth_rates.png", ps);
    }
}

/// The leading mode: each cell filled by the change of its area, its shape change drawn as an
/// axis, and the displacement field `Σ_i φ_i δc_i` as arrows.
fn draw_mode(base: &Tissue<f64>, mode: &[f64], zeta: f64) -> Result<render::Picture, SweepError> {
    let cells = base.cells();
    let shape = cells.shape();
    let lattice = cells.lattice();
    let (nx, ny, n) = (shape.nx, shape.ny, shape.len());
    let phi = cells.phi();
    let mut patches = Patches {
        nx,
        ny,
        origins: Vec::new(),
        phi: vec![0.0; phi.len()],
    };
    let mut d_area = Vec::new();
    let mut d_shape = Vec::new();
    let mut centres = Vec::new();
    let mut disp = [vec![0.0; lattice.len()], vec![0.0; lattice.len()]];
    for i in 0..cells.n_cells() {
        patches.origins.push(cells.map().origin[i]);
        cells.unrolled_into(i, &mut patches.phi[i * n..(i + 1) * n]);
        let p = &phi[i * n..(i + 1) * n];
        let m = &mode[i * n..(i + 1) * n];
        let xs = cells.map().cell_x(shape, i);
        let ys = cells.map().cell_y(shape, i);
        let c = base.centre(i);
        let (mut a, mut da, mut dc) = (0.0, 0.0, [0.0; 2]);
        let (mut ds, mut s0) = ([0.0; 2], [0.0; 2]);
        for u in 0..nx {
            for v in 0..ny {
                let k = u * ny + v;
                let rel = [
                    lattice.delta_x(c[0], xs[u] as f64),
                    lattice.delta_y(c[1], ys[v] as f64),
                ];
                a += p[k] * p[k];
                da += 2.0 * p[k] * m[k];
                dc[0] += 2.0 * p[k] * m[k] * rel[0];
                dc[1] += 2.0 * p[k] * m[k] * rel[1];
                let grad = |f: &[f64]| {
                    [
                        0.5 * (f[shape.xp[u] * ny + v] - f[shape.xm[u] * ny + v]),
                        0.5 * (f[u * ny + (v + 1) % ny] - f[u * ny + (v + ny - 1) % ny]),
                    ]
                };
                let (g0, gm) = (grad(p), grad(m));
                let s = mechanics::equations::shape_tensor_density(g0);
                s0[0] += s[0];
                s0[1] += s[1];
                // The derivative of ½(∂yφ² − ∂xφ²) and −∂xφ ∂yφ along the mode.
                ds[0] += g0[1] * gm[1] - g0[0] * gm[0];
                ds[1] -= g0[0] * gm[1] + g0[1] * gm[0];
            }
        }
        d_area.push(da);
        d_shape.push(ds);
        centres.push([c[0], c[1]]);
        let dcell = [dc[0] / a, dc[1] / a];
        for u in 0..nx {
            for v in 0..ny {
                let node = lattice.index(xs[u] as usize, ys[v] as usize);
                disp[0][node] += p[u * ny + v] * dcell[0];
                disp[1][node] += p[u * ny + v] * dcell[1];
            }
        }
    }
    let mut pic = TissuePicture::new(lattice.lx, lattice.ly, 640);
    pic.patches = patches;
    pic.fill = Fill::Values {
        values: d_area,
        label: "δA (area change)".into(),
        signed: true,
    };
    pic.axes = Some(CellAxes {
        centres,
        shapes: d_shape,
    });
    let [dx, dy] = disp;
    pic.flow = Some(LatticeVectors {
        a: dx,
        b: dy,
        every: 6,
    });
    pic.title = format!("Leading mode at ζ = {}: δA, δS axes, displacement", g(zeta));
    pic.draw()
        .map_err(|e| SweepError::Reproduce { why: e.to_string() })
}

/// An isolated cell (one disc of radius R on 41 × 41 nodes, margin 16) run for 200 TU at
/// ζ = 0, 0.01 and −0.01 from the same disc: the largest change of `|S|`, of the centre and of φ
/// that activity makes. In the continuum the active force on an isolated cell,
/// `ζ Σ_x φ S·∇φ = ζ S·Σ_x ∇(φ²/2)`, vanishes, and so does its discrete sum over the periodic
/// patch; a deformed cell in the tissue has `|S|` ≈ 0.02–0.05.
fn isolated_cell() -> Result<Claim, SweepError> {
    let lattice = phasefield::Lattice::new(41, 41);
    let shape = phasefield::PatchShape::new(lattice, 16).map_err(|e| SweepError::Reproduce {
        why: format!("isolated cell: {e}"),
    })?;
    let params = ModelParams::paper(0.0);
    let run = |zeta: f64| -> Result<(f64, [f64; 2], Vec<f64>), SweepError> {
        let cells = phasefield::init::discs(lattice, shape.clone(), &[[20.3, 20.6]], 8.0, 2.5);
        let mut t = Tissue::new(cells, params.with_zeta(zeta));
        let mut ws = mechanics::Workspace::new(t.cells());
        for _ in 0..400 {
            t.step(&mut ws, &StepParams::new(DT, 1))
                .map_err(|e| SweepError::Reproduce {
                    why: format!("isolated cell at ζ = {zeta}: {e}"),
                })?;
        }
        t.refresh(&mut ws);
        let c = t.centre(0);
        Ok((
            ws.cell(0).shape.magnitude(),
            [c[0], c[1]],
            t.cells().phi().to_vec(),
        ))
    };
    let (s0, c0, p0) = run(0.0)?;
    let mut worst: (f64, f64, f64) = (0.0, 0.0, 0.0);
    for zeta in [0.01, -0.01] {
        let (s, c, p) = run(zeta)?;
        let dphi = p
            .iter()
            .zip(&p0)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        worst.0 = worst.0.max((s - s0).abs());
        worst.1 = worst.1.max((c[0] - c0[0]).hypot(c[1] - c0[1]));
        worst.2 = worst.2.max(dphi);
    }
    let (v, why) = rule_isolated(worst.0, s0);
    Ok(Claim::new(
        "An isolated cell does not deform under activity (ζ = ±0.01 against ζ = 0, 200 TU)",
        format!(
            "|S| = {} at ζ = 0; largest change of |S| {}, of the centre {} nodes, of φ {}",
            g(s0),
            g(worst.0),
            g(worst.1),
            g(worst.2)
        ),
        v,
        why,
    ))
}

/// How much an isolated cell's `|S|` may change under activity and still count as undeformed:
/// 2·10⁻³, a tenth of the smallest deformation of a tissue's cell (0.02 × 1/20 … the paper's
/// S at threshold).
const ISOLATED_CHANGE: f64 = 2e-3;

/// The resolution of the isolated cell's change of `|S|`: 10⁻⁶, a thousandth of the tissue
/// deformation, far above the round-off of 400 steps in f64.
const ISOLATED_RESOLUTION: f64 = 1e-6;

/// "An isolated cell does not deform under activity": the rule of an absence (issue 54's
/// `Rule`) on the largest change of `|S|`, with [`ISOLATED_CHANGE`] counting and
/// [`ISOLATED_RESOLUTION`] as its error.
fn rule_isolated(change: f64, s0: f64) -> (Verdict, String) {
    let o = super::rule::Rule::absence("the largest change of |S| under activity", ISOLATED_CHANGE)
        .decide(change, ISOLATED_RESOLUTION);
    (o.verdict, format!("{} (|S| at rest {})", o.why, g(s0)))
}

/// What the claims read of one configuration's threshold by one method.
struct Measured {
    gamma: f64,
    lx: usize,
    pressure: PressureKind,
    method: String,
    /// ζ_cr and its error; `None` without a sign change of σ.
    zeta: Option<(f64, f64)>,
    /// The configuration and why it has no ζ_cr, when it has none.
    missing: Option<String>,
}

impl Measured {
    fn of(r: &Row) -> Self {
        Self {
            gamma: r.config.gamma,
            lx: r.config.hex.lx,
            pressure: r.config.pressure,
            method: r.method.to_string(),
            zeta: r.zeta(),
            missing: r
                .result
                .as_ref()
                .err()
                .map(|why| format!("{}: {why}", r.config.name())),
        }
    }

    fn same_config(&self, o: &Self) -> bool {
        (self.gamma, self.lx, self.pressure) == (o.gamma, o.lx, o.pressure)
    }
}

/// The thresholds of `zeta_cr.csv` in `dir`, as [`make`] had them (without the reason of a
/// missing one).
#[cfg(test)]
fn measured_from_table(dir: &Path) -> Result<Vec<Measured>, SweepError> {
    let t = super::Table::read(&dir.join("zeta_cr.csv"))?;
    let (gamma, z, e) = (t.f64s("gamma")?, t.f64s("zeta_cr")?, t.f64s("zeta_cr_err")?);
    let (lx, pressure, method) = (t.col("lx")?, t.col("pressure")?, t.col("method")?);
    t.rows
        .iter()
        .enumerate()
        .map(|(k, row)| {
            let p = [PressureKind::Paper, PressureKind::Interaction]
                .into_iter()
                .find(|p| pressure_name(*p) == row[pressure])
                .ok_or_else(|| SweepError::Reproduce {
                    why: format!(
                        "{}: row {}: pressure {}",
                        t.path.display(),
                        k + 1,
                        row[pressure]
                    ),
                })?;
            let found = z[k].is_finite();
            Ok(Measured {
                gamma: gamma[k],
                lx: row[lx].parse().unwrap_or(0),
                pressure: p,
                method: row[method].clone(),
                zeta: found.then_some((z[k], e[k])),
                missing: (!found).then(|| format!("γ = {}, L = {}", gamma[k], row[lx])),
            })
        })
        .collect()
}

fn claims(rows: &[Measured]) -> Vec<Claim> {
    let mut claims = Vec::new();
    // Methods agree.
    let mut pairs = Vec::new();
    for a in rows.iter().filter(|r| r.method == "arnoldi") {
        if let Some(gr) = rows
            .iter()
            .find(|r| r.method == "growth" && r.same_config(a))
        {
            if let (Some((za, ea)), Some((zg, eg))) = (a.zeta, gr.zeta) {
                pairs.push((za, ea, zg, eg));
            }
        }
    }
    let (v, why) = rule_agree(&pairs);
    claims.push(Claim::new(
        "Check: perturbation growth and Arnoldi give the same ζ_cr",
        pairs
            .iter()
            .map(|p| format!("{} ± {} / {} ± {}", g(p.0), g(p.1), g(p.2), g(p.3)))
            .collect::<Vec<_>>()
            .join("; "),
        v,
        why,
    ));
    for pressure in [PressureKind::Paper, PressureKind::Interaction] {
        let pn = pressure_name(pressure);
        let arn: Vec<&Measured> = rows
            .iter()
            .filter(|r| r.method == "arnoldi" && r.pressure == pressure)
            .collect();
        // The box with the most γ values.
        let mut by_box: BTreeMap<usize, Vec<(f64, f64, f64)>> = BTreeMap::new();
        for r in &arn {
            if let Some((z, e)) = r.zeta {
                by_box.entry(r.lx).or_default().push((r.gamma, z, e));
            }
        }
        let missing: Vec<String> = arn.iter().filter_map(|r| r.missing.clone()).collect();
        if let Some((lx, pts)) = by_box
            .iter()
            .max_by_key(|(lx, v)| (v.len(), std::cmp::Reverse(**lx)))
        {
            let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
            let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
            let e: Vec<f64> = pts.iter().map(|p| p.2).collect();
            let list = pts
                .iter()
                .map(|p| format!("{}: {} ± {}", p.0, g(p.1), g(p.2)))
                .collect::<Vec<_>>()
                .join(", ");
            let (v, why) = rule_linear(&x, &y, &e);
            claims.push(Claim::new(
                format!("9.2a: ζ_cr is linear in γ (hexagonal rest state, L = {lx}, {pn} form)"),
                format!("ζ_cr by Arnoldi at γ = {list}"),
                v,
                why,
            ));
            let (v, why) = rule_proportional(&x, &y, &e);
            claims.push(Claim::new(
                format!("9.2a: ζ_cr ∝ γ, a line through zero (L = {lx}, {pn} form)"),
                "weighted line through the same points".to_string(),
                v,
                why,
            ));
        }
        // Box sizes, at every γ measured on more than one box.
        let mut by_gamma: BTreeMap<String, Vec<(f64, f64, f64)>> = BTreeMap::new();
        for r in &arn {
            if let Some((z, e)) = r.zeta {
                by_gamma
                    .entry(r.gamma.to_string())
                    .or_default()
                    .push((r.lx as f64, z, e));
            }
        }
        for (gamma, pts) in by_gamma.iter().filter(|(_, v)| v.len() > 1) {
            let list = pts
                .iter()
                .map(|p| format!("L = {}: {} ± {}", p.0, g(p.1), g(p.2)))
                .collect::<Vec<_>>()
                .join(", ");
            let (v, why) = rule_box(pts);
            claims.push(Claim::new(
                format!("9.2b: ζ_cr does not depend on the box (γ = {gamma}, {pn} form)"),
                list.clone(),
                v,
                why,
            ));
            if gamma == "0.01" {
                let (v, why) = rule_continuum(pts);
                claims.push(Claim::new(
                    format!("Continuum active nematics: ζ_cr → 0 as L → ∞ (γ = 0.01, {pn} form; the paper says the cell model has a finite threshold)"),
                    list,
                    v,
                    why,
                ));
            }
        }
        if !missing.is_empty() {
            claims.push(Claim::new(
                format!("ζ_cr found in the bracket [0, {ZETA_HI}] ({pn} form)"),
                format!("{} configurations without a sign change", missing.len()),
                Verdict::Inconclusive,
                format!(
                    "{} (NaN rows of zeta_cr.csv; σ ≥ 0 already at ζ = 0 means the relaxed packing is not a stable rest state there, or its leading σ is within the Ritz residual of 0)",
                    missing.join("; ")
                ),
            ));
        }
    }
    claims
}

fn settings(
    scale: Scale,
    plan: &Plan,
    rests: &BTreeMap<String, RestState>,
    conv: &[Conv],
) -> String {
    // Configurations run box by box within each pressure form: sort before removing repeats.
    let mut boxes: Vec<HexBox> = plan.arnoldi.iter().map(|c| c.hex).collect();
    boxes.sort_by_key(|h| (h.cols, h.rows));
    boxes.dedup();
    let box_lines = boxes
        .iter()
        .map(|h| {
            let [ax, ay] = h.spacings();
            format!(
                "{} × {} cells on {} × {} nodes (spacings {} along the rows, {} across; residual anisotropy {} %)",
                h.cols,
                h.rows,
                h.lx,
                h.ly,
                g(ax),
                g(ay),
                g(100.0 * h.anisotropy())
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    let (tmin, tmax, vmax, rate, smin, smax) = rests.values().fold(
        (f64::INFINITY, 0.0f64, 0.0f64, 0.0f64, f64::INFINITY, 0.0f64),
        |a, r| {
            (
                a.0.min(r.time),
                a.1.max(r.time),
                a.2.max(r.v_max),
                a.3.max(r.phi_rate),
                a.4.min(r.s_rms),
                a.5.max(r.s_rms),
            )
        },
    );
    let relax = Relaxation::default();
    let conv_lines = if conv.is_empty() {
        String::new()
    } else {
        let reference = conv[0].sigma;
        format!(
            "- Convergence (`convergence.csv`; σ at the Arnoldi ζ_cr of γ = 0.01, 6 × 10, paper form): {}.\n",
            conv.iter()
                .map(|c| format!("{}: σ = {} (Δσ = {})", c.what, g(c.sigma), g(c.sigma - reference)))
                .collect::<Vec<_>>()
                .join("; ")
        )
    };
    format!(
        "- Rest state: a hexagonal packing at the paper's density (one cell per {} nodes), discs of radius {}R relaxed at ζ = 0 with dt {} until no field changes by more than {:e} per TU (over {} steps) or {} TU: {box_lines}. Relaxed in {}–{} TU; at the end the largest field rate is {}/TU, the largest cell speed {} (a steady treadmilling of the interfaces: φ stays, v_i ≠ 0 balances the relaxation), and S_rms = {}–{}: the shape anisotropy the packing keeps from the square grid (`rest_states.csv`).\n\
         - The map: {STEPS} Heun steps of dt {DT} (τ = {} TU), f64, margin 16, about the rest state at each ζ (the state relaxed at ζ = 0; its residual forcing at ζ > 0 is the drift of the map, |M(x₀) − x₀|, in `translations.csv` at ζ = 0 and at each ζ_cr). The two uniform translations are projected out; on the lattice they are not exactly neutral, and their own growth rates (the Rayleigh quotient t·Jt of each unit generator) are in `translations.csv` at ζ = 0 and at each ζ_cr. σ = ln|μ|/τ of the leading eigenvalue μ of the map's Jacobian.\n\
         - Arnoldi: Krylov dimension {}, `J v ≈ (M(x₀ + εv) − M(x₀))/ε` with ε = {:e} for a unit v (the perturbation is then about 1e-7 per node: truncation error O(ε) against round-off O(1e-16/ε) per node, balanced near 1e-8 relative; checked against ε/10 and 10ε below), Hessenberg eigenproblem by faer; error = the leading Ritz residual. Each evaluation of a bisection starts from the last one's leading mode with a random third mixed in.\n\
         - Perturbation growth: {} perturbations of norm {:e} about the same base, integrated over τ and renormalised (simultaneous power iteration with Rayleigh–Ritz on the {}×{} projected matrix), {} intervals ({} on a cold start); σ from the last rate plus the geometric tail of its approach, error twice that tail. Its convergence is slow because the leading modes form a dense band (spacing ~1e-4/TU), so it is run on fewer configurations.\n\
         - ζ_cr: bisection on [0, {ZETA_HI}] (the bracket first narrowed, up to three times, to ± 1e-4 around the root of the straight line through its ends), to half-width {TOL_ARNOLDI:e} (Arnoldi) and {TOL_GROWTH:e} (growth); its error adds the σ error over dσ/dζ in quadrature.\n\
         {conv_lines}\
         - Scale `{}`. Files: `zeta_cr.csv`, `growth_rates.csv`, `spectrum.csv` (the leading Ritz values at the last evaluation), `rest_states.csv`, `convergence.csv`, `translations.csv`, `zeta_cr_gamma.png`, `zeta_cr_box.png`, `growth_rates.png`, `mode.png`.",
        g(AREA_PER_CELL),
        relax.init_radius,
        relax.step.dt,
        relax.phi_rate,
        relax.check_every,
        relax.max_time,
        g(tmin),
        g(tmax),
        g(rate),
        g(vmax),
        g(smin),
        g(smax),
        STEPS as f64 * DT,
        plan.arnoldi_opts.krylov,
        plan.arnoldi_opts.eps,
        plan.growth_opts.vectors,
        plan.growth_opts.amplitude,
        plan.growth_opts.vectors,
        plan.growth_opts.vectors,
        plan.growth_opts.intervals,
        3 * plan.growth_opts.intervals,
        scale.name(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The stability section of docs/reproduction.md states the verdicts of the figure's
    /// thresholds, kept in `docs/data/stability/quick/zeta_cr.csv`, and of the isolated cell,
    /// computed again here.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let dir = crate::stored_tables("stability/quick");
        let rows = measured_from_table(&dir).unwrap();
        let mut claims = claims(&rows);
        let reference = rows
            .iter()
            .find(|r| {
                r.method == "arnoldi"
                    && r.gamma == 0.01
                    && r.lx == 83
                    && r.pressure == PressureKind::Paper
            })
            .and_then(|r| r.zeta)
            .unwrap();
        let conv = crate::Table::read(&dir.join("convergence.csv")).unwrap();
        let (case, shift, err) = (
            conv.col("case").unwrap(),
            conv.f64s("zeta_shift").unwrap(),
            conv.f64s("zeta_shift_err").unwrap(),
        );
        let shifts: Vec<(String, f64, f64)> = (0..conv.rows.len())
            .map(|k| (conv.rows[k][case].clone(), shift[k], err[k]))
            .collect();
        claims.extend(claim_discretisation(reference.0, reference.1, &shifts));
        claims.push(isolated_cell().unwrap());
        let want: Vec<(String, Verdict)> =
            claims.into_iter().map(|c| (c.claim, c.verdict)).collect();
        crate::assert_doc_verdicts("stability", "**Verdicts (quick):**", &want);
    }

    /// A threshold kept on disk reads back to the bit, NaN included; one made with other
    /// settings, or a damaged file, is not read back.
    #[test]
    fn a_kept_threshold_reads_back_only_with_its_settings() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("kept.toml");
        let t = Threshold {
            zeta_cr: 5.7e-4,
            err: 1.0 / 3.0 * 1e-5,
            slope: 0.123456789012345,
            evaluations: vec![
                stability::Evaluation {
                    zeta: 0.0,
                    sigma: -1.1e-3,
                    sigma_err: f64::NAN,
                },
                stability::Evaluation {
                    zeta: 8e-3,
                    sigma: 2.5e-3,
                    sigma_err: 1e-6,
                },
            ],
            spectrum: None,
        };
        let o = Outcome {
            threshold: Some(t.clone()),
            no_crossing: None,
        };
        keep(&path, "settings A", o).unwrap();
        let back: Outcome = kept(&path, "settings A").unwrap();
        let b = back.threshold.unwrap();
        assert_eq!(b.zeta_cr.to_bits(), t.zeta_cr.to_bits());
        assert_eq!(b.err.to_bits(), t.err.to_bits());
        assert_eq!(b.slope.to_bits(), t.slope.to_bits());
        assert!(b.evaluations[0].sigma_err.is_nan());
        assert_eq!(b.evaluations[1], t.evaluations[1]);
        assert!(kept::<Outcome>(&path, "settings B").is_none());
        std::fs::write(&path, "fingerprint = \"settings A\"\n[value\n").unwrap();
        assert!(kept::<Outcome>(&path, "settings A").is_none());
    }

    #[test]
    fn the_isolated_cell_rule_gives_each_outcome() {
        assert_eq!(rule_isolated(1e-9, 1e-4).0, Verdict::Holds);
        assert_eq!(rule_isolated(5e-3, 1e-4).0, Verdict::DoesNotHold);
        assert_eq!(rule_isolated(1.9995e-3, 1e-4).0, Verdict::Inconclusive);
        assert_eq!(rule_isolated(1e-4, 1e-4).0, Verdict::Holds);
    }

    /// The real cell: activity leaves it as it is.
    #[test]
    fn an_isolated_cell_does_not_deform() {
        let c = isolated_cell().unwrap();
        assert_eq!(c.verdict, Verdict::Holds, "{}", c.measured);
    }
}
