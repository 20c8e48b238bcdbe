//! `reproduce defects`: the supplementary defect figure. Defect density and creation rate
//! against ζ; total density and net charge over time; where pairs are created.

use render::{Plot, Series};

use super::lengths::{by_value, times, trend, turbulence, PRESSURES, ZETAS};
use super::pipeline::{cell, sci, Csv, Made, PointRuns};
use super::rule::Rule;
use super::{
    g, mean_se, mean_std, AtValue, Claim, Rec, ReproduceParams, SweepResult, Table, Verdict,
};
use study::SweepError;

/// Bins per side of the creation-position test.
const BINS: usize = 4;

/// The side of the defects figure's box (the `lengths` ζ sweep: L = 200).
const BOX: f64 = 200.0;

/// The paper's cell radius, which sets the pairing distance 2R.
const RADIUS: f64 = 8.0;

/// The bin of `BINS × BINS` over the box that holds `(x, y)`.
fn bin(x: f64, y: f64) -> usize {
    let b = |v: f64| ((v.rem_euclid(BOX) / BOX * BINS as f64) as usize).min(BINS - 1);
    b(x) * BINS + b(y)
}

/// A run's paired fraction of births and what independent births would give: `creations`
/// pairs (two births each) and `unpaired` births and deaths without a partner (half of them
/// births, as births and deaths balance in a steady state) over `frames` frames on `area`
/// nodes. A birth at random has an opposite-charge birth within `2R` in the same frame interval
/// with probability `1 − exp(−(b/2) π (2R)² / area)`, `b` the births per frame. `None` for a run
/// with no birth.
fn pairing(
    creations: f64,
    unpaired: f64,
    frames: usize,
    area: f64,
    radius: f64,
) -> Option<(f64, f64)> {
    let births = 2.0 * creations + 0.5 * unpaired;
    if births <= 0.0 || frames == 0 {
        return None;
    }
    let per_frame = births / frames as f64;
    let disc = std::f64::consts::PI * (2.0 * radius).powi(2);
    let null = 1.0 - (-(0.5 * per_frame) * disc / area).exp();
    Some((2.0 * creations / births, null))
}

/// The Pearson correlations of the creation maps of every pair of runs from different seeds
/// (runs of one seed start from the same packing, so they share their early defects) that
/// each have at least one creation per two bins: near 0 when places are random, positive when
/// runs share preferred places (fixed in the box, as a grid artefact would be).
fn map_correlations<S: PartialEq>(maps: &[(S, [f64; BINS * BINS])]) -> Vec<f64> {
    let used: Vec<&(S, [f64; BINS * BINS])> = maps
        .iter()
        .filter(|m| m.1.iter().sum::<f64>() >= (BINS * BINS / 2) as f64)
        .collect();
    let mut r = Vec::new();
    for i in 0..used.len() {
        for j in 0..i {
            if used[i].0 == used[j].0 {
                continue;
            }
            let (a, b) = (&used[i].1, &used[j].1);
            let (ma, mb) = (mean_std(a).0, mean_std(b).0);
            let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
            let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
            let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
            if va > 0.0 && vb > 0.0 {
                r.push(cov / (va * vb).sqrt());
            }
        }
    }
    r
}

/// The least excess of the paired fraction over chance that counts as "in pairs": a tenth of
/// the births. Below it (with two s.e.), births are not paired.
const PAIRING_EFFECT: f64 = 0.1;

/// The verdict on "±½ defects annihilate in pairs" from each run's paired fraction of deaths
/// `f` and its null expectation `q`: the rule of an effect (issue 54's `Rule`) on the mean of
/// `f − q` over runs, with [`PAIRING_EFFECT`] counting; inconclusive with fewer than three runs.
fn annihilate_in_pairs(f: &[f64], q: &[f64]) -> (Verdict, String) {
    if f.len() < 3 {
        return (
            Verdict::Inconclusive,
            format!(
                "{} runs with deaths: too few to test (three needed)",
                f.len()
            ),
        );
    }
    let excess: Vec<f64> = f.iter().zip(q).map(|(f, q)| f - q).collect();
    let (e, se) = mean_se(&excess);
    let o = Rule::effect("paired fraction of deaths − chance", PAIRING_EFFECT).decide(e, se);
    (o.verdict, o.why)
}

