//! `reproduce scaling`: the cost of a step with subdomains (patches of side 2(R + margin))
//! against the full domain (margin 0: every cell on the whole lattice), in time and memory,
//! at the paper's density (15 cells per 50²) as the box grows.

use std::path::Path;
use std::time::Instant;

use render::{Plot, Series};

use super::{drawn, g, write_text, Claim, ReproduceParams, Scale, Verdict, PAPER_SCENE};
use crate::SweepError;

/// One measurement: wall seconds per step (median of `repeats`) and the heap bytes the
/// simulation holds (tissue and workspace, [`mechanics::Tissue::heap_bytes`]).
fn measure(lx: usize, margin: usize, steps: u64, repeats: usize) -> Result<(f64, f64), SweepError> {
    let count = lx * lx * 15 / 2500;
    let sets = vec![
        format!("domain.lx={lx}"),
        format!("domain.ly={lx}"),
        format!("cells.count={count}"),
        format!("integrator.margin={margin}"),
        "integrator.dt=0.5".into(),
        "model.zeta=0.005".into(),
        "run.relax_time=0".into(),
        format!("run.time={}", steps as f64 * 0.5),
        format!("run.output_every={}", steps as f64 * 0.5),
    ];
    let scene = scene::Scene::parse(PAPER_SCENE, &sets).map_err(|e| SweepError::Scene {
        point: format!("scaling L = {lx}, margin {margin}"),
        source: Box::new(e),
    })?;
    let mut times = Vec::new();
    let mut mem = f64::NAN;
    for _ in 0..repeats {
        let mut sim = scene.simulation::<f32>().map_err(|e| SweepError::Scene {
            point: format!("scaling L = {lx}, margin {margin}"),
            source: Box::new(e),
        })?;
        let start = Instant::now();
        sim.run().map_err(|source| SweepError::Run {
            point: format!("scaling L = {lx}, margin {margin}"),
            source,
        })?;
        times.push(start.elapsed().as_secs_f64() / steps as f64);
        mem = (sim.tissue().heap_bytes() + sim.workspace().heap_bytes()) as f64;
    }
    times.sort_by(f64::total_cmp);
    Ok((times[times.len() / 2], mem))
}

/// The exponent of `y ∝ x^k`: the least-squares slope in log–log.
fn exponent(x: &[f64], y: &[f64]) -> f64 {
    let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let ly: Vec<f64> = y.iter().map(|v| v.ln()).collect();
    crate::summary::slope(&lx, &ly)
}

pub(super) fn make(p: &ReproduceParams, dir: &Path) -> Result<(Vec<Claim>, String), SweepError> {
    let (sub, full): (Vec<usize>, Vec<usize>) = match p.scale {
        Scale::Quick => (vec![100, 200, 400], vec![50, 100, 150, 200]),
        Scale::Paper => (vec![100, 200, 400, 800], vec![50, 100, 150, 200, 250]),
    };
    p.reporter.stage("scaling: timing steps on one thread");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| SweepError::Threads(e.to_string()))?;
    let mut csv = String::from("method,lx,cells,seconds_per_step,heap_bytes\n");
    type Row<'a> = (&'a str, Vec<(f64, f64, f64)>);
    let mut rows: Vec<Row> = Vec::new();
    for (method, sizes, margin) in [("subdomains", &sub, 16usize), ("full domain", &full, 0)] {
        let mut pts = Vec::new();
        for &lx in sizes {
            let cells = (lx * lx * 15 / 2500) as f64;
            // Enough steps for a tenth of a second or so, at least 5.
            let steps = if margin == 0 {
                5
            } else {
                (20_000 / lx as u64).max(5)
            };
            let (t, m) = pool.install(|| measure(lx, margin, steps, 3))?;
            csv += &format!("{method},{lx},{cells},{t:e},{m}\n");
            pts.push((cells, t, m));
        }
        rows.push((method, pts));
    }
    write_text(&dir.join("scaling.csv"), &csv)?;
    let mut pt = Plot::new(
        "Time per step at the paper's density (1 thread, f32)",
        "cells N",
        "seconds per step",
    );
    pt.log_x = true;
    pt.log_y = true;
    let mut pm = Plot::new(
        "Memory at the paper's density",
        "cells N",
        "bytes held by the simulation",
    );
    pm.log_x = true;
    pm.log_y = true;
    let mut claims = Vec::new();
    let mut summary = Vec::new();
    for (method, pts) in &rows {
        let n: Vec<f64> = pts.iter().map(|p| p.0).collect();
        let t: Vec<f64> = pts.iter().map(|p| p.1).collect();
        let m: Vec<f64> = pts.iter().map(|p| p.2).collect();
        let zero = vec![0.0; n.len()];
        pt.series
            .push(Series::new(*method).with_points(&n, &t, &zero));
        pm.series
            .push(Series::new(*method).with_points(&n, &m, &zero));
        summary.push((method.to_string(), exponent(&n, &t), exponent(&n, &m)));
    }
    drawn(pt.save_png(&dir.join("time_per_step.png")))?;
    drawn(pm.save_png(&dir.join("memory.png")))?;
    for (method, kt, km) in &summary {
        let (want, lo, hi) = if method == "subdomains" {
            ("O(N)", 0.8, 1.25)
        } else {
            ("O(N²)", 1.7, 2.3)
        };
        let ok = |k: f64| (lo..=hi).contains(&k);
        claims.push(Claim::new(
            format!("9.7: {method} cost {want} in time and memory"),
            format!("time ∝ N^{}, memory ∝ N^{}", g(*kt), g(*km)),
            if ok(*kt) && ok(*km) {
                Verdict::Holds
            } else if ok(*kt) {
                Verdict::Inconclusive
            } else {
                Verdict::DoesNotHold
            },
            format!(
                "the log–log slopes {} in [{lo}, {hi}]",
                if ok(*kt) && ok(*km) {
                    "both lie"
                } else {
                    "do not both lie"
                }
            ),
        ));
    }
    let settings = format!(
        "- Paper scene at its density (15 cells per 50²), ζ = 0.005, dt 0.5, f32, one thread, no output, straight from a random start.\n\
         - Subdomains: margin 16 (patches of side 2(R + 16) = 48), L ∈ {{{}}}. Full domain: margin 0 (every cell on the whole lattice), L ∈ {{{}}}.\n\
         - Time: the median over 3 repeats of the wall time of a run, per step (the machine's load adds noise; the exponents are what matter). Memory: the heap bytes the simulation holds (fields, patch maps, scratch buffers, lattice sums and tables: `Tissue::heap_bytes` + `Workspace::heap_bytes`), counted from the buffers' capacities, not sampled from the process.\n\
         - Files: `scaling.csv`, `time_per_step.png`, `memory.png`.",
        sub.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(", "),
        full.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(", ")
    );
    Ok((claims, settings))
}

#[cfg(test)]
mod tests {
    #[test]
    fn exponents_of_power_laws() {
        let x = [60.0, 240.0, 960.0];
        let y: Vec<f64> = x.iter().map(|v: &f64| 3e-6 * v.powi(2)).collect();
        assert!((super::exponent(&x, &y) - 2.0).abs() < 1e-12);
    }
}
