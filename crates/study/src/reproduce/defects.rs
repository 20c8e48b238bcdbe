//! `reproduce defects`: the supplementary defect figure. Defect density and creation rate
//! against ζ; total density and net charge over time; where pairs are created.

use std::path::Path;

use render::{Plot, Series};

use super::lengths::{by_value, times, trend, turbulence, PRESSURES, ZETAS};
use super::{
    drawn, g, write_text, AtValue, Claim, Rec, ReproduceParams, SweepResult, Table, Verdict,
};
use crate::SweepError;

/// Bins per side of the creation-position test.
const BINS: usize = 4;

/// The figure's tables, plots and claims for one pressure form.
fn one_form(
    p: &ReproduceParams,
    dir: &Path,
    zeta: &SweepResult,
    pressure: &str,
) -> Result<Vec<Claim>, SweepError> {
    let recs: Vec<Rec> = zeta
        .records(None)?
        .into_iter()
        .filter(|r| r.values[0] == pressure)
        .collect();
    let density = by_value(zeta, pressure, &ZETAS, "defect_density")?;
    let rate = by_value(zeta, pressure, &ZETAS, "creation_rate")?;
    let mut csv = String::from(
        "zeta,defect_density,defect_density_std,creation_rate,creation_rate_std,seeds\n",
    );
    for (d, r) in density.iter().zip(&rate) {
        csv += &format!(
            "{},{:e},{:e},{:e},{:e},{}\n",
            d.0, d.1 .0, d.1 .1, r.1 .0, r.1 .1, d.2
        );
    }
    write_text(&dir.join(format!("defects_vs_zeta_{pressure}.csv")), &csv)?;
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
    pd.series.push(series(&density, "defect density"));
    drawn(pd.save_png(&dir.join(format!("defect_density_vs_zeta_{pressure}.png"))))?;
    let mut pr = Plot::new(
        format!("Creation rate of defect pairs against ζ ({pressure} pressure)"),
        "activity ζ",
        "pair creations per node per TU",
    );
    pr.series.push(series(&rate, "creation rate"));
    drawn(pr.save_png(&dir.join(format!("creation_rate_vs_zeta_{pressure}.png"))))?;

    // Over time, and the charge of every frame.
    let mut time_csv = String::from("zeta,seed,time,n_plus,n_minus,defect_density,net_charge\n");
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
    let (mut frames, mut charged, mut max_charge) = (0usize, 0usize, 0.0f64);
    let (mut creations, mut unpaired) = (Vec::new(), 0.0f64);
    for r in &recs {
        let t = Table::read(&r.run.join("analysis/observables.csv"))?;
        let (time, np, nm, dens, net, un) = (
            t.f64s("time")?,
            t.f64s("n_plus")?,
            t.f64s("n_minus")?,
            t.f64s("defect_density")?,
            t.f64s("net_charge")?,
            t.f64s("unpaired")?,
        );
        for k in 0..time.len() {
            time_csv += &format!(
                "{},{},{},{},{},{:e},{}\n",
                r.values[1], r.seed, time[k], np[k], nm[k], dens[k], net[k]
            );
            frames += 1;
            if net[k] != 0.0 {
                charged += 1;
            }
            max_charge = max_charge.max(net[k].abs());
        }
        unpaired += un.iter().filter(|x| x.is_finite()).sum::<f64>();
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
        if r.values[1].parse::<f64>().unwrap_or(0.0) > 0.0 {
            let ev = Table::read(&r.run.join("analysis/defect_events.csv"))?;
            let (kind, x, y) = (ev.strs("kind")?, ev.f64s("x")?, ev.f64s("y")?);
            for k in 0..kind.len() {
                if kind[k] == "creation" {
                    creations.push((x[k], y[k]));
                }
            }
        }
    }
    write_text(
        &dir.join(format!("defects_in_time_{pressure}.csv")),
        &time_csv,
    )?;
    drawn(pt.save_png(&dir.join(format!("defect_density_in_time_{pressure}.png"))))?;
    drawn(pq.save_png(&dir.join(format!("net_charge_in_time_{pressure}.png"))))?;

    // Where pairs are created: counts in BINS × BINS cells of the box against uniform.
    let lx = 200.0;
    let mut counts = [0usize; BINS * BINS];
    for &(x, y) in &creations {
        let b = |v: f64| ((v.rem_euclid(lx) / lx * BINS as f64) as usize).min(BINS - 1);
        counts[b(x) * BINS + b(y)] += 1;
    }
    let n = creations.len() as f64;
    let expect = n / (BINS * BINS) as f64;
    let chi2: f64 = counts
        .iter()
        .map(|&c| (c as f64 - expect).powi(2) / expect.max(1e-300))
        .sum();
    // 99th percentile of χ² with 15 degrees of freedom.
    let chi2_crit = 30.58;
    let mut pos_csv = String::from("bin_x,bin_y,creations\n");
    for (k, c) in counts.iter().enumerate() {
        pos_csv += &format!("{},{},{c}\n", k / BINS, k % BINS);
    }
    write_text(
        &dir.join(format!("creation_positions_{pressure}.csv")),
        &pos_csv,
    )?;

    let active: Vec<AtValue> = density.iter().filter(|d| d.0 > 0.0).cloned().collect();
    let (vd, td) = trend(&density, 1.0);
    let (va, ta) = trend(&active, 1.0);
    let (vr, tr) = trend(
        &rate
            .iter()
            .filter(|d| d.0 > 0.0)
            .cloned()
            .collect::<Vec<_>>(),
        1.0,
    );
    let at_rest = density.first().map_or(f64::NAN, |d| d.1 .0);
    let top = density.last().map_or(f64::NAN, |d| d.1 .0);
    Ok(vec![
        Claim::new(
            format!("9.5 ({pressure} pressure): the total topological charge stays zero"),
            format!("{charged} of {frames} analysed frames have a non-zero net charge (largest |charge| {max_charge})"),
            if frames == 0 { Verdict::Inconclusive } else if charged == 0 { Verdict::Holds } else { Verdict::DoesNotHold },
            "every +1/2 found has a −1/2 partner in the same frame, as a periodic domain requires",
        ),
        Claim::new(
            format!("9.5 ({pressure} pressure): ±1/2 defects appear in pairs at random places"),
            format!(
                "{} pair creations at ζ > 0; {} births or deaths without a partner within 2R; creation positions in {BINS}×{BINS} bins: χ² = {} (15 degrees of freedom, 1 % critical value {chi2_crit})",
                creations.len(),
                unpaired,
                g(chi2)
            ),
            if creations.len() < 5 * BINS * BINS {
                Verdict::Inconclusive
            } else if chi2 < chi2_crit {
                Verdict::Holds
            } else {
                Verdict::Inconclusive
            },
            if creations.len() < 5 * BINS * BINS {
                format!("fewer than {} creations: too few to test where they happen", 5 * BINS * BINS)
            } else if chi2 < chi2_crit {
                "births are paired +1/2 with −1/2, and the pair positions are consistent with uniform over the box".into()
            } else {
                "χ² exceeds the 1 % value, but the creations of one run are not independent (one flow pattern makes several), so the test cannot tell clustering in time from preferred places".into()
            },
        ),
        Claim::new(
            format!("9.5 ({pressure} pressure): the defect density grows with ζ"),
            format!("ζ from 0: {td}; among ζ > 0: {ta}; at rest {} of the largest density is already there", g(at_rest / top)),
            if vd == Verdict::Holds && va == Verdict::Holds { Verdict::Holds } else if vd == Verdict::DoesNotHold { Verdict::DoesNotHold } else { Verdict::Inconclusive },
            match (vd, va) {
                (Verdict::Holds, Verdict::Holds) => "it grows by more than two standard errors, from rest and among active runs".to_string(),
                (Verdict::Holds, _) => "it grows from rest to the largest ζ, but among active runs the change is within two standard errors: most defects are already there at rest".to_string(),
                (Verdict::DoesNotHold, _) => "it falls from rest to the largest ζ by more than two standard errors: the defects of the smoothed Q are mostly there at rest, and activity orders the tissue".to_string(),
                _ => "the change is not beyond two standard errors".to_string(),
            },
        ),
        Claim::new(
            format!("9.5 ({pressure} pressure): the creation rate grows with ζ"),
            format!("among ζ > 0: {tr}"),
            vr,
            match vr {
                Verdict::Holds => "it grows by more than two standard errors",
                Verdict::DoesNotHold => "it falls by more than two standard errors",
                Verdict::Inconclusive => "the change is within two standard errors",
            },
        ),
    ])
}