/// The verdict on "±½ defects appear in pairs at random places" from each run's paired
/// fraction of births `f` and its null expectation `q`, and the correlations `r` of the
/// creation maps of pairs of runs: the rule of an effect on the mean of `f − q` with
/// [`PAIRING_EFFECT`] counting (pairs), and the rule of an absence on the mean of `r` with
/// [`SHARED_PLACES`] counting (random places); holds when both hold, does not hold when one
/// does not ([`super::rules::all_hold`]); inconclusive with fewer than three runs or three pairs
/// of runs.
fn pairs_at_random_places(f: &[f64], q: &[f64], r: &[f64]) -> (Verdict, String) {
    if f.len() < 3 || r.len() < 3 {
        return (
            Verdict::Inconclusive,
            format!(
                "{} runs with births and {} pairs of runs with creation maps: too few to test (three of each needed)",
                f.len(),
                r.len()
            ),
        );
    }
    let excess: Vec<f64> = f.iter().zip(q).map(|(f, q)| f - q).collect();
    let (e, e_se) = mean_se(&excess);
    let (rm, r_se) = mean_se(r);
    let pairs = Rule::effect("paired fraction of births − chance", PAIRING_EFFECT).decide(e, e_se);
    let places =
        Rule::absence("correlation of two runs' creation maps", SHARED_PLACES).decide(rm, r_se);
    let verdict = super::rules::all_hold([pairs.verdict, places.verdict]);
    (
        verdict,
        format!("pairs: {}; places: {}", pairs.why, places.why),
    )
}

/// The correlation of two runs' creation maps that counts as shared places: ½.
const SHARED_PLACES: f64 = 0.5;

/// The figure's tables, plots and claims for one pressure form.
fn one_form(
    p: &ReproduceParams,
    made: &mut Made,
    runs_csv: &mut Csv,
    zeta: &SweepResult,
    points: &[PointRuns],
    pressure: &str,
) -> Result<Vec<Claim>, SweepError> {
    let recs: Vec<&Rec> = points
        .iter()
        .filter(|pt| pt.values[0] == pressure)
        .flat_map(|pt| &pt.runs)
        .collect();
    let density = by_value(zeta, pressure, &ZETAS, "defect_density")?;
    let rate = by_value(zeta, pressure, &ZETAS, "creation_rate")?;
    against_zeta(made, pressure, &density, &rate);
    let mut events = Events::default();
    let mut time_csv = Csv::new(&[
        "zeta",
        "seed",
        "time",
        "n_plus",
        "n_minus",
        "defect_density",
        "net_charge",
    ]);
    let mut pt = Plot::new(
        format!("Defect density in time (seed 1, {pressure} pressure)"),
        "time (TU)",
        "±1/2 defects per node",
    );
    let mut pq = Plot::new(
        format!("Net topological charge in time (every run, {pressure} pressure)"),
        "time (TU)",
        "net charge",
    );
    for &r in &recs {
        events.add(p, r, &mut time_csv, [&mut pt, &mut pq])?;
    }
    made.add_table(format!("defects_in_time_{pressure}.csv"), time_csv);
    made.add_plot(format!("defect_density_in_time_{pressure}.png"), pt);
    made.add_plot(format!("net_charge_in_time_{pressure}.png"), pq);

    // Where pairs are created: counts in BINS × BINS cells of the box.
    let mut counts = [0usize; BINS * BINS];
    for &(x, y) in &events.creations {
        counts[bin(x, y)] += 1;
    }
    let mut pos_csv = Csv::new(&["bin_x", "bin_y", "creations"]);
    for (k, c) in counts.iter().enumerate() {
        pos_csv.row([cell(k / BINS), cell(k % BINS), cell(c)]);
    }
    made.add_table(format!("creation_positions_{pressure}.csv"), pos_csv);

    for run in &events.runs {
        runs_csv.row(run.row(pressure));
    }
    Ok(events.claims(pressure, &density, &rate))
}

