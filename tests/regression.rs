//! Whole runs of the shipped paper scene against measured and published behaviour.

use std::sync::{Arc, Mutex};

use mechanics::{Observables, Observation, Schedule};
use scene::Scene;

fn paper_scene(overrides: &[&str]) -> Scene {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/paper.toml"))
            .unwrap();
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    Scene::parse(&text, &o).unwrap()
}

/// Runs `scene` (relaxation, then activity) in f64 and returns `(time, observables)` every
/// `every` steps.
fn run(scene: &Scene, every: u64) -> Vec<(f64, Observables)> {
    let mut sim = scene.simulation::<f64>().expect("a scene of discs builds");
    let samples = Arc::new(Mutex::new(Vec::new()));
    let sink = samples.clone();
    sim.add_callback(
        "sampler",
        Schedule::IterationInterval(every),
        move |o: &mut Observation<f64>| {
            let obs = o.observables();
            sink.lock().unwrap().push((o.time(), obs));
            Ok(())
        },
    );
    sim.run().unwrap();
    let out = samples.lock().unwrap().clone();
    out
}

/// Sixty cells at the paper's density relax at ζ = 0 (paper pressure, seed 1).
/// Measured: `v_rms` rises from 0.023 to 0.042 at t ≈ 20 while the small initial discs grow,
/// then falls to 4.7e-3 (200 TU), 1.4e-3 (1000 TU), 1.1e-3 (1200 TU) and 7e-4 (2000 TU):
/// the slow coarsening the reference code shows too (~1e-3 after 1200 TU). The areas settle
/// into [163.7, 170.5] around a mean of 167.3 (the domain area per cell, 166.7, plus the
/// overlaps), a band of ±2.1 %.
#[test]
fn sixty_cells_relax_at_zero_activity() {
    let scene = paper_scene(&["model.zeta=0", "run.relax_time=0", "run.time=1200"]);
    let series = run(&scene, 50);
    let peak = series.iter().map(|(_, o)| o.v_rms).fold(0.0, f64::max);
    let (t_end, end) = *series.last().unwrap();
    assert!((t_end - 1200.0).abs() < 1e-6);
    eprintln!(
        "peak v_rms {peak:.3e}, final {:.3e}, areas [{:.1}, {:.1}] mean {:.2}",
        end.v_rms, end.area_min, end.area_max, end.area_mean
    );
    // At least a factor 20 below the peak, and below the reference code's 1e-3 level × 2.
    assert!(
        end.v_rms < peak / 20.0 && end.v_rms < 2e-3,
        "{} vs peak {peak}",
        end.v_rms
    );
    // Decreasing from 100 TU on, sampled every 100 TU.
    let late: Vec<f64> = series
        .iter()
        .filter(|(t, _)| *t >= 99.0 && (*t as u64).is_multiple_of(100))
        .map(|(_, o)| o.v_rms)
        .collect();
    assert!(late.windows(2).all(|w| w[1] < w[0]), "{late:?}");
    // Areas: within ±4 % of the mean (measured ±2.1 %), the mean within 1 of 167.3.
    assert!(end.area_min > 0.96 * end.area_mean && end.area_max < 1.04 * end.area_mean);
    assert!((end.area_mean - 167.3).abs() < 1.0, "{}", end.area_mean);
    // Passive steps skip the deformation tensors; observations must still report them.
    assert!(end.s_rms > 0.1, "{}", end.s_rms);
}

/// The reference's protocol (the authors' code run on this machine kind, figures below): interaction
/// pressure, 200 TU relaxation, 1000 TU at ζ = 0.005, averages over the last 500 TU. The
/// reference code gives, over five seeds, v_rms 0.0425 ± 0.0052, area 158.3 ± 1.6,
/// S_rms 2.30 ± 0.17. Ours over seeds 1–5: v_rms 0.0453 ± 0.0019, area 158.2 ± 0.6,
/// S_rms 2.38 ± 0.08. One seed must fall within 3 reference standard deviations.
#[test]
fn active_statistics_agree_with_the_reference_code() {
    let scene = paper_scene(&["model.pressure=\"interaction\"", "run.seed=3"]);
    let series = run(&scene, 5);
    let last: Vec<&Observables> = series
        .iter()
        .filter(|(t, _)| *t >= 700.0 - 1e-9)
        .map(|(_, o)| o)
        .collect();
    let n = last.len() as f64;
    let v = last.iter().map(|o| o.v_rms).sum::<f64>() / n;
    let a = last.iter().map(|o| o.area_mean).sum::<f64>() / n;
    let s = last.iter().map(|o| o.s_rms).sum::<f64>() / n;
    eprintln!("v_rms {v:.4} area {a:.1} s_rms {s:.3}");
    assert!((v - 0.0425).abs() < 3.0 * 0.0052, "v_rms {v}");
    assert!((a - 158.3).abs() < 3.0 * 1.6, "area {a}");
    assert!((s - 2.30).abs() < 3.0 * 0.17, "s_rms {s}");
}