pub(super) fn make(p: &ReproduceParams, dir: &Path) -> Result<(Vec<Claim>, String), SweepError> {
    let (zeta, _) = turbulence(p)?;
    p.reporter.stage("defects: tables and plots");
    let mut claims = Vec::new();
    for pressure in PRESSURES {
        claims.extend(one_form(p, dir, &zeta, pressure)?);
    }
    let (t, from) = times(p.scale);
    let settings = format!(
        "- The ζ sweep of `reproduce lengths` (L = 200, 240 cells, γ = 0.01, both pressure forms, ζ ∈ {{{}}}, seeds {}), 200 TU of relaxation then {t} TU; frames every 10 TU analysed from t = {from}.\n\
         - Defects: ±1/2 of the box-smoothed Q (3R box); tracked between frames (links within R), births and deaths paired within 2R into creations and annihilations. Density = defects per node; creation rate = pair creations per node per TU, averaged over the frames.\n\
         - Files (one of each per pressure form, `_paper` and `_interaction`): `defects_vs_zeta_*.csv`, `defects_in_time_*.csv`, `creation_positions_*.csv`, `defect_density_vs_zeta_*.png`, `creation_rate_vs_zeta_*.png`, `defect_density_in_time_*.png`, `net_charge_in_time_*.png`.",
        ZETAS.join(", "),
        p.scale.seeds()
    );
    Ok((claims, settings))
}