/// The defect density and the creation rate against ζ at one pressure form: their table and
/// plots.
fn against_zeta(made: &mut Made, pressure: &str, density: &[AtValue], rate: &[AtValue]) {
    let mut csv = Csv::new(&[
        "zeta",
        "defect_density",
        "defect_density_std",
        "creation_rate",
        "creation_rate_std",
        "seeds",
    ]);
    for (d, r) in density.iter().zip(rate) {
        csv.row([
            cell(d.0),
            sci(d.1 .0),
            sci(d.1 .1),
            sci(r.1 .0),
            sci(r.1 .1),
            cell(d.2),
        ]);
    }
    made.add_table(format!("defects_vs_zeta_{pressure}.csv"), csv);
    let series = |pts: &[AtValue], label: &str| {
        let x: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let m: Vec<f64> = pts.iter().map(|p| p.1 .0).collect();
        let e: Vec<f64> = pts.iter().map(|p| p.1 .1).collect();
        Series::new(label).with_points(&x, &m, &e)
    };
    let mut pd = Plot::new(
        format!("Defect density against ζ (γ = 0.01, L = 200, {pressure} pressure)"),
        "activity ζ",
        "±1/2 defects per node",
    );
    pd.series.push(series(density, "defect density"));
    made.add_plot(format!("defect_density_vs_zeta_{pressure}.png"), pd);
    let mut pr = Plot::new(
        format!("Creation rate of defect pairs against ζ ({pressure} pressure)"),
        "activity ζ",
        "pair creations per node per TU",
    );
    pr.series.push(series(rate, "creation rate"));
    made.add_plot(format!("creation_rate_vs_zeta_{pressure}.png"), pr);
}

/// What the frames and the defect events of one pressure form's runs add up to: the frames
/// and those with a net charge, the pair creations and their places, the births and deaths
/// without a partner, and per active run the paired fractions of births and deaths with their
/// null expectations and the map of creations.
#[derive(Default)]
struct Events {
    frames: usize,
    charged: usize,
    max_charge: f64,
    /// Where the pairs were created (for the table of positions).
    creations: Vec<(f64, f64)>,
    n_creations: usize,
    unpaired: f64,
    fractions: Vec<f64>,
    nulls: Vec<f64>,
    maps: Vec<(u64, [f64; BINS * BINS])>,
    d_fractions: Vec<f64>,
    d_nulls: Vec<f64>,
    annihilations: usize,
    /// Each run's events, for `defect_runs.csv`.
    runs: Vec<RunEvents>,
}

/// What one run adds to [`Events`]: a row of `defect_runs.csv`.
#[derive(Debug, Clone, PartialEq)]
struct RunEvents {
    zeta: String,
    seed: u64,
    frames: usize,
    charged: usize,
    max_charge: f64,
    unpaired: f64,
    /// ζ > 0: its creations, annihilations, pairing and map count.
    active: bool,
    creations: usize,
    annihilations: usize,
    /// The paired fraction of births and its null, where it had births.
    births: Option<(f64, f64)>,
    /// The same of deaths.
    deaths: Option<(f64, f64)>,
    map: [f64; BINS * BINS],
}

/// The columns of `defect_runs.csv`.
const RUN_COLUMNS: [&str; 16] = [
    "pressure",
    "zeta",
    "seed",
    "frames",
    "charged_frames",
    "max_charge",
    "unpaired",
    "active",
    "creations",
    "annihilations",
    "births_paired",
    "births_chance",
    "deaths_paired",
    "deaths_chance",
    "map",
    "bins",
];

impl RunEvents {
    fn row(&self, pressure: &str) -> Vec<String> {
        let pair = |p: Option<(f64, f64)>| {
            let (f, q) = p.unwrap_or((f64::NAN, f64::NAN));
            [sci(f), sci(q)]
        };
        [
            cell(pressure),
            cell(&self.zeta),
            cell(self.seed),
            cell(self.frames),
            cell(self.charged),
            cell(self.max_charge),
            cell(self.unpaired),
            cell(self.active),
            cell(self.creations),
            cell(self.annihilations),
        ]
        .into_iter()
        .chain(pair(self.births))
        .chain(pair(self.deaths))
        .chain([
            self.map
                .iter()
                .map(|v| v.to_string())
                .collect::<Vec<_>>()
                .join(" "),
            cell(BINS),
        ])
        .collect()
    }

