//! Does perturbation growth started on Arnoldi's leading mode keep its rate?
use mechanics::{ModelParams, StepParams};
use stability::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let zeta: f64 = std::env::args()
        .nth(1)
        .map_or(0.004, |s| s.parse().unwrap());
    let hex = HexBox::new(6, 10, 100.0 * 100.0 / 60.0)?;
    let params = ModelParams::paper(0.0);
    let rest = rest_state(&hex, &params, &Relaxation::default())?;
    let mut map = StepMap::new(
        &rest.tissue,
        &params.clone().with_zeta(zeta),
        StepParams::new(0.5, 1),
        100,
    )?;
    let sp = arnoldi(
        &mut map,
        &ArnoldiOptions {
            krylov: 40,
            eps: 1e-5,
            seed: 1,
        },
        None,
    )?;
    for r in sp.ritz.iter().take(5) {
        println!(
            "ritz sigma {:+.5e} omega {:+.2e} res {:.1e}",
            r.sigma, r.omega, r.residual
        );
    }
    for p in [1usize, 4, 8] {
        let g = growth_rate(
            &mut map,
            &GrowthOptions {
                amplitude: 1e-5,
                intervals: 40,
                vectors: p,
                seed: 1,
            },
            None,
        )?;
        println!(
            "p={p}: sigma {:.5e} ± {:.1e} overlap {:.3}; {:?}",
            g.sigma,
            g.sigma_err,
            dot(&g.direction, &sp.mode),
            g.rates
                .iter()
                .step_by(4)
                .map(|r| format!("{r:.4e}"))
                .collect::<Vec<_>>()
        );
    }
    Ok(())
}
