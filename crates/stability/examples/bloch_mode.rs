//! What the leading Bloch mode of one wave is made of: the share of its norm in each cell's own
//! translation along x and along y (`∂_x φ_p`, `∂_y φ_p`), the rest being shape and size.
//!
//! `cargo run --release -p stability --example bloch_mode -- QX QY ZETA [paper|interaction]`
//! (the figure's packing: primitive cell 6 × 2 cells on 83 × 24, γ = 0.01, τ = 100 × 0.5 TU)
use mechanics::{ModelParams, PressureKind, StepParams};
use stability::*;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let arg = |k: usize, d: f64| args.get(k).map_or(d, |s| s.parse().unwrap());
    let (q, zeta) = ([arg(1, 0.125), arg(2, 0.0)], arg(3, 0.0));
    let pressure = if args.get(4).map_or("paper", |s| s) == "paper" {
        PressureKind::Paper
    } else {
        PressureKind::Interaction
    };
    let params = ModelParams::paper(0.0).with_pressure(pressure);
    let tiling = BlochTiling::relax(
        HexBox::new(6, 2, 100.0 * 100.0 / 60.0)?,
        [1, 2],
        &params,
        &Relaxation::default(),
    )?;
    let p = params.with_zeta(zeta);
    let reps = tiling.supercell_for(q);
    let mut map = BlochMap::new(&tiling, &p, StepParams::new(0.5, 1), 100, reps, q)?;
    let opts = ArnoldiOptions {
        krylov: 30,
        eps: 1e-5,
        seed: 1,
    };
    let s = arnoldi(&mut map, &opts, None)?;
    println!(
        "q = {q:?}, ζ = {zeta}: σ = {:.3e} ± {:.1e}",
        s.sigma(),
        s.ritz[0].residual
    );
    // The primitive cell's cells, as the first copy of the relaxed box holds them.
    let cells = tiling.rest.tissue.cells();
    let shape = cells.shape();
    let (nx, ny, n) = (shape.nx, shape.ny, shape.len());
    let per = tiling.primitive.n_cells();
    let cols = tiling.reps[0] * tiling.primitive.cols;
    let half = per * n;
    let (mut sx, mut sy) = (0.0, 0.0);
    for p in 0..per {
        let pc = tiling.primitive.cols;
        let i = (p / pc) * cols + p % pc;
        let f = &cells.phi()[i * n..(i + 1) * n];
        let mut gx = vec![0.0; n];
        let mut gy = vec![0.0; n];
        for a in 0..nx {
            for b in 0..ny {
                gx[a * ny + b] = 0.5 * (f[shape.xp[a] * ny + b] - f[shape.xm[a] * ny + b]);
                gy[a * ny + b] = 0.5 * (f[a * ny + (b + 1) % ny] - f[a * ny + (b + ny - 1) % ny]);
            }
        }
        let (ngx, ngy) = (norm(&gx), norm(&gy));
        for part in [0, half] {
            let u = &s.mode[part + p * n..part + (p + 1) * n];
            sx += (dot(u, &gx) / ngx).powi(2);
            sy += (dot(u, &gy) / ngy).powi(2);
        }
    }
    let total = dot(&s.mode, &s.mode);
    println!(
        "share of the mode's norm²: each cell's translation along x {:.3}, along y {:.3}, the rest {:.3}",
        sx / total,
        sy / total,
        1.0 - (sx + sy) / total
    );
    Ok(())
}