    /// The runs of `pressure` in a table that [`RunEvents::row`] wrote.
    #[cfg(test)]
    fn from_table(t: &Table, pressure: &str) -> Result<Vec<Self>, SweepError> {
        let c = |n: &str| t.col(n);
        let bad = |k: usize, what: &str| SweepError::Reproduce {
            why: format!("{}: row {}: {what}", t.path.display(), k + 1),
        };
        let (pc, zc, sc, fc, cc, mc, uc, ac) = (
            c("pressure")?,
            c("zeta")?,
            c("seed")?,
            c("frames")?,
            c("charged_frames")?,
            c("max_charge")?,
            c("unpaired")?,
            c("active")?,
        );
        let (crc, anc, mapc) = (c("creations")?, c("annihilations")?, c("map")?);
        let (bf, bq, df, dq) = (
            t.f64s("births_paired")?,
            t.f64s("births_chance")?,
            t.f64s("deaths_paired")?,
            t.f64s("deaths_chance")?,
        );
        let pair = |f: f64, q: f64| f.is_finite().then_some((f, q));
        let mut out = Vec::new();
        for (k, row) in t.rows.iter().enumerate().filter(|(_, r)| r[pc] == pressure) {
            let n = |col: usize, what: &str| -> Result<f64, SweepError> {
                row[col].parse().map_err(|_| bad(k, what))
            };
            let mut map = [0.0; BINS * BINS];
            for (m, v) in map.iter_mut().zip(row[mapc].split(' ')) {
                *m = v.parse().map_err(|_| bad(k, "map"))?;
            }
            out.push(Self {
                zeta: row[zc].clone(),
                seed: n(sc, "seed")? as u64,
                frames: n(fc, "frames")? as usize,
                charged: n(cc, "charged_frames")? as usize,
                max_charge: n(mc, "max_charge")?,
                unpaired: n(uc, "unpaired")?,
                active: row[ac] == "true",
                creations: n(crc, "creations")? as usize,
                annihilations: n(anc, "annihilations")? as usize,
                births: pair(bf[k], bq[k]),
                deaths: pair(df[k], dq[k]),
                map,
            });
        }
        Ok(out)
    }
}

impl Events {
    /// Adds one run's events.
    fn push(&mut self, e: RunEvents) {
        self.frames += e.frames;
        self.charged += e.charged;
        self.max_charge = self.max_charge.max(e.max_charge);
        self.unpaired += e.unpaired;
        if e.active {
            self.n_creations += e.creations;
            self.annihilations += e.annihilations;
            if let Some((f, q)) = e.births {
                self.fractions.push(f);
                self.nulls.push(q);
            }
            if let Some((f, q)) = e.deaths {
                self.d_fractions.push(f);
                self.d_nulls.push(q);
            }
            self.maps.push((e.seed, e.map));
        }
        self.runs.push(e);
    }

    /// Adds the run `r`: its rows of the table in time, its series of the density (seed 1)
    /// and net-charge plots, and its events.
    fn add(
        &mut self,
        p: &ReproduceParams,
        r: &Rec,
        time_csv: &mut Csv,
        [pt, pq]: [&mut Plot; 2],
    ) -> Result<(), SweepError> {
        let t = Table::read(&r.run.join("analysis/observables.csv"))?;
        let (time, np, nm, dens, net, un) = (
            t.f64s("time")?,
            t.f64s("n_plus")?,
            t.f64s("n_minus")?,
            t.f64s("defect_density")?,
            t.f64s("net_charge")?,
            t.f64s("unpaired")?,
        );
        let mut run = RunEvents {
            zeta: r.values[1].clone(),
            seed: r.seed,
            frames: 0,
            charged: 0,
            max_charge: 0.0,
            unpaired: un.iter().filter(|x| x.is_finite()).sum::<f64>(),
            active: r.values[1].parse::<f64>().unwrap_or(0.0) > 0.0,
            creations: 0,
            annihilations: 0,
            births: None,
            deaths: None,
            map: [0.0; BINS * BINS],
        };
        for k in 0..time.len() {
            time_csv.row([
                cell(&r.values[1]),
                cell(r.seed),
                cell(time[k]),
                cell(np[k]),
                cell(nm[k]),
                sci(dens[k]),
                cell(net[k]),
            ]);
            run.frames += 1;
            if net[k] != 0.0 {
                run.charged += 1;
            }
            run.max_charge = run.max_charge.max(net[k].abs());
        }
        if r.seed == p.scale.seeds().first {
            pt.series
                .push(Series::new(format!("ζ = {}", r.values[1])).with_points(
                    &time,
                    &dens,
                    &vec![0.0; time.len()],
                ));
        }
        pq.series.push(
            Series::new(if r.seed == p.scale.seeds().first {
                format!("ζ = {}", r.values[1])
            } else {
                String::new()
            })
            .with_points(&time, &net, &vec![0.0; time.len()])
            .markers_only(),
        );
        if run.active {
            let ev = Table::read(&r.run.join("analysis/defect_events.csv"))?;
            let (kind, x, y) = (ev.strs("kind")?, ev.f64s("x")?, ev.f64s("y")?);
            let (mut born, mut ended) = (0.0, 0.0);
            for k in 0..kind.len() {
                if kind[k] == "creation" {
                    self.creations.push((x[k], y[k]));
                    run.map[bin(x[k], y[k])] += 1.0;
                    run.creations += 1;
                    born += 1.0;
                } else if kind[k] == "annihilation" {
                    ended += 1.0;
                    run.annihilations += 1;
                }
            }
            run.births = pairing(born, run.unpaired, time.len(), BOX * BOX, RADIUS);
            // Deaths: half of the unpaired events are deaths, as for births.
            run.deaths = pairing(ended, run.unpaired, time.len(), BOX * BOX, RADIUS);
        }
        self.push(run);
        Ok(())
    }

