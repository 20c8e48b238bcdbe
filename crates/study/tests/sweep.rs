//! Sweeps end to end: the same summary for any number of jobs, and resumption that redoes
//! only what did not finish.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use study::{plan, run_points, write_summary, SweepParams, Vary, COMPLETE};

/// Two cells in 48², 5 TU of relaxation and 10 TU of activity at dt 0.5 (30 steps), a series
/// row every TU (6 in the window [10, 15]).
const SCENE: &str = "\
[domain]
lx = 48
ly = 48
[cells]
count = 2
init = \"positions\"
positions = [[16.0, 24.0], [30.0, 24.5]]
[integrator]
margin = 12
[run]
relax_time = 5
time = 10
output_every = 5
series_every = 1
";

fn points() -> (Vec<String>, Vec<study::Point>) {
    let varies: Vec<Vary> = vec![
        "model.zeta=0,0.01".parse().unwrap(),
        "model.gamma=0.01,0.02".parse().unwrap(),
    ];
    let keys = varies.iter().map(|v| v.key.clone()).collect();
    (
        keys,
        plan(SCENE, &[], &varies, Some("1-2".parse().unwrap())).unwrap(),
    )
}

fn sweep(dir: &std::path::Path, jobs: usize) -> (study::SweepInfo, String, u64) {
    let (keys, points) = points();
    let steps = Arc::new(AtomicU64::new(0));
    let s = steps.clone();
    let info = run_points(
        &points,
        dir,
        SweepParams::new(jobs, 1),
        Arc::new(move |n| {
            s.fetch_add(n, Ordering::Relaxed);
        }),
        &rundir::Interrupt::never(),
    )
    .unwrap();
    let path = write_summary(dir, &keys, &points, false).unwrap();
    (
        info,
        std::fs::read_to_string(path).unwrap(),
        steps.load(Ordering::Relaxed),
    )
}

#[test]
fn the_summary_is_the_same_for_any_number_of_jobs() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let (info_a, sum_a, steps_a) = sweep(a.path(), 1);
    let (info_b, sum_b, _) = sweep(b.path(), 2);
    assert_eq!((info_a.ran, info_a.skipped, info_b.ran), (8, 0, 8));
    assert_eq!(steps_a, 8 * 30, "progress counts every step of every run");
    assert_eq!(sum_a, sum_b, "summary.csv does not depend on --jobs");
    let lines: Vec<&str> = sum_a.lines().collect();
    assert_eq!(
        lines[0],
        "model.zeta,model.gamma,seed,window_start,window_end,rows,v_rms,s_rms,area_mean,growth_rate,growth_exponent"
    );
    assert_eq!(lines.len(), 9);
    assert!(lines[1].starts_with("0,0.01,1,10,15,6,"), "{}", lines[1]);
    assert!(lines[8].starts_with("0.01,0.02,2,10,15,6,"), "{}", lines[8]);
}

#[test]
fn a_second_sweep_redoes_only_what_did_not_finish() {
    let dir = tempfile::tempdir().unwrap();
    let (_, first, _) = sweep(dir.path(), 2);
    let runs = dir.path().join("runs");
    // One run lost its mark (killed before it finished); another is complete.
    let killed = runs.join("model.zeta=0.01_model.gamma=0.01_seed=2");
    let kept = runs.join("model.zeta=0_model.gamma=0.02_seed=1");
    std::fs::remove_file(killed.join(COMPLETE)).unwrap();
    std::fs::write(killed.join("series.csv"), "step,time\n0,0\n").unwrap();
    let kept_time = std::fs::metadata(kept.join("series.csv"))
        .unwrap()
        .modified()
        .unwrap();
    let (info, again, steps) = sweep(dir.path(), 2);
    assert_eq!((info.ran, info.skipped, steps), (1, 7, 30));
    assert_eq!(again, first, "the rerun restores the same summary");
    let kept_again = std::fs::metadata(kept.join("series.csv"))
        .unwrap()
        .modified()
        .unwrap();
    assert_eq!(kept_time, kept_again, "a complete run is not touched");
    // A third call does nothing.
    let (info, _, steps) = sweep(dir.path(), 1);
    assert_eq!((info.ran, info.skipped, steps), (0, 8, 0));
}
