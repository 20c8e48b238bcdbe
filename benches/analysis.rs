//! The analysis of one 400 × 400 frame of `large.toml` (960 cells, ζ = 0.005 after 40 TU of
//! relaxation and 20 TU of activity): lattice fields from the state, box smoothing of four
//! components, three correlation accumulations, defect detection and orientation, tracking
//! and defect-centred crops of side 101, each timed alone and all together.
//!
//! Run with `cargo bench -p monolayer-benches --bench analysis`.

use analysis::correlation::Correlator;
use analysis::crop::DefectAverage;
use analysis::defects::detect;
use analysis::fields::vorticity;
use analysis::smooth::box_smooth;
use analysis::tracking::{TrackParams, Tracker};
use criterion::{criterion_main, Criterion};
use mechanics::{TissueFields, Workspace};
use phasefield::Lattice;
use scene::Scene;
use study::analyze::crop_fields;

fn frame() -> (Lattice, mechanics::Tissue, Workspace) {
    let path = format!("{}/../scenes/large.toml", env!("CARGO_MANIFEST_DIR"));
    let s = Scene::parse(&std::fs::read_to_string(path).unwrap(), &[]).unwrap();
    let mut t = s.tissue::<f64>().expect("a scene of discs builds");
    let mut ws = Workspace::new(t.cells());
    for k in 0..300 {
        t.params_mut().zeta = if k < 200 { 0.0 } else { 0.005 };
        t.step(&mut ws, &s.step_params()).unwrap();
    }
    (t.lattice(), t, ws)
}

fn analyse(
    lattice: Lattice,
    f: &TissueFields,
    corr: &mut [Correlator; 3],
    tracker: &mut Tracker,
    avg: &mut DefectAverage,
) -> usize {
    let sm = |v: &[f64]| box_smooth(lattice, v, 25).unwrap();
    let (svx, svy, sqxx, sqxy) = (sm(&f.vx), sm(&f.vy), sm(&f.qxx), sm(&f.qxy));
    let w = vorticity(lattice, &svx, &svy);
    corr[0].add(&[&svx, &svy]);
    corr[1].add(&[&w]);
    corr[2].add(&[&sqxx, &sqxy]);
    let found = detect(lattice, &sqxx, &sqxy);
    tracker.push(&found);
    avg.add(lattice, &crop_fields(f), &found);
    found.len()
}

fn bench_analysis(c: &mut Criterion) {
    let pool = monolayer_benches::pool(2);
    let (lattice, t, mut ws) = pool.install(frame);
    let f = pool.install(|| t.fields(&mut ws));
    let mut g = c.benchmark_group("analysis-400");
    g.sample_size(10);
    g.bench_function("fields", |b| pool.install(|| b.iter(|| t.fields(&mut ws))));
    g.bench_function("smooth-4", |b| {
        b.iter(|| [&f.vx, &f.vy, &f.qxx, &f.qxy].map(|v| box_smooth(lattice, v, 25).unwrap()))
    });
    let mut corr = [
        Correlator::new(lattice),
        Correlator::new(lattice),
        Correlator::new(lattice),
    ];
    g.bench_function("correlations-3", |b| {
        b.iter(|| {
            corr[0].add(&[&f.vx, &f.vy]);
            corr[1].add(&[&f.vx]);
            corr[2].add(&[&f.qxx, &f.qxy]);
        })
    });
    let sq = (
        box_smooth(lattice, &f.qxx, 25).unwrap(),
        box_smooth(lattice, &f.qxy, 25).unwrap(),
    );
    g.bench_function("defects", |b| b.iter(|| detect(lattice, &sq.0, &sq.1)));
    let n_defects = detect(lattice, &sq.0, &sq.1).len();
    eprintln!("{n_defects} defects in the frame");
    let mut tracker = Tracker::new(lattice, TrackParams::for_radius(8.0));
    let mut avg = DefectAverage::new(101);
    g.bench_function("whole-frame", |b| {
        b.iter(|| analyse(lattice, &f, &mut corr, &mut tracker, &mut avg))
    });
    g.finish();
}

#[allow(missing_docs)]
mod group {
    criterion::criterion_group!(benches, super::bench_analysis);
}
use group::benches;
criterion_main!(benches);