    /// The claims of §9.5 at one pressure form.
    fn claims(&self, pressure: &str, density: &[AtValue], rate: &[AtValue]) -> Vec<Claim> {
        let correlations = &map_correlations(&self.maps)[..];
        let (v_pairs, why_pairs) =
            pairs_at_random_places(&self.fractions, &self.nulls, correlations);
        let Self {
            frames,
            charged,
            max_charge,
            n_creations,
            unpaired,
            fractions,
            nulls,
            d_fractions,
            d_nulls,
            annihilations,
            ..
        } = self;
        let (frames, charged, max_charge, unpaired, annihilations) =
            (*frames, *charged, *max_charge, *unpaired, *annihilations);
        let active: Vec<AtValue> = density.iter().filter(|d| d.0 > 0.0).cloned().collect();
        let (td, ta) = (trend(density, 1.0), trend(&active, 1.0));
        let tr = trend(
            &rate
                .iter()
                .filter(|d| d.0 > 0.0)
                .cloned()
                .collect::<Vec<_>>(),
            1.0,
        );
        let at_rest = density.first().map_or(f64::NAN, |d| d.1 .0);
        let top = density.last().map_or(f64::NAN, |d| d.1 .0);
        vec![
        Claim::new(
            format!("9.5 ({pressure} pressure): the total topological charge stays zero"),
            format!("{charged} of {frames} analysed frames have a non-zero net charge (largest |charge| {max_charge})"),
            if frames == 0 { Verdict::Inconclusive } else if charged == 0 { Verdict::Holds } else { Verdict::DoesNotHold },
            "every +1/2 found has a −1/2 partner in the same frame, as a periodic domain requires",
        ),
        Claim::new(
            format!("9.5 ({pressure} pressure): ±1/2 defects appear in pairs at random places"),
            format!(
                "{} pair creations at ζ > 0, {} births or deaths without a partner within 2R; paired fraction of births {} ± {} (s.e. over {} runs) against {} ± {} for independent births at the same rate; creation maps ({BINS}×{BINS} bins) of two runs of different seeds correlate by r = {} ± {} (s.e. over {} pairs of runs, an underestimate, since the pairs share runs)",
                n_creations,
                unpaired,
                g(mean_se(fractions).0),
                g(mean_se(fractions).1),
                fractions.len(),
                g(mean_se(nulls).0),
                g(mean_se(nulls).1),
                g(mean_se(correlations).0),
                g(mean_se(correlations).1),
                correlations.len()
            ),
            v_pairs,
            why_pairs,
        ),
        {
            let (v, why) = annihilate_in_pairs(d_fractions, d_nulls);
            Claim::new(
                format!("9.5 ({pressure} pressure): ±1/2 defects annihilate in pairs"),
                format!(
                    "{annihilations} pair annihilations at ζ > 0, {unpaired} births or deaths without a partner; paired fraction of deaths {} ± {} (s.e. over {} runs) against {} ± {} for independent deaths at the same rate",
                    g(mean_se(d_fractions).0),
                    g(mean_se(d_fractions).1),
                    d_fractions.len(),
                    g(mean_se(d_nulls).0),
                    g(mean_se(d_nulls).1),
                ),
                v,
                why,
            )
        },
        Claim::new(
            format!("9.5 ({pressure} pressure): the defect density grows with ζ"),
            format!(
                "ζ from 0: {}; among ζ > 0: {}; at rest {} of the largest density is already there",
                td.measured,
                ta.measured,
                g(at_rest / top)
            ),
            td.verdict,
            format!("from rest to the largest ζ: {}", td.why),
        ),
        Claim::new(
            format!("9.5 ({pressure} pressure): the creation rate grows with ζ"),
            format!("among ζ > 0: {}", tr.measured),
            tr.verdict,
            tr.why,
        ),
    ]
    }
}

