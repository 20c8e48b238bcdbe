//! ζ_cr of one hexagonal packing by both methods, with each evaluation and the timings.
//!
//! `cargo run --release -p stability --example threshold -- COLS ROWS GAMMA PRESSURE`
//! (`METHODS=arnoldi` for Arnoldi alone; `TILE=k` for k × k copies of the COLS × ROWS box,
//! an exact tiling; the uniform translations' own growth rates are printed at ζ = 0 and ζ_cr)
use mechanics::{ModelParams, PressureKind, StepParams};
use stability::*;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let cols: usize = args.get(1).map_or(6, |s| s.parse().unwrap());
    let rows: usize = args.get(2).map_or(10, |s| s.parse().unwrap());
    let gamma: f64 = args.get(3).map_or(0.01, |s| s.parse().unwrap());
    let pressure = if args.get(4).map_or("paper", |s| s) == "paper" {
        PressureKind::Paper
    } else {
        PressureKind::Interaction
    };
    let tile: usize = std::env::var("TILE").map_or(1, |t| t.parse().unwrap());
    let hex = HexBox::new(cols, rows, 100.0 * 100.0 / 60.0)?.tiled(tile);
    let mut params = ModelParams::paper(0.0).with_pressure(pressure);
    params.energy.gamma = gamma;
    let t0 = Instant::now();
    let rest = rest_state(&hex, &params, &Relaxation::default())?;
    println!(
        "box {}x{} relaxed t={} v_max={:.2e} phi_rate={:.2e} s_rms={:.4} in {:.1}s",
        hex.lx,
        hex.ly,
        rest.time,
        rest.v_max,
        rest.phi_rate,
        rest.s_rms,
        t0.elapsed().as_secs_f64()
    );
    let opts = ThresholdOptions {
        step: StepParams::new(0.5, 1),
        steps: 100,
        lo: 0.0,
        hi: 0.008,
        tol: 2e-5,
        narrow: 1e-4,
    };
    // The settings of `monolayer reproduce stability`; METHODS=arnoldi skips the slower growth.
    let only_arnoldi = std::env::var("METHODS").is_ok_and(|m| m == "arnoldi");
    for method in [
        Method::Arnoldi(ArnoldiOptions {
            krylov: 30,
            eps: 1e-5,
            seed: 1,
        }),
        Method::Growth(GrowthOptions {
            amplitude: 1e-4,
            intervals: 24,
            vectors: 4,
            seed: 2,
        }),
    ] {
        if only_arnoldi && method.name() == "growth" {
            continue;
        }
        let t0 = Instant::now();
        let t = threshold(&rest.tissue, &params, &method, &opts)?;
        println!(
            "{}: zeta_cr {:.4e} ± {:.2e} slope {:.3} in {:.1}s",
            method.name(),
            t.zeta_cr,
            t.err,
            t.slope,
            t0.elapsed().as_secs_f64()
        );
        for e in &t.evaluations {
            println!(
                "   zeta {:.5} sigma {:+.4e} ± {:.1e}",
                e.zeta, e.sigma, e.sigma_err
            );
        }
        for zeta in [0.0, t.zeta_cr] {
            let mut map =
                StepMap::new(&rest.tissue, &params.with_zeta(zeta), opts.step, opts.steps)?;
            let [sx, sy] = map.translation_rates(1e-5)?;
            println!(
                "   translations at zeta {zeta:.5}: sigma_x {sx:+.3e} sigma_y {sy:+.3e}, drift {:.2e}",
                map.drift()
            );
        }
    }
    Ok(())
}
