//! The cost of each physics term (docs/model.md §11) per step: one relaxed step (dt 0.2,
//! ζ = 0.005) of `large.toml` (960 cells, 400², margin 12, f32 storage) without terms, with
//! self-propulsion (`[polarity]` α = 0.04, D_r = 4.5e-4, aligning to the velocity), with
//! adhesion (ω = 0.005), with two populations of different γ and ζ (±0.005), and in a channel
//! (`[walls] kind = "channel"`, κ_w = 1, ℓ_w = 1), and with a cell-cycle clock (`[division]`
//! with every cell in its growth phase and none due: the step, the clock's checks after it and
//! each cell's own target area in the kernels), on one and two threads. Throughput is in node
//! updates (cells × patch nodes per step). `division/event` is one division of a cell of the
//! relaxed tissue with the workspace fitted after it (the cost of an event, not per step),
//! after a first one that took the storage's reallocation.
//!
//! Run with `cargo bench -p monolayer-benches --bench terms`.

use criterion::{criterion_main, BenchmarkId, Criterion, Throughput};
use mechanics::terms::{Population, Populations};
use mechanics::Workspace;
use monolayer_benches::{pool, relaxed_scene};

fn bench_terms(c: &mut Criterion) {
    let mut g = c.benchmark_group("terms");
    g.sample_size(10);
    let base = ["integrator.margin=12".to_string()];
    let with = |extra: &[&str]| -> Vec<String> {
        base.iter()
            .cloned()
            .chain(extra.iter().map(|s| s.to_string()))
            .collect()
    };
    let cases: [(&str, Vec<String>, bool); 6] = [
        ("none", with(&[]), false),
        (
            "polarity",
            with(&[
                "polarity.alpha=0.04",
                "polarity.rotational_diffusion=4.5e-4",
                "polarity.align=\"velocity\"",
                "polarity.align_rate=0.1",
            ]),
            false,
        ),
        ("adhesion", with(&["adhesion.omega=0.005"]), false),
        ("populations", with(&[]), true),
        ("walls", with(&["walls.kind=\"channel\""]), false),
        (
            "division",
            with(&[
                "division.cycle_time=1",
                "division.cycle_spread=1",
                "division.growth_time=1e9",
                "division.max_cells=2000",
            ]),
            false,
        ),
    ];
    for (name, overrides, populations) in cases {
        let (t, mut ws, s) =
            pool(2).install(|| relaxed_scene::<f32>("large.toml", &overrides, 100, 0.005));
        let n = t.n_cells();
        let mut t = if populations {
            let kinds = vec![
                Population::new().with_gamma(0.01).with_zeta(0.005),
                Population::new().with_gamma(0.02).with_zeta(-0.005),
            ];
            t.with(Populations::new(kinds, &[n / 2, n - n / 2], 1))
        } else {
            t
        };
        let sp = s.step_params();
        g.throughput(Throughput::Elements((n * t.cells().patch_len()) as u64));
        for threads in [1, 2] {
            let pool = pool(threads);
            let id = BenchmarkId::new(name, format!("threads={threads}"));
            g.bench_function(id, |b| {
                pool.install(|| {
                    b.iter(|| {
                        t.step(&mut ws, &sp).unwrap();
                        t.proliferate(&mut ws)
                    })
                });
            });
        }
        if name == "division" {
            let id = BenchmarkId::new("division", "event");
            g.bench_function(id, |b| {
                // The storage grows as `Vec`s do: a first division in the set-up takes the
                // reallocation, so this one is the amortised event of a run.
                b.iter_batched(
                    || {
                        let (mut t, mut ws) = (t.clone(), Workspace::new(t.cells()));
                        t.divide(n / 3, [1.0, 0.0]);
                        ws.fit(t.cells());
                        (t, ws)
                    },
                    |(mut t, mut ws)| {
                        t.divide(n / 2, [1.0, 0.0]);
                        ws.fit(t.cells());
                        (t, ws)
                    },
                    criterion::BatchSize::LargeInput,
                )
            });
        }
    }
    g.finish();
}

#[allow(missing_docs)]
mod group {
    criterion::criterion_group!(benches, super::bench_terms);
}
use group::benches;
criterion_main!(benches);