pub(super) fn make(p: &ReproduceParams) -> Result<Made, SweepError> {
    let (zeta, _) = turbulence(p)?;
    p.reporter.stage("defects: tables and plots");
    let points = zeta.points(None)?;
    let mut made = Made::new(Vec::new(), String::new());
    let mut claims = Vec::new();
    let mut runs_csv = Csv::new(&RUN_COLUMNS);
    for pressure in PRESSURES {
        claims.extend(one_form(
            p,
            &mut made,
            &mut runs_csv,
            &zeta,
            &points,
            pressure,
        )?);
    }
    made.add_table("defect_runs.csv", runs_csv);
    let (t, from) = times(p.scale);
    let settings = format!(
        "- The ζ sweep of `reproduce lengths` (L = 200, 240 cells, γ = 0.01, both pressure forms, ζ ∈ {{{}}}, seeds {}), 200 TU of relaxation then {t} TU; frames every 10 TU analysed from t = {from}.\n\
         - Defects: ±1/2 of the box-smoothed Q (3R box); tracked between frames (links within R), births and deaths paired within 2R into creations and annihilations. Density = defects per node; creation rate = pair creations per node per TU, averaged over the frames.\n\
         - In pairs at random places (per active run, then over runs): the paired fraction of births `2C / (2C + U/2)` (C creations, U unpaired births and deaths, half of them births) against independent births at the same rate, `1 − exp(−(b/2) π (2R)² / L²)` with b births per frame; and the Pearson correlation of the creation counts in {BINS}×{BINS} bins between every two runs of different seeds (runs of one seed share their starting packing; near 0 for random places, positive for places the runs share). Holds: the paired excess above 0 by two s.e. and the correlation within two s.e. of 0 and below 0.5; does not hold: the paired excess below 0.1 within two s.e., or the correlation above 0 by two s.e.; otherwise inconclusive.\n\
         - Files (one of each per pressure form, `_paper` and `_interaction`): `defects_vs_zeta_*.csv`, `defects_in_time_*.csv`, `defect_runs.csv` (each run's frames, charges and events, both forms), `creation_positions_*.csv`, `defect_density_vs_zeta_*.png`, `creation_rate_vs_zeta_*.png`, `defect_density_in_time_*.png`, `net_charge_in_time_*.png`.",
        ZETAS.join(", "),
        p.scale.seeds()
    );
    made.claims = claims;
    made.settings = settings;
    Ok(made)
}

/// The claims of the figure's tables kept in `dir` (`defect_runs.csv` and
/// `defects_vs_zeta_*.csv`), as [`make`] gives them.
#[cfg(test)]
fn verdicts_from_tables(dir: &std::path::Path) -> Result<Vec<(String, Verdict)>, SweepError> {
    let runs = Table::read(&dir.join("defect_runs.csv"))?;
    let mut out = Vec::new();
    for pressure in PRESSURES {
        let t = Table::read(&dir.join(format!("defects_vs_zeta_{pressure}.csv")))?;
        let (z, seeds) = (t.f64s("zeta")?, t.f64s("seeds")?);
        let at = |m: &str, s: &str| -> Result<Vec<AtValue>, SweepError> {
            let (m, s) = (t.f64s(m)?, t.f64s(s)?);
            Ok((0..z.len())
                .map(|k| (z[k], (m[k], s[k]), seeds[k] as usize))
                .collect())
        };
        let (density, rate) = (
            at("defect_density", "defect_density_std")?,
            at("creation_rate", "creation_rate_std")?,
        );
        let mut events = Events::default();
        for run in RunEvents::from_table(&runs, pressure)? {
            events.push(run);
        }
        out.extend(
            events
                .claims(pressure, &density, &rate)
                .into_iter()
                .map(|c| (c.claim, c.verdict)),
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The defects section of docs/reproduction.md states the verdicts of the figure's runs,
    /// kept in `docs/data/defects/quick/`.
    #[test]
    fn the_docs_state_the_verdicts_of_the_stored_tables() {
        let want = verdicts_from_tables(&crate::stored_tables("defects/quick")).unwrap();
        assert_eq!(want.len(), 10);
        crate::assert_doc_verdicts("defects", "**Verdicts (quick):**", &want);
    }

    /// The 9.5 rule gives each outcome on synthetic statistics.
    #[test]
    fn the_pairing_rule_gives_each_outcome() {
        let q = [0.05, 0.06, 0.05, 0.04];
        let paired = [0.7, 0.75, 0.68, 0.72];
        let random_r = [0.05, -0.1, 0.02, -0.04, 0.08, -0.02];
        assert_eq!(
            pairs_at_random_places(&paired, &q, &random_r).0,
            Verdict::Holds
        );
        // Births no more paired than chance.
        let chance = [0.05, 0.04, 0.06, 0.05];
        assert_eq!(
            pairs_at_random_places(&chance, &q, &random_r).0,
            Verdict::DoesNotHold
        );
        // Every run creates its pairs in the same bins.
        let shared = [0.8, 0.7, 0.75, 0.85, 0.9, 0.78];
        assert_eq!(
            pairs_at_random_places(&paired, &q, &shared).0,
            Verdict::DoesNotHold
        );
        // Correlations too spread to bound, pairing too noisy to tell.
        let wide = [0.9, -0.8, 0.7, -0.6, 0.2, -0.1];
        let noisy = [0.9, 0.0, 0.5, 0.1];
        assert_eq!(
            pairs_at_random_places(&noisy, &q, &wide).0,
            Verdict::Inconclusive
        );
        // Too few runs.
        assert_eq!(
            pairs_at_random_places(&paired[..2], &q[..2], &random_r).0,
            Verdict::Inconclusive
        );
    }

    #[test]
    fn the_annihilation_rule_gives_each_outcome() {
        let q = [0.02, 0.03, 0.02, 0.025];
        assert_eq!(
            annihilate_in_pairs(&[0.7, 0.75, 0.68, 0.72], &q).0,
            Verdict::Holds
        );
        assert_eq!(
            annihilate_in_pairs(&[0.03, 0.05, 0.02, 0.04], &q).0,
            Verdict::DoesNotHold
        );
        assert_eq!(
            annihilate_in_pairs(&[0.0, 0.5, 0.05, 0.4], &q).0,
            Verdict::Inconclusive
        );
        assert_eq!(
            annihilate_in_pairs(&[0.7], &q[..1]).0,
            Verdict::Inconclusive
        );
    }

    /// The null expectation of pairing is small for sparse births and tends to 1 for dense
    /// ones; a run of pairs only has a paired fraction 1, one of lone births 0.
    #[test]
    fn pairing_fractions_and_their_null() {
        let (f, q) = pairing(10.0, 0.0, 10, 40000.0, 8.0).unwrap();
        assert_eq!(f, 1.0);
        // 2 births per frame, half opposite: 1 × π·16² / 40000 = 0.0201.
        assert!((q - (1.0 - (-std::f64::consts::PI * 256.0 / 40000.0f64).exp())).abs() < 1e-12);
        let (f, _) = pairing(0.0, 40.0, 10, 40000.0, 8.0).unwrap();
        assert_eq!(f, 0.0);
        let (_, dense) = pairing(1e5, 0.0, 10, 40000.0, 8.0).unwrap();
        assert!(dense > 0.999);
        assert!(pairing(0.0, 0.0, 10, 40000.0, 8.0).is_none());
    }

    /// Identical maps correlate by 1, a map and its mirror by −1; maps with too few
    /// creations, and pairs of runs of one seed, are left out.
    #[test]
    fn creation_maps_correlate() {
        let mut a = [0.0; BINS * BINS];
        for (k, v) in a.iter_mut().enumerate() {
            *v = k as f64;
        }
        let mut b = a;
        b.reverse();
        let r = map_correlations(&[(1, a), (2, a), (3, b)]);
        assert_eq!(r.len(), 3);
        assert!((r[0] - 1.0).abs() < 1e-12 && (r[1] + 1.0).abs() < 1e-12);
        assert!(map_correlations(&[(1, [0.1; BINS * BINS]), (2, a)]).is_empty());
        assert!(map_correlations(&[(1, a), (1, a)]).is_empty());
    }
}
